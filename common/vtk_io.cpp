// The VTK adapter for MeshData: the only file in common/ that includes VTK.
#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <filesystem>
#include <fstream>
#include <new>
#include <tuple>

#include "common/child_process.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "common/vtk_read_errors.hpp"
#include "common/vtk_smp.hpp"

namespace stentsim {
namespace {

vtkSmartPointer<vtkPoints> to_vtk_points(const MeshData& m) {
  auto pts = vtkSmartPointer<vtkPoints>::New();
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(m.points.size()));
  for (std::size_t i = 0; i < m.points.size(); ++i) pts->SetPoint(static_cast<vtkIdType>(i), m.points[i].data());
  return pts;
}

void add_arrays(vtkFieldData* target, const std::map<std::string, DataArray>& arrays) {
  for (const auto& [name, a] : arrays) {
    vtkNew<vtkDoubleArray> arr;
    arr->SetName(name.c_str());
    arr->SetNumberOfComponents(a.components);
    arr->SetNumberOfTuples(static_cast<vtkIdType>(a.tuples()));
    std::copy(a.values.begin(), a.values.end(), arr->GetPointer(0));
    target->AddArray(arr);
  }
}

void add_field_text(vtkDataObject* obj, const std::map<std::string, std::string>& text) {
  for (const auto& [k, v] : text) {
    vtkNew<vtkStringArray> s;
    s->SetName(k.c_str());
    s->InsertNextValue(v);
    obj->GetFieldData()->AddArray(s);
  }
}

std::map<std::string, DataArray> read_arrays(vtkFieldData* fd) {
  std::map<std::string, DataArray> out;
  for (int i = 0; i < fd->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = fd->GetArray(i);
    if (!a || !a->GetName()) continue;
    DataArray d;
    d.components = a->GetNumberOfComponents();
    d.values.resize(static_cast<std::size_t>(a->GetNumberOfTuples() * d.components));
    for (vtkIdType t = 0; t < a->GetNumberOfTuples(); ++t)
      for (int c = 0; c < d.components; ++c) d.values[static_cast<std::size_t>(t * d.components + c)] = a->GetComponent(t, c);
    out[a->GetName()] = std::move(d);
  }
  return out;
}

std::map<std::string, std::string> read_field_text(vtkDataObject* obj) {
  std::map<std::string, std::string> out;
  vtkFieldData* fd = obj->GetFieldData();
  for (int i = 0; i < fd->GetNumberOfArrays(); ++i) {
    auto* s = vtkStringArray::SafeDownCast(fd->GetAbstractArray(i));
    if (s && s->GetName() && s->GetNumberOfValues() > 0) out[s->GetName()] = s->GetValue(0);
  }
  return out;
}

void read_points(vtkPointSet* ps, MeshData& m) {
  m.points.resize(static_cast<std::size_t>(ps->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < ps->GetNumberOfPoints(); ++i) ps->GetPoint(i, m.points[static_cast<std::size_t>(i)].data());
}

template <typename Writer, typename Data>
void write_with(const std::string& file, Data* data) {
  const std::filesystem::path target(file);
  if (!target.parent_path().empty()) std::filesystem::create_directories(target.parent_path());
  const auto tmp = files::temporary_name_for(target);
  vtkNew<Writer> w;
  w->SetFileName(tmp.c_str());
  w->SetInputData(data);
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  w->SetCompressorTypeToZLib();
  if (w->Write() != 1) {
    std::filesystem::remove(tmp);
    throw ComputeError(fmt::format("{}: VTK could not write the file", file));
  }
  files::replace(tmp, target);
}



// VTK's XML reader allocates what a piece's NumberOfPoints / NumberOfPolys ... say
// before reading a byte of it: a damaged count means gigabytes (std::bad_alloc). Even
// zlib-compressed data takes a byte per thousand values, so a count above 1000 x the
// file's size is damage. The attributes precede the data: the first 64 kB are scanned.
void check_xml_counts(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(65536, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  const double limit = 1000.0 * static_cast<double>(std::filesystem::file_size(file)) + 1e6;
  for (std::size_t at = head.find("NumberOf"); at != std::string::npos; at = head.find("NumberOf", at + 8)) {
    const std::size_t eq = head.find("=\"", at);
    if (eq == std::string::npos || eq > at + 40) continue;
    const std::string name = head.substr(at, eq - at);
    const double n = std::strtod(head.c_str() + eq + 2, nullptr);
    if (n > limit || n < 0)
      throw InputError(fmt::format("{}: {} = {:.0f} is more than a file of {} bytes can hold (damaged?)", file, name,
                                   n, std::filesystem::file_size(file)));
  }
}

// Runs an XML reader; its error events (a short array, bad offsets: it returns what it
// read so far) and a failed allocation are InputErrors naming the file.
void read_xml(vtkXMLReader* r, const std::string& file) {
  vtkNew<VtkReadErrors> errors;
  r->AddObserver(vtkCommand::ErrorEvent, errors);
  r->SetFileName(file.c_str());
  try {
    r->Update();
  } catch (const std::bad_alloc&) {
    throw InputError(fmt::format("{}: the file asks for more memory than there is (a damaged count?)", file));
  }
  if (!errors->first.empty() || r->GetErrorCode() != 0)
    throw InputError(fmt::format("{}: the file could not be read: {} (damaged or cut short?)", file,
                                 errors->first.empty() ? "VTK error code " + std::to_string(r->GetErrorCode()) : errors->first));
}

// What VTK reads as it is from a damaged file: a cell that refers past the points, an
// array with another tuple count than its points or cells.
void check_read(const MeshData& m, const std::string& file) {
  const auto n = static_cast<std::int64_t>(m.points.size());
  for (std::size_t i = 0; i < m.connectivity.size(); ++i)
    if (m.connectivity[i] < 0 || m.connectivity[i] >= n)
      throw InputError(fmt::format("{}: a cell refers to point {}, but the file has {} points (damaged?)", file, m.connectivity[i], n));
  for (const auto& [data, count, kind] : {std::tuple(&m.point_data, m.points.size(), "point"), std::tuple(&m.cell_data, m.num_cells(), "cell")})
    for (const auto& [name, a] : *data)
      if (a.components < 1 || a.values.size() != count * static_cast<std::size_t>(a.components))
        throw InputError(fmt::format("{}: {} array '{}' holds {} values in {} components for {} {}s (damaged?)", file, kind, name,
                                     a.values.size(), a.components, count, kind));
}

}  // namespace

void write_vtu(const std::string& file, const MeshData& m) {
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(to_vtk_points(m));
  vtkNew<vtkIdTypeArray> offsets, conn;
  offsets->SetNumberOfTuples(static_cast<vtkIdType>(m.cell_offsets.size()));
  for (std::size_t i = 0; i < m.cell_offsets.size(); ++i) offsets->SetValue(static_cast<vtkIdType>(i), m.cell_offsets[i]);
  conn->SetNumberOfTuples(static_cast<vtkIdType>(m.connectivity.size()));
  for (std::size_t i = 0; i < m.connectivity.size(); ++i) conn->SetValue(static_cast<vtkIdType>(i), m.connectivity[i]);
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, conn);
  vtkNew<vtkUnsignedCharArray> types;
  types->SetNumberOfTuples(static_cast<vtkIdType>(m.cell_types.size()));
  for (std::size_t i = 0; i < m.cell_types.size(); ++i) types->SetValue(static_cast<vtkIdType>(i), static_cast<unsigned char>(m.cell_types[i]));
  grid->SetCells(types, cells);
  add_arrays(grid->GetPointData(), m.point_data);
  add_arrays(grid->GetCellData(), m.cell_data);
  add_field_text(grid, m.field_text);
  write_with<vtkXMLUnstructuredGridWriter>(file, grid.GetPointer());
}

void write_vtp(const std::string& file, const MeshData& m) {
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(to_vtk_points(m));
  vtkNew<vtkCellArray> lines, polys, verts;
  // VTK orders poly data cells as verts, lines, polys: keep cell data in that order.
  std::vector<std::size_t> order;
  for (int pass = 0; pass < 3; ++pass) {
    for (std::size_t c = 0; c < m.num_cells(); ++c) {
      const CellType t = m.cell_types[c];
      const int kind = t == CellType::vertex ? 0 : (t == CellType::line || t == CellType::polyline) ? 1
                       : (t == CellType::triangle || t == CellType::quad) ? 2 : -1;
      if (kind < 0) throw ComputeError(fmt::format("{}: cell type {} cannot be written to VTP", file, static_cast<int>(t)));
      if (kind != pass) continue;
      auto nodes = m.cell(c);
      std::vector<vtkIdType> ids(nodes.begin(), nodes.end());
      (kind == 0 ? verts : kind == 1 ? lines : polys)->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
      order.push_back(c);
    }
  }
  poly->SetVerts(verts);
  poly->SetLines(lines);
  poly->SetPolys(polys);
  add_arrays(poly->GetPointData(), m.point_data);
  std::map<std::string, DataArray> reordered;
  for (const auto& [name, a] : m.cell_data) {
    DataArray r{a.components, {}};
    for (std::size_t c : order)
      for (int k = 0; k < a.components; ++k) r.values.push_back(a.at(c, k));
    reordered[name] = std::move(r);
  }
  add_arrays(poly->GetCellData(), reordered);
  add_field_text(poly, m.field_text);
  write_with<vtkXMLPolyDataWriter>(file, poly.GetPointer());
}

void check_vtk_xml_file(const std::string& file) {
  files::require_regular_file(file);
  check_xml_counts(file);
  const std::string ext = std::filesystem::path(file).extension().string();
  process::probe_read_in_child(file, "VTK XML", [&] {
    // The forked child has none of the parent's TBB worker threads: VTK's parallel loops
    // would wait for them forever.
    use_sequential_vtk_smp();
    vtkSmartPointer<vtkXMLReader> r;
    if (ext == ".vtp") r = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    else r = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    // VTK reports a failed allocation as an error event, not an exception: the probe
    // turns it into one, so the file is refused instead of read again unbounded.
    vtkNew<VtkReadErrors> errors;
    r->AddObserver(vtkCommand::ErrorEvent, errors);
    r->SetFileName(file.c_str());
    r->Update();
    if (errors->first.find("llocat") != std::string::npos) throw std::bad_alloc();
  });
}

MeshData read_vtu(const std::string& file) {
  check_vtk_xml_file(file);
  vtkNew<vtkXMLUnstructuredGridReader> r;
  read_xml(r, file);
  vtkUnstructuredGrid* g = r->GetOutput();
  if (!g) throw InputError(fmt::format("{}: not a readable VTU file", file));
  MeshData m;
  read_points(g, m);
  for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
    vtkIdType npts;
    const vtkIdType* pts;
    g->GetCellPoints(c, npts, pts);
    m.add_cell(static_cast<CellType>(g->GetCellType(c)), std::vector<std::int64_t>(pts, pts + npts));
  }
  m.point_data = read_arrays(g->GetPointData());
  m.cell_data = read_arrays(g->GetCellData());
  m.field_text = read_field_text(g);
  check_read(m, file);
  return m;
}

MeshData read_vtp(const std::string& file) {
  check_vtk_xml_file(file);
  vtkNew<vtkXMLPolyDataReader> r;
  read_xml(r, file);
  vtkPolyData* p = r->GetOutput();
  if (!p) throw InputError(fmt::format("{}: not a readable VTP file", file));
  MeshData m;
  read_points(p, m);
  for (vtkIdType c = 0; c < p->GetNumberOfCells(); ++c) {
    vtkIdType npts;
    const vtkIdType* pts;
    p->GetCellPoints(c, npts, pts);
    const int vt = p->GetCellType(c);
    CellType t = vt == VTK_VERTEX ? CellType::vertex : vt == VTK_LINE ? CellType::line : vt == VTK_POLY_LINE ? CellType::polyline
               : vt == VTK_TRIANGLE ? CellType::triangle : vt == VTK_QUAD ? CellType::quad : CellType::polyline;
    if (vt == VTK_POLYGON || vt == VTK_TRIANGLE_STRIP)
      throw InputError(fmt::format("{}: cell {} is a polygon or strip; triangulate the surface first", file, c));
    m.add_cell(t, std::vector<std::int64_t>(pts, pts + npts));
  }
  m.point_data = read_arrays(p->GetPointData());
  m.cell_data = read_arrays(p->GetCellData());
  m.field_text = read_field_text(p);
  check_read(m, file);
  return m;
}

}  // namespace stentsim
