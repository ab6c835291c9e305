#include "workflows/lumen_export.hpp"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSTLWriter.h>

#include <array>
#include <unordered_map>
#include <vector>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_tags.hpp"
#include "segmentation_io/surface_input.hpp"

namespace stentsim::workflows {

MeshData deformed_lumen(const std::filesystem::path& frame, const std::string& units) {
  const MeshData m = read_vtu(frame.string());
  const auto groups = m.cell_data.find(tags::kFaceGroup);
  const auto disp = m.point_data.find("Displacement");
  if (groups == m.cell_data.end() || disp == m.point_data.end() || disp->second.components != 3 ||
      disp->second.tuples() != m.points.size())
    throw InputError(fmt::format("{}: an artery result frame needs the cell array {} and the point array Displacement (3 "
                                 "components per point); is it a stentsim solve's artery frame?",
                                 frame.string(), tags::kFaceGroup));
  const double scale = 1.0 / segmentation::unit_length_in_mm(units);
  MeshData out;
  out.field_text["units"] = units;
  out.field_text["content"] = "deformed endothelium (lumen) of the last solve frame, open at the cuts";
  std::unordered_map<std::int64_t, std::int64_t> index;  // frame point -> surface point
  auto point = [&](std::int64_t p) {
    const auto [it, added] = index.try_emplace(p, static_cast<std::int64_t>(out.points.size()));
    if (added) {
      const auto k = static_cast<std::size_t>(p);
      out.points.push_back(scale * (m.points[k] + Eigen::Vector3d(disp->second.at(k, 0), disp->second.at(k, 1), disp->second.at(k, 2))));
    }
    return it->second;
  };
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (static_cast<int>(groups->second.at(c)) != tags::endothelium) continue;
    const auto n = m.cell(c);
    std::vector<std::array<std::int64_t, 3>> tris;
    switch (m.cell_types[c]) {
      case CellType::triangle: tris = {{n[0], n[1], n[2]}}; break;
      case CellType::quad: tris = {{n[0], n[1], n[2]}, {n[0], n[2], n[3]}}; break;
      case CellType::quadratic_triangle:  // corners 0 1 2, mid-side nodes 3 (0-1), 4 (1-2), 5 (2-0): VTK order
        tris = {{n[0], n[3], n[5]}, {n[3], n[1], n[4]}, {n[5], n[4], n[2]}, {n[3], n[4], n[5]}};
        break;
      case CellType::tetra:
      case CellType::quadratic_tetra:
      case CellType::hexahedron: continue;  // volume cells: their FaceGroup is 0 anyway
      default:
        throw InputError(fmt::format("{}: cell {} is tagged endothelium but is no triangle, quadratic triangle or quad", frame.string(), c));
    }
    // The mesh winds its faces with the normal out of the wall, into the lumen; a flow
    // domain's boundary faces the other way (out of the fluid), so each triangle is reversed.
    for (const auto& t : tris) out.add_cell(CellType::triangle, {point(t[0]), point(t[2]), point(t[1])});
  }
  if (out.num_cells() == 0)
    throw InputError(fmt::format("{}: no endothelium faces ({} = {}) in this artery frame", frame.string(), tags::kFaceGroup,
                                 static_cast<int>(tags::endothelium)));
  return out;
}

void write_lumen(const MeshData& surface, const std::filesystem::path& vtp, const std::filesystem::path& stl) {
  write_vtp(vtp.string(), surface);
  vtkNew<vtkPoints> points;
  for (const auto& p : surface.points) points->InsertNextPoint(p.x(), p.y(), p.z());
  vtkNew<vtkCellArray> polys;
  for (std::size_t c = 0; c < surface.num_cells(); ++c) {
    const auto n = surface.cell(c);
    const vtkIdType ids[3] = {n[0], n[1], n[2]};
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(polys);
  const std::filesystem::path tmp = files::temporary_name_for(stl);
  vtkNew<vtkSTLWriter> writer;
  writer->SetFileName(tmp.string().c_str());
  writer->SetInputData(poly);
  writer->SetFileTypeToBinary();
  writer->SetHeader("stentsim: deformed lumen after deflation");
  if (writer->Write() != 1 || writer->GetErrorCode() != 0) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(fmt::format("could not write {}", stl.string()));
  }
  files::replace(tmp, stl);
}

}  // namespace stentsim::workflows
