// VTK adapter: reading surfaces in the formats segmentation tools export.
#include <fmt/format.h>
#include <vtkAlgorithm.h>
#include <vtkCellArray.h>
#include <vtkExecutive.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cctype>
#include <new>
#include <cstdlib>
#include <fstream>
#include <optional>

#include "common/child_process.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "segmentation_io/legacy_vtk_ascii.hpp"
#include "segmentation_io/stl_binary.hpp"
#include "segmentation_io/surface_input.hpp"
#include "common/vtk_read_errors.hpp"
#include "common/vtk_smp.hpp"

namespace stentsim::segmentation {

double unit_length_in_mm(const std::string& u) {
  if (u == "mm") return 1.0;
  if (u == "cm") return 10.0;
  if (u == "m") return 1000.0;
  if (u == "um") return 1e-3;
  throw InputError(fmt::format("unknown length unit '{}'; expected mm, cm, m or um", u));
}

namespace {

TriSurface finite_checked(TriSurface s, const std::filesystem::path& file) {
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (!s.points[i].allFinite())
      throw InputError(fmt::format("{}: point {} has a coordinate that is not a finite number", file.string(), i + 1));
  return s;
}

// Every cell's point ids inside the point list, before a filter dereferences them
// (VTK's readers pass an out-of-range index through; the triangle filter then reads
// outside the points).
void check_point_indices(vtkPolyData* pd, const std::filesystem::path& file) {
  const vtkIdType n = pd->GetNumberOfPoints();
  for (vtkCellArray* cells : {pd->GetVerts(), pd->GetLines(), pd->GetPolys(), pd->GetStrips()}) {
    if (!cells) continue;
    vtkIdType count = 0, cell = 0;
    const vtkIdType* ids = nullptr;
    for (cells->InitTraversal(); cells->GetNextCell(count, ids); ++cell)
      for (vtkIdType k = 0; k < count; ++k)
        if (ids[k] < 0 || ids[k] >= n)
          throw InputError(fmt::format("{}: cell {} refers to point {}, but the file has {} points (indices 0 to {})",
                                       file.string(), cell + 1, ids[k], n, n - 1));
  }
}

}  // namespace

TriSurface read_surface_file(const std::filesystem::path& file) {
  files::require_regular_file(file, "surface file");
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  vtkSmartPointer<vtkAlgorithm> reader;
  if (ext == ".vtp") {
    check_vtk_xml_file(file.string());
    auto r = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    if (!r->CanReadFile(file.c_str()))
      throw InputError(fmt::format("{}: not a VTK XML PolyData (.vtp) file", file.string()));
    r->SetFileName(file.c_str());
    reader = r;
  } else if (ext == ".vtk") {
    if (std::optional<TriSurface> ascii = read_legacy_vtk_ascii(file)) return finite_checked(std::move(*ascii), file);
    // BINARY: VTK's legacy reader trusts the counts before each raw section and
    // crashes inside itself on a damaged one (mutation fuzzing found it), so it
    // reads the file in a child first.
    process::probe_read_in_child(file, "legacy VTK", [&] {
      use_sequential_vtk_smp();  // the forked child has none of the parent's TBB workers
      auto probe = vtkSmartPointer<vtkPolyDataReader>::New();
      probe->SetFileName(file.c_str());
      probe->Update();
    });
    auto r = vtkSmartPointer<vtkPolyDataReader>::New();
    r->SetFileName(file.c_str());
    if (!r->IsFilePolyData())
      throw InputError(fmt::format("{}: not a legacy VTK file with POLYDATA (an unstructured grid or image is not a surface)",
                                   file.string()));
    reader = r;
  } else if (ext == ".stl") {
    if (std::optional<TriSurface> binary = read_binary_stl(file)) return finite_checked(std::move(*binary), file);
    auto r = vtkSmartPointer<vtkSTLReader>::New();  // ASCII
    r->SetFileName(file.c_str());
    r->MergingOn();  // STL repeats each vertex per facet
    reader = r;
  } else if (ext == ".obj") {
    auto r = vtkSmartPointer<vtkOBJReader>::New();
    r->SetFileName(file.c_str());
    reader = r;
  } else {
    throw InputError(fmt::format("{}: unknown surface format '{}'; expected .vtp, .vtk, .stl or .obj", file.string(), ext));
  }
  // A reader that reported an error returns what it read so far, possibly cells that refer
  // past their arrays: refused before anything touches it.
  vtkNew<VtkReadErrors> errors;
  reader->AddObserver(vtkCommand::ErrorEvent, errors);
  try {
    reader->Update();
  } catch (const std::bad_alloc&) {
    throw InputError(fmt::format("{}: the {} file asks for more memory than there is (a damaged count?)", file.string(), ext));
  }
  if (!errors->first.empty())
    throw InputError(fmt::format("{}: the {} file could not be read: {} (damaged or cut short?)", file.string(), ext, errors->first));
  vtkPolyData* raw = vtkPolyData::SafeDownCast(reader->GetOutputDataObject(0));
  if (!raw) throw InputError(fmt::format("{}: no surface could be read (damaged {} file?)", file.string(), ext));
  check_point_indices(raw, file);
  vtkNew<vtkTriangleFilter> tri;
  tri->SetInputData(raw);
  tri->PassLinesOff();
  tri->PassVertsOff();
  tri->Update();
  vtkPolyData* pd = tri->GetOutput();
  if (!pd || pd->GetNumberOfPolys() == 0)
    throw InputError(fmt::format("{}: no triangles could be read (damaged or empty {} file?)", file.string(), ext));
  TriSurface s;
  s.points.resize(std::size_t(pd->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) pd->GetPoint(i, s.points[std::size_t(i)].data());
  vtkCellArray* polys = pd->GetPolys();
  vtkNew<vtkIdList> ids;
  polys->InitTraversal();
  while (polys->GetNextCell(ids)) {
    if (ids->GetNumberOfIds() != 3) continue;
    s.triangles.push_back({int(ids->GetId(0)), int(ids->GetId(1)), int(ids->GetId(2))});
  }
  return finite_checked(std::move(s), file);
}

}  // namespace stentsim::segmentation
