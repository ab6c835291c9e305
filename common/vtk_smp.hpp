#pragma once
// VTK's parallel back-end switched to sequential loops for the rest of the process,
// for a forked child: it has none of its parent's TBB worker threads. Compiled as
// C++17 (vtk_smp.cpp): VTK 9.1's vtkSMPTools.h does not compile as C++20.
namespace stentsim {
void use_sequential_vtk_smp();
}  // namespace stentsim
