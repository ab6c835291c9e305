// The deformed lumen after deflation (workflows/lumen_export.hpp): the
// endothelium faces of an artery frame moved by their displacement, split into
// linear triangles, with only the points they use, in the input's units; and
// the .vtp and binary .stl it writes read back.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>

#include <Eigen/Geometry>

#include "common/error.hpp"
#include "common/mesh_tags.hpp"
#include "segmentation_io/surface_input.hpp"
#include "workflows/lumen_export.hpp"

namespace stentsim::workflows {
namespace {

namespace fs = std::filesystem;

/// One tet10 with its face 0-1-2 as a tri6 endothelium face, a tri6 outer face (1-2-3), and a displacement u(X) = (X_z, 2 X_x, 0.5).
MeshData frame() {
  MeshData m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0, 0}, {0.5, 0.5, 0}, {0, 0.5, 0}, {0, 0, 0.5}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  m.add_cell(CellType::quadratic_tetra, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  m.add_cell(CellType::quadratic_triangle, {0, 1, 2, 4, 5, 6});
  m.add_cell(CellType::quadratic_triangle, {1, 2, 3, 5, 9, 8});
  m.cell_data[tags::kFaceGroup] = {1, {0.0, double(tags::endothelium), double(tags::outer_wall)}};
  DataArray u{3, {}};
  for (const auto& x : m.points) u.values.insert(u.values.end(), {x.z(), 2 * x.x(), 0.5});
  m.point_data["Displacement"] = u;
  return m;
}

TEST(LumenExport, EndotheliumMovedSplitAndScaled) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_lumen_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_vtu((dir / "artery_00003.vtu").string(), frame());
  const MeshData mm = deformed_lumen(dir / "artery_00003.vtu", "mm");
  ASSERT_EQ(mm.num_cells(), 4u);    // a tri6 as four triangles
  ASSERT_EQ(mm.points.size(), 6u);  // the face's six nodes only (not node 3 or the outer face's 8, 9)
  for (const auto& p : mm.points) {
    // Every point of the face has X_z = 0: x = X + (0, 2 X_x, 0.5), so x_y = X_y + 2 x_x with X_y in [0, 1].
    EXPECT_NEAR(p.z(), 0.5, 1e-12);
    EXPECT_GE(p.y() - 2 * p.x(), -1e-12);
    EXPECT_LE(p.y() - 2 * p.x(), 1 + 1e-12);
  }
  double area = 0.0;
  for (std::size_t c = 0; c < mm.num_cells(); ++c) {
    const auto n = mm.cell(c);
    area += 0.5 * (mm.points[static_cast<std::size_t>(n[1])] - mm.points[static_cast<std::size_t>(n[0])])
                      .cross(mm.points[static_cast<std::size_t>(n[2])] - mm.points[static_cast<std::size_t>(n[0])])
                      .norm();
  }
  // The face (0,0),(1,0),(0,1) maps to (0,0),(1,2),(0,1) in the plane z = 0.5: area 1/2 · |det [[1, 0], [2, 1]]| = 1/2.
  EXPECT_NEAR(area, 0.5, 1e-12);
  // The mesh's face 0-1-2 has its normal along +z (out of its tet, into the lumen); the lumen's triangles face the other way.
  for (std::size_t c = 0; c < mm.num_cells(); ++c) {
    const auto n = mm.cell(c);
    const Eigen::Vector3d a = mm.points[static_cast<std::size_t>(n[0])], b = mm.points[static_cast<std::size_t>(n[1])],
                          d = mm.points[static_cast<std::size_t>(n[2])];
    EXPECT_LT((b - a).cross(d - a).z(), 0.0) << "triangle " << c;
  }
  // In cm: every coordinate a tenth.
  const MeshData cm = deformed_lumen(dir / "artery_00003.vtu", "cm");
  ASSERT_EQ(cm.points.size(), mm.points.size());
  for (std::size_t i = 0; i < cm.points.size(); ++i) EXPECT_LT((10 * cm.points[i] - mm.points[i]).norm(), 1e-12);
  EXPECT_EQ(cm.field_text.at("units"), "cm");

  write_lumen(mm, dir / "lumen_after.vtp", dir / "lumen_after.stl");
  const segmentation::TriSurface stl = segmentation::read_surface_file(dir / "lumen_after.stl");
  EXPECT_EQ(stl.num_triangles(), 4u);
  EXPECT_EQ(fs::file_size(dir / "lumen_after.stl"), 84u + 50u * 4u);  // binary
  const segmentation::TriSurface vtp = segmentation::read_surface_file(dir / "lumen_after.vtp");
  EXPECT_EQ(vtp.num_triangles(), 4u);
  fs::remove_all(dir);
}

TEST(LumenExport, AFrameWithoutEndotheliumIsNamed) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_lumen_none_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  MeshData m = frame();
  m.cell_types[1] = CellType::line;  // a cell tagged endothelium that is no face
  m.cell_offsets = {0, 10, 12, 18};
  m.connectivity = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 0, 1, 1, 2, 3, 5, 9, 8};
  write_vtu((dir / "line.vtu").string(), m);
  EXPECT_THROW(deformed_lumen(dir / "line.vtu", "mm"), InputError);
  m = frame();
  m.cell_data[tags::kFaceGroup].values[1] = tags::outer_wall;
  write_vtu((dir / "a.vtu").string(), m);
  try {
    deformed_lumen(dir / "a.vtu", "mm");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.vtu"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no endothelium"), std::string::npos) << e.what();
  }
  m.point_data.erase("Displacement");
  write_vtu((dir / "b.vtu").string(), m);
  EXPECT_THROW(deformed_lumen(dir / "b.vtu", "mm"), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::workflows
