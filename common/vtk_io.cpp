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
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <filesystem>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"

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

void require_readable(const std::string& file) {
  if (!std::filesystem::exists(file)) throw InputError(fmt::format("{}: file not found", file));
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

MeshData read_vtu(const std::string& file) {
  require_readable(file);
  vtkNew<vtkXMLUnstructuredGridReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  vtkUnstructuredGrid* g = r->GetOutput();
  if (r->GetErrorCode() != 0 || !g) throw InputError(fmt::format("{}: not a readable VTU file", file));
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
  return m;
}

MeshData read_vtp(const std::string& file) {
  require_readable(file);
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  vtkPolyData* p = r->GetOutput();
  if (r->GetErrorCode() != 0 || !p) throw InputError(fmt::format("{}: not a readable VTP file", file));
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
  return m;
}

}  // namespace stentsim
