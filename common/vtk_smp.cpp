#include "common/vtk_smp.hpp"

#include <vtkSMPTools.h>

namespace stentsim {
void use_sequential_vtk_smp() { vtkSMPTools::SetBackend("Sequential"); }
}  // namespace stentsim
