// Surface input: each reader on fixtures the test writes itself, unit sanity,
// and every check's repair or error message.
#include <gtest/gtest.h>

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <set>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sys/stat.h>
#include <unistd.h>
#include <fstream>
#include <limits>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/log.hpp"
#include "common/self_intersection.hpp"
#include "segmentation_io/label_image.hpp"
#include "segmentation_io/simvascular_io.hpp"
#include "segmentation_io/centerline.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "segmentation_io/surface_distance.hpp"
#include "segmentation_io/surface_input.hpp"
#include "tests/segmentation_io/polydata_fixture.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

namespace {

// A small healthy tube (24 around, 10 mm): fast fixtures.
TriSurface small_tube() {
  PhantomSpec s = phantom_preset("straight-healthy", 1);
  s.length = 10;
  s.circumferential_points = 24;
  return surface_from_mesh(build_phantom(s).lumen, "tube");
}

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("stentsim_test_surface_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_stl_ascii(const fs::path& f, const TriSurface& s) {
  std::ofstream o(f);
  o << "solid test\n";
  for (const auto& t : s.triangles) {
    Eigen::Vector3d n = (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]).normalized();
    o << "facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n outer loop\n";
    for (int v : t) o << "  vertex " << s.points[v].x() << " " << s.points[v].y() << " " << s.points[v].z() << "\n";
    o << " endloop\nendfacet\n";
  }
  o << "endsolid test\n";
}

void write_stl_binary(const fs::path& f, const TriSurface& s) {
  std::ofstream o(f, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "binary stl written by the stentsim test", 79);
  o.write(header, 80);
  std::uint32_t n = std::uint32_t(s.triangles.size());
  o.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : s.triangles) {
    float v[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) v[3 + 3 * k + c] = float(s.points[t[k]][c]);
    o.write(reinterpret_cast<const char*>(v), 48);
    std::uint16_t attr = 0;
    o.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

void write_obj(const fs::path& f, const TriSurface& s) {
  std::ofstream o(f);
  o.precision(17);
  for (const auto& p : s.points) o << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& t : s.triangles) o << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

void write_legacy_vtk(const fs::path& f, const TriSurface& s) {
  std::ofstream o(f);
  o.precision(17);
  o << "# vtk DataFile Version 3.0\ntube\nASCII\nDATASET POLYDATA\nPOINTS " << s.points.size() << " double\n";
  for (const auto& p : s.points) o << p.x() << " " << p.y() << " " << p.z() << "\n";
  o << "POLYGONS " << s.triangles.size() << " " << 4 * s.triangles.size() << "\n";
  for (const auto& t : s.triangles) o << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

}  // namespace

TEST(SurfaceReaders, EveryFormatGivesTheSameSurface) {
  TriSurface ref = small_tube();
  fs::path d = temp_dir("readers");
  write_vtp((d / "t.vtp").string(), mesh_from_surface(ref));
  write_legacy_vtk(d / "t.vtk", ref);
  write_stl_ascii(d / "t_ascii.stl", ref);
  write_stl_binary(d / "t_binary.stl", ref);
  write_obj(d / "t.obj", ref);
  for (const char* f : {"t.vtp", "t.vtk", "t_ascii.stl", "t_binary.stl", "t.obj"}) {
    TriSurface s = read_surface_file(d / f);
    EXPECT_EQ(s.num_triangles(), ref.num_triangles()) << f;
    EXPECT_EQ(s.points.size(), ref.points.size()) << f;  // STL: merged back to shared vertices
    EXPECT_NEAR(surface_area(s), surface_area(ref), 1e-5 * surface_area(ref)) << f;
    SurfaceReport rep;
    TriSurface c = check_and_repair(s, {}, f, rep);
    EXPECT_EQ(rep.open_ends, 2) << f;
    EXPECT_TRUE(rep.notes.empty()) << f << ": " << (rep.notes.empty() ? "" : rep.notes[0]);
  }
  fs::remove_all(d);
}

TEST(SurfaceReaders, ClearErrors) {
  fs::path d = temp_dir("reader_errors");
  EXPECT_CONTAINS(error_of([&] { read_surface_file(d / "missing.stl"); }), "not found");
  std::ofstream(d / "x.ply") << "ply\n";
  EXPECT_CONTAINS(error_of([&] { read_surface_file(d / "x.ply"); }), "unknown surface format");
  std::ofstream(d / "junk.vtp") << "this is not xml";
  EXPECT_CONTAINS(error_of([&] { read_surface_file(d / "junk.vtp"); }), "junk.vtp");
  std::ofstream(d / "grid.vtk") << "# vtk DataFile Version 3.0\ng\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 0 double\n";
  EXPECT_CONTAINS(error_of([&] { read_surface_file(d / "grid.vtk"); }), "POLYDATA");
  fs::remove_all(d);
}

// Binary STL by the size rule (84 + 50 n bytes), not by a "solid" prefix; a file
// cut short is an error, extra bytes a warning; a huge count in the header is
// checked against the size before anything is allocated; NaN is named.
TEST(SurfaceReaders, BinaryStlBySizeRule) {
  const TriSurface ref = small_tube();
  const fs::path d = temp_dir("stl_size_rule");
  write_stl_binary(d / "b.stl", ref);
  std::string bytes;
  {
    std::ifstream in(d / "b.stl", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto write = [&](const char* name, const std::string& b) {
    std::ofstream(d / name, std::ios::binary) << b;
    return d / name;
  };
  // A binary header that starts with "solid" (as many exporters write it).
  std::string solid = bytes;
  std::memcpy(solid.data(), "solid exported by a CAD tool", 28);
  const TriSurface s = read_surface_file(write("solid_header.stl", solid));
  EXPECT_EQ(s.num_triangles(), ref.num_triangles());
  EXPECT_EQ(s.points.size(), ref.points.size());
  // Cut short by 20 bytes: an error naming the count and the sizes.
  const std::string cut = error_of([&] { read_surface_file(write("cut.stl", bytes.substr(0, bytes.size() - 20))); });
  EXPECT_CONTAINS(cut, "cut.stl");
  EXPECT_CONTAINS(cut, "cut short");
  EXPECT_CONTAINS(cut, std::to_string(ref.num_triangles()) + " triangles");
  // Trailing bytes: read with a warning that names the file and the extra bytes, the same surface.
  log::set_file(d / "warnings.log");
  EXPECT_EQ(read_surface_file(write("longer.stl", bytes + std::string(10, '\0'))).num_triangles(), ref.num_triangles());
  log::set_file({});
  const std::string warned = stentsim::files::read_text(d / "warnings.log");
  EXPECT_CONTAINS(warned, "warning");
  EXPECT_CONTAINS(warned, "longer.stl");
  EXPECT_CONTAINS(warned, "10");
  // A header claiming 2^31 triangles in a small file: the size rule names the file,
  // the count and the size it would need, before anything is allocated.
  std::string huge = bytes;
  const std::uint32_t n = 1u << 31;
  std::memcpy(huge.data() + 80, &n, 4);
  const std::string huge_error = error_of([&] { read_surface_file(write("huge.stl", huge)); });
  EXPECT_CONTAINS(huge_error, "huge.stl");
  EXPECT_CONTAINS(huge_error, "2147483648 triangles");
  EXPECT_CONTAINS(huge_error, "cut short");
  EXPECT_CONTAINS(huge_error, std::to_string(84ull + 50ull * n));
  // A NaN coordinate, named by triangle and vertex.
  std::string nan = bytes;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + 84 + 50 * 3 + 12 + 12 + 4, &q, 4);  // triangle 4, vertex 2, y
  EXPECT_CONTAINS(error_of([&] { read_surface_file(write("nan.stl", nan)); }), "vertex 2 of triangle 4");
  // Neither kind: a few bytes that are no text.
  EXPECT_CONTAINS(error_of([&] { read_surface_file(write("tiny.stl", std::string("\x01\x02\x03", 3))); }),
                  "neither an ASCII STL");
  fs::remove_all(d);
}

// A cell that refers past the point list, in every VTK-read format, and a folder
// given as the surface: clear errors, never a crash in a VTK filter.
TEST(SurfaceReaders, OutOfRangeIndicesAndFoldersAreErrors) {
  const fs::path d = temp_dir("reader_indices");
  std::ofstream(d / "bad.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 99\n";
  std::ofstream(d / "bad.vtk") << "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 double\n"
                                  "0 0 0\n1 0 0\n0 1 0\nPOLYGONS 2 8\n3 0 1 2\n3 0 1 7\n";
  std::ofstream(d / "bad.vtp") << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\">\n<PolyData>\n"
                                  "<Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\">\n<Points><DataArray type=\"Float64\" "
                                  "NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0</DataArray></Points>\n"
                                  "<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 12345"
                                  "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">3</DataArray>"
                                  "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  for (const char* f : {"bad.obj", "bad.vtk", "bad.vtp"}) {
    const std::string e = error_of([&] { read_surface_file(d / f); });
    EXPECT_CONTAINS(e, f);
    EXPECT_CONTAINS(e, "3 points");
  }
  fs::create_directories(d / "folder.stl");
  EXPECT_CONTAINS(error_of([&] { read_surface_file(d / "folder.stl"); }), "not a regular file");
  fs::remove_all(d);
}

// A FIFO or a device given as an input (directly or through a symbolic link) would block
// a reader or feed it without end: every reader a user can feed refuses it at once.
TEST(SurfaceReaders, FifosAndDevicesAreRefusedWithoutReading) {
  const fs::path d = fs::temp_directory_path() / ("stentsim-fifo-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  ASSERT_EQ(::mkfifo((d / "pipe").c_str(), 0600), 0);
  const std::vector<std::string> names = {"lumen.stl", "lumen.vtp", "label.nii.gz", "label.mha", "path.pth", "seg.ctgr"};
  for (const std::string& target : {(d / "pipe").string(), std::string("/dev/zero")}) {
    for (const auto& n : names) {
      fs::remove(d / n);
      fs::create_symlink(target, d / n);
    }
    const std::vector<std::pair<std::string, std::function<void()>>> readers = {
        {"lumen.stl", [&] { read_surface_file(d / "lumen.stl"); }},
        {"lumen.vtp", [&] { read_surface_file(d / "lumen.vtp"); }},
        {"label.nii.gz", [&] { label_image_surface(d / "label.nii.gz", LabelSurfaceOptions{}); }},
        {"label.mha", [&] { label_image_surface(d / "label.mha", LabelSurfaceOptions{}); }},
        {"path.pth", [&] { read_simvascular_path(d / "path.pth"); }},
        {"seg.ctgr", [&] { read_simvascular_contours(d / "seg.ctgr"); }},
        {"lumen.stl", [&] { stentsim::files::read_text(d / "lumen.stl"); }},
    };
    for (const auto& [name, read] : readers) {
      const std::string e = error_of(read);
      EXPECT_CONTAINS(e, name);
      EXPECT_CONTAINS(e, "not a regular file (a folder, device or pipe)");
    }
  }
  fs::remove_all(d);
}

// A binary legacy VTK file whose version line is damaged ("5.1" -> "nan.1", a fuzz
// mutant): VTK's reader then takes the 5.1 sections for the old layout and crashed
// the process (SIGSEGV) on the raw OFFSETS; now the file is refused by name. The
// binary file as written, and one with its version line intact, still read.
TEST(SurfaceReaders, DamagedBinaryLegacyVtkIsRefusedNotACrash) {
  const fs::path d = temp_dir("legacy_vtk_binary");
  const TriSurface ref = small_tube();
  auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
  w->SetInputData(to_polydata(ref));
  w->SetFileTypeToBinary();
  w->SetFileName((d / "good.vtk").c_str());
  w->Write();
  EXPECT_EQ(read_surface_file(d / "good.vtk").num_triangles(), ref.num_triangles());
  std::string text = stentsim::files::read_text(d / "good.vtk");
  const auto at = text.find("Version 5.1");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 11, "Version nan.1");
  std::ofstream(d / "damaged.vtk", std::ios::binary) << text;
  const std::string e = error_of([&] { read_surface_file(d / "damaged.vtk"); });
  EXPECT_CONTAINS(e, (d / "damaged.vtk").string());
  EXPECT_CONTAINS(e, "legacy VTK");
  fs::remove_all(d);
}

// Legacy VTK as VTK 9.1's writer makes it (5.1: OFFSETS/CONNECTIVITY, dataset FIELD data
// before the points, polygons and a triangle strip): stentsim's parser gives VTK's own
// triangulation, orientation included.
TEST(SurfaceReaders, LegacyVtkAsVtkWritesIt) {
  const fs::path d = temp_dir("legacy_vtk51");
  const TriSurface ref = small_tube();
  auto pd = to_polydata(ref);
  auto strips = vtkSmartPointer<vtkCellArray>::New();
  const vtkIdType strip[5] = {0, 1, 24, 25, 2};
  strips->InsertNextCell(5, strip);
  pd->SetStrips(strips);
  auto field = vtkSmartPointer<vtkDoubleArray>::New();
  field->SetName("TimeValue");
  field->InsertNextValue(0.5);
  pd->GetFieldData()->AddArray(field);
  auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
  w->SetInputData(pd);
  w->SetFileName((d / "t.vtk").c_str());
  w->Write();
  const std::string text = [&] { std::ifstream f(d / "t.vtk"); return std::string(std::istreambuf_iterator<char>(f), {}); }();
  ASSERT_NE(text.find("OFFSETS"), std::string::npos) << "not the 5.1 form";
  ASSERT_NE(text.find("FIELD"), std::string::npos);
  const TriSurface s = read_surface_file(d / "t.vtk");
  auto tri = vtkSmartPointer<vtkTriangleFilter>::New();
  tri->SetInputData(pd);
  tri->Update();
  std::set<std::array<int, 3>> vtk;  // each triangle rotated to start at its smallest index (orientation kept)
  auto canon = [](std::array<int, 3> t) {
    while (t[0] != std::min({t[0], t[1], t[2]})) std::rotate(t.begin(), t.begin() + 1, t.end());
    return t;
  };
  vtkCellArray* out = tri->GetOutput()->GetPolys();
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  for (out->InitTraversal(); out->GetNextCell(n, ids);) vtk.insert(canon({int(ids[0]), int(ids[1]), int(ids[2])}));
  std::set<std::array<int, 3>> ours;
  for (const auto& t : s.triangles) ours.insert(canon(t));
  EXPECT_EQ(s.num_triangles(), ref.num_triangles() + 3);
  EXPECT_EQ(ours, vtk);
  fs::remove_all(d);
}

TEST(SurfaceChecks, UnitsThatSayMetresAreReported) {
  TriSurface t = small_tube();
  for (auto& p : t.points) p *= 1e-3;  // the same tube written in metres
  SurfaceReport rep;
  EXPECT_CONTAINS(error_of([&] { check_and_repair(t, {}, "lumen.stl", rep); }), "looks like it is in metres");
  SurfaceCheckOptions o;
  o.units = "m";
  TriSurface ok = check_and_repair(t, o, "lumen.stl", rep);
  EXPECT_NEAR(bounding_box_diagonal(ok), bounding_box_diagonal(small_tube()), 1e-9);
}

TEST(SurfaceChecks, DuplicatePointsAreMerged) {
  TriSurface t = small_tube();
  // Give triangle 5 its own copies of its vertices (as an STL would).
  for (int& v : t.triangles[5]) {
    t.points.push_back(t.points[v]);
    v = int(t.points.size()) - 1;
  }
  SurfaceReport rep;
  TriSurface r = check_and_repair(t, {}, "lumen", rep);
  EXPECT_EQ(rep.merged_points, 3);
  EXPECT_EQ(r.points.size(), small_tube().points.size());
  SurfaceCheckOptions strict;
  strict.repair = false;
  EXPECT_CONTAINS(error_of([&] { check_and_repair(t, strict, "lumen", rep); }), "duplicate points");
}

TEST(SurfaceChecks, DegenerateAndDuplicateTrianglesAreRemoved) {
  TriSurface t = small_tube();
  t.triangles.push_back({3, 3, 4});
  t.triangles.push_back(t.triangles[10]);
  SurfaceReport rep;
  TriSurface r = check_and_repair(t, {}, "lumen", rep);
  EXPECT_EQ(rep.degenerate_triangles, 1);
  EXPECT_EQ(rep.duplicate_triangles, 1);
  EXPECT_EQ(r.num_triangles(), small_tube().num_triangles());
  SurfaceCheckOptions strict;
  strict.repair = false;
  EXPECT_CONTAINS(error_of([&] { check_and_repair(t, strict, "lumen", rep); }), "degenerate");
  // Nothing but degenerate triangles (collinear corners over 10 mm): an error, not an empty surface downstream.
  TriSurface line;
  for (int i = 0; i < 30; ++i) {
    line.points.emplace_back(0.3 * i, 0.6 * i, 0.0);
    if (i >= 2) line.triangles.push_back({i - 2, i - 1, i});
  }
  EXPECT_CONTAINS(error_of([&] { check_and_repair(line, {}, "line.stl", rep); }), "all 28 triangles are degenerate");
}

TEST(SurfaceChecks, NonManifoldEdgeIsAnError) {
  TriSurface t = small_tube();
  auto e = t.triangles[400];  // strip 8: all its edges are inner edges
  t.points.push_back(Eigen::Vector3d(5, 5, 5));
  t.triangles.push_back({e[0], e[1], int(t.points.size()) - 1});  // a fin on an inner edge
  SurfaceReport rep;
  std::string msg = error_of([&] { check_and_repair(t, {}, "lumen.stl", rep); });
  EXPECT_CONTAINS(msg, "lumen.stl");
  EXPECT_CONTAINS(msg, "non-manifold");
}

TEST(SurfaceChecks, SmallHoleIsFilledLargeOneIsAnError) {
  TriSurface t = small_tube();
  TriSurface small = t;
  small.triangles.erase(small.triangles.begin() + 200, small.triangles.begin() + 202);
  SurfaceReport rep;
  TriSurface r = check_and_repair(small, {}, "lumen", rep);
  EXPECT_EQ(rep.holes_filled, 1);
  EXPECT_EQ(boundary_loops(r).size(), 2u);
  // A window of two rings: a hole that is not small.
  TriSurface big = t;
  const int N = 24;
  std::vector<std::array<int, 3>> keep;
  for (std::size_t i = 0; i < big.triangles.size(); ++i) {
    std::size_t strip = i / (2 * N), j = (i % (2 * N)) / 2;
    if ((strip == 20 || strip == 21) && j < 8) continue;  // an 8 × 2 window
    keep.push_back(big.triangles[i]);
  }
  big.triangles = keep;
  std::string msg = error_of([&] { check_and_repair(big, {}, "lumen", rep); });
  EXPECT_CONTAINS(msg, "open boundaries");
}

TEST(SurfaceChecks, DisconnectedPieces) {
  TriSurface t = small_tube();
  TriSurface tiny = small_tube();
  // A tiny speck far away: dropped.
  TriSurface with_speck = t;
  int base = int(with_speck.points.size());
  with_speck.points.push_back({20, 0, 0});
  with_speck.points.push_back({20.01, 0, 0});
  with_speck.points.push_back({20, 0.01, 0});
  with_speck.triangles.push_back({base, base + 1, base + 2});
  SurfaceReport rep;
  TriSurface r = check_and_repair(with_speck, {}, "lumen", rep);
  EXPECT_EQ(rep.pieces_dropped, 1);
  EXPECT_EQ(r.num_triangles(), t.num_triangles());
  // A second full tube beside it: an error listing the pieces.
  TriSurface two = t;
  base = int(two.points.size());
  for (auto p : tiny.points) two.points.push_back(p + Eigen::Vector3d(5, 0, 0));
  for (auto tr : tiny.triangles) two.triangles.push_back({tr[0] + base, tr[1] + base, tr[2] + base});
  EXPECT_CONTAINS(error_of([&] { check_and_repair(two, {}, "lumen", rep); }), "2 disconnected pieces");
}

TEST(SurfaceChecks, InvertedAndInconsistentNormalsAreTurned) {
  TriSurface t = small_tube();
  for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
  SurfaceReport rep;
  TriSurface r = check_and_repair(t, {}, "lumen", rep);
  EXPECT_TRUE(rep.normals_inverted);
  EXPECT_GT(signed_volume(capped(r, boundary_loops(r))), 0);
  TriSurface mixed = small_tube();
  for (int i : {7, 100, 333}) std::swap(mixed.triangles[i][1], mixed.triangles[i][2]);
  SurfaceReport rep2;
  TriSurface r2 = check_and_repair(mixed, {}, "lumen", rep2);
  EXPECT_EQ(rep2.orientation_flips, 3);
  EXPECT_FALSE(rep2.normals_inverted);
  EXPECT_NEAR(signed_volume(capped(r2, boundary_loops(r2))), signed_volume(capped(small_tube(), boundary_loops(small_tube()))), 1e-9);
}

TEST(SurfaceChecks, SelfIntersectionIsAnError) {
  TriSurface t = small_tube();
  // Push one wall vertex through the opposite wall.
  const int N = 24, ring = 20;
  t.points[ring * N] = t.points[ring * N + N / 2] * 1.8;
  t.points[ring * N].z() = t.points[ring * N + N / 2].z();
  SurfaceReport rep;
  std::string msg = error_of([&] { check_and_repair(t, {}, "lumen.vtp", rep); });
  EXPECT_CONTAINS(msg, "intersects itself");
  const TriSurface tube = small_tube();
  EXPECT_FALSE(self_intersecting_triangles(tube.points, tube.triangles, 20).size());
}

TEST(SurfaceChecks, ClosedSurfaceIsNotALumen) {
  TriSurface t = small_tube();
  TriSurface closed = capped(t, boundary_loops(t));
  SurfaceReport rep;
  EXPECT_CONTAINS(error_of([&] { check_and_repair(closed, {}, "tree.stl", rep); }), "0 open ends but 2 were expected");
  SurfaceCheckOptions o;
  o.expected_open_ends = 0;
  EXPECT_NO_THROW(check_and_repair(closed, o, "tree.stl", rep));
}

TEST(SegmentationStage, SurfaceWithWallAndSynthesizedWallAndPhantom) {
  fs::path d = temp_dir("stage");
  PhantomGeometry g = build_phantom(phantom_preset("case2-rca", 1));
  write_stl_binary(d / "lumen.stl", surface_from_mesh(g.lumen, "l"));
  write_obj(d / "wall.obj", surface_from_mesh(g.wall, "w"));
  std::ofstream(d / "case.yaml") << "input:\n  surface:\n    lumen: lumen.stl\n    wall: wall.obj\n";
  auto cfg = ConfigMap::load(d / "case.yaml");
  auto input = cfg.map("input");
  SegmentationInput in = parse_segmentation_input(input);
  ASSERT_FALSE(in.is_phantom());
  Summary s;
  run_segmentation_stage(in, d / "out_lumen.vtp", d / "out_wall.vtp", s);
  EXPECT_EQ(read_vtp((d / "out_lumen.vtp").string()).num_cells(), g.lumen.num_cells());
  EXPECT_EQ(std::get<std::string>(s.qois().at("wall_source").value), "file");

  // Lumen only: the wall is synthesized around it and encloses it.
  SegmentationInput only;
  SurfaceInput si;
  si.lumen = d / "lumen.stl";
  si.synthesis.wall_thickness = 0.7;
  only.source = si;
  Summary s2;
  run_segmentation_stage(only, d / "l2.vtp", d / "w2.vtp", s2);
  TriSurface wall = surface_from_mesh(read_vtp((d / "w2.vtp").string()), "w2");
  TriSurface lumen = surface_from_mesh(read_vtp((d / "l2.vtp").string()), "l2");
  EXPECT_EQ(boundary_loops(wall).size(), 2u);
  SurfaceDistance to_wall(wall);
  auto inside = inside_closed_surface(capped(wall, boundary_loops(wall)), lumen.points);
  std::size_t out = std::count(inside.begin(), inside.end(), false);
  EXPECT_LT(out, lumen.points.size() / 50);  // only points on the end planes may touch
  double thinnest = 1e9;
  for (std::size_t i = 0; i < lumen.points.size(); i += 13) thinnest = std::min(thinnest, to_wall.distance(lumen.points[i]));
  EXPECT_GT(thinnest, 0.3);

  // Phantom input with the true centerline.
  auto pc = ConfigMap::from_string("input:\n  phantom:\n    preset: tortuous\n    seed: 2\n", (d / "p.yaml").string());
  auto pin = pc.map("input");
  SegmentationInput ph = parse_segmentation_input(pin);
  Summary s3;
  run_segmentation_stage(ph, d / "pl.vtp", d / "pw.vtp", s3, d / "pc.vtp");
  EXPECT_TRUE(fs::exists(d / "pc.vtp"));
  // Both or neither: an error naming the section.
  auto both = ConfigMap::from_string("input:\n  phantom: {preset: tortuous}\n  surface: {lumen: x.stl}\n", "c.yaml");
  auto bin = both.map("input");
  EXPECT_CONTAINS(error_of([&] { parse_segmentation_input(bin); }), "exactly one of");
  fs::remove_all(d);
}

// Wall synthesis on a lumen-only phantom (issue 3): the outer wall at the
// throat sits at R_ref + t (the healthy reference radius from the segments
// either side of the stenosis, plus the healthy wall thickness: the plaque
// fills the space between), and with positive remodeling m at
// R_ref + t + m (R_ref − r_throat) (WallSynthesisOptions). The stenosis is
// long (14 of 24 mm) so a whole-segment median radius would fall inside it.
TEST(WallSynthesis, OuterRadiusAtTheThroatFollowsTheReferenceRule) {
  PhantomSpec spec;
  spec.curve = PhantomCurve::straight;
  spec.length = 24.0;
  spec.reference_radius = 1.5;
  spec.stenosis_severity = 50.0;
  spec.stenosis_length = 14.0;
  spec.eccentricity = 0.0;
  PhantomGeometry g = build_phantom(spec);
  TriSurface lumen = surface_from_mesh(g.lumen, "phantom lumen");
  const double Rref = spec.reference_radius, t = 0.5, r_throat = g.min_radius;
  ASSERT_NEAR(r_throat, 0.75, 1e-6);
  // The straight phantom's axis through the throat.
  const auto& C = g.true_centerline.points;
  const Eigen::Vector3d axis = (C.back() - C.front()).normalized();
  auto outer_radius_at_throat = [&](const TriSurface& wall) {
    double sum = 0;
    int count = 0;
    for (const auto& x : wall.points) {
      const Eigen::Vector3d d = x - g.stenosis_point;
      const double along = d.dot(axis);
      if (std::abs(along) > 0.3) continue;
      sum += (d - along * axis).norm();
      ++count;
    }
    EXPECT_GT(count, 32) << "no wall ring near the throat";
    return sum / std::max(1, count);
  };
  for (double m : {0.0, 1.0}) {
    SCOPED_TRACE(m);
    WallSynthesisOptions o;
    o.wall_thickness = t;
    o.remodeling = m;
    Summary summary;
    const double R = outer_radius_at_throat(synthesize_wall(lumen, o, summary));
    const double expected = Rref + t + m * (Rref - r_throat);
    std::printf("remodeling %.1f: outer radius at the throat %.4f mm, expected %.4f mm (%.2f %%)\n", m, R, expected,
                100 * (R / expected - 1));
    // 2 %: the rule is met to 0.2 % / 0.8 %; the old whole-centerline median missed by 5.3 % / 8.2 %.
    EXPECT_NEAR(R, expected, 0.02 * expected);
  }
}
