// Label images (issue 3): a cylinder label written by VTK (NIfTI with a
// rotating, translating qform; MetaImage with non-unit spacing and an origin
// offset) comes back as an open tube of the right radius, volume and place.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageWriter.h>
#include <vtkNIFTIImageHeader.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkSmartPointer.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>
#include <tuple>

#include <Eigen/Geometry>

#include "common/error.hpp"
#include "common/config.hpp"
#include "common/mesh_data.hpp"
#include "common/summary.hpp"
#include "segmentation_io/label_image.hpp"
#include "segmentation_io/segmentation_stage.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

const double kR = 1.2, kRw = 1.8;        // lumen and outer wall radius, mm
const double kSp[3] = {0.1, 0.08, 0.15};  // non-unit, anisotropic spacing
const int kDim[3] = {50, 50, 80};

// Labels 1 (lumen, r < R) and 2 (wall, R ≤ r < Rw) around the axis through
// the middle of the x-y extent, for slices 5..74 (the ends are inside the image).
vtkSmartPointer<vtkImageData> cylinder(const double origin[3]) {
  auto im = vtkSmartPointer<vtkImageData>::New();
  im->SetDimensions(kDim[0], kDim[1], kDim[2]);
  im->SetSpacing(kSp[0], kSp[1], kSp[2]);
  im->SetOrigin(origin[0], origin[1], origin[2]);
  im->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* p = static_cast<unsigned char*>(im->GetScalarPointer());
  const double cx = 0.5 * (kDim[0] - 1) * kSp[0], cy = 0.5 * (kDim[1] - 1) * kSp[1];
  for (int k = 0; k < kDim[2]; ++k)
    for (int j = 0; j < kDim[1]; ++j)
      for (int i = 0; i < kDim[0]; ++i) {
        double r = std::hypot(i * kSp[0] - cx, j * kSp[1] - cy);
        unsigned char v = 0;
        if (k >= 5 && k <= 74) v = r < kR ? 1 : (r < kRw ? 2 : 0);
        p[i + kDim[0] * (j + kDim[1] * k)] = v;
      }
  return im;
}

struct TubeStats {
  double mean_r = 0, max_dev = 0, length = 0, volume = 0;
};

// Radius about the axis through `a` along `d`, the length between the cuts
// and the capped volume.
TubeStats measure(const TriSurface& s, const Vector3d& a, const Vector3d& d) {
  TubeStats t;
  double smin = 1e300, smax = -1e300;
  for (const auto& x : s.points) {
    double along = (x - a).dot(d);
    smin = std::min(smin, along), smax = std::max(smax, along);
    t.mean_r += (x - a - along * d).norm();
  }
  t.mean_r /= double(s.points.size());
  for (const auto& x : s.points) {
    double along = (x - a).dot(d);
    t.max_dev = std::max(t.max_dev, std::abs((x - a - along * d).norm() - t.mean_r));
  }
  t.length = smax - smin;
  auto loops = boundary_loops(s);
  EXPECT_EQ(loops.size(), 2u);
  t.volume = signed_volume(capped(s, loops));
  return t;
}

}  // namespace

TEST(LabelImage, MetaImageCylinderInPhysicalCoordinates) {
  fs::path dir = fs::temp_directory_path() / "stentsim_label_mha";
  fs::create_directories(dir);
  const double origin[3] = {10.0, -5.0, 3.0};
  auto w = vtkSmartPointer<vtkMetaImageWriter>::New();
  w->SetInputData(cylinder(origin));
  w->SetFileName((dir / "labels.mha").c_str());
  w->SetCompression(false);
  w->Write();
  LabelSurfaceOptions o;
  o.labels = {1};
  TriSurface lumen = label_image_surface(dir / "labels.mha", o);
  const Vector3d a(origin[0] + 0.5 * (kDim[0] - 1) * kSp[0], origin[1] + 0.5 * (kDim[1] - 1) * kSp[1], 0);
  TubeStats t = measure(lumen, a, Vector3d::UnitZ());
  const double exact = M_PI * kR * kR * t.length;
  std::printf("mha lumen: mean radius %.4f (R %.2f, rel %.2e), max deviation %.4f, length %.3f, volume %.4f vs "
              "%.4f (rel %.2e)\n", t.mean_r, kR, t.mean_r / kR - 1, t.max_dev, t.length, t.volume, exact,
              t.volume / exact - 1);
  EXPECT_NEAR(t.mean_r, kR, 0.02 * kR);
  EXPECT_LT(t.max_dev, 0.08);  // under one voxel
  EXPECT_NEAR(t.volume, exact, 0.03 * exact);
  EXPECT_GT(t.length, 6.0);    // 10.5 mm label less the trimmed caps
  // Outer wall: labels 1 and 2 together.
  o.labels = {1, 2};
  TriSurface wall = label_image_surface(dir / "labels.mha", o);
  TubeStats tw = measure(wall, a, Vector3d::UnitZ());
  std::printf("mha wall: mean radius %.4f (Rw %.2f)\n", tw.mean_r, kRw);
  EXPECT_NEAR(tw.mean_r, kRw, 0.02 * kRw);
  // Errors name the file.
  o.labels = {7};
  try {
    label_image_surface(dir / "labels.mha", o);
    ADD_FAILURE() << "no error for a missing label";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("labels.mha"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("7"), std::string::npos) << e.what();
  }
  EXPECT_THROW(label_image_surface(dir / "labels.png", o), InputError);
  // The whole stage from a case's input section: checked lumen and wall files.
  auto cfg = ConfigMap::from_string("label_image:\n  file: " + (dir / "labels.mha").string() +
                                        "\n  lumen_label: 1\n  wall_label: 2\n",
                                    dir / "case.yaml");
  SegmentationInput in = parse_segmentation_input(cfg);
  Summary summary;
  run_segmentation_stage(in, dir / "lumen.vtp", dir / "wall.vtp", summary);
  TriSurface back = surface_from_mesh(read_vtp((dir / "wall.vtp").string()), "wall");
  EXPECT_EQ(boundary_loops(back).size(), 2u);
  fs::remove_all(dir);
}

TEST(LabelImage, NiftiQformRotatesAndTranslates) {
  fs::path dir = fs::temp_directory_path() / "stentsim_label_nii";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  // qform: 90° about x (data z → world −y... ) plus a translation.
  auto q = vtkSmartPointer<vtkMatrix4x4>::New();
  q->Identity();
  q->SetElement(1, 1, 0), q->SetElement(1, 2, -1), q->SetElement(2, 1, 1), q->SetElement(2, 2, 0);
  q->SetElement(0, 3, -20.0), q->SetElement(1, 3, 7.0), q->SetElement(2, 3, 40.0);
  auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
  w->SetInputData(cylinder(zero));
  w->SetQFormMatrix(q);
  w->SetFileName((dir / "labels.nii.gz").c_str());
  w->Write();
  LabelSurfaceOptions o;
  o.labels = {1};
  TriSurface lumen = label_image_surface(dir / "labels.nii.gz", o);
  // Axis in data coordinates through (cx, cy, ·) along z → world through q·(cx, cy, 0) along q·e_z.
  const double cx = 0.5 * (kDim[0] - 1) * kSp[0], cy = 0.5 * (kDim[1] - 1) * kSp[1];
  double in[4] = {cx, cy, 0, 1}, out[4];
  q->MultiplyPoint(in, out);
  const Vector3d a(out[0], out[1], out[2]), d(0, -1, 0);
  TubeStats t = measure(lumen, a, d);
  const double exact = M_PI * kR * kR * t.length;
  std::printf("nii lumen: mean radius %.4f (rel %.2e), max deviation %.4f, length %.3f, volume rel %.2e\n", t.mean_r,
              t.mean_r / kR - 1, t.max_dev, t.length, t.volume / exact - 1);
  EXPECT_NEAR(t.mean_r, kR, 0.02 * kR);
  EXPECT_LT(t.max_dev, 0.08);
  EXPECT_NEAR(t.volume, exact, 0.03 * exact);
  fs::remove_all(dir);
}

// NIfTI's xyzt_units is the file's unit when the case gives none (the units
// rule): the same cylinder with its spacing in metres and the header saying
// metres gives the millimetre lumen; a case that says mm is an error naming
// both and the setting, and removing it (or saying m) clears it.
TEST(LabelImage, NiftiXyztUnitsGiveTheUnitsAndAContradictionIsAnError) {
  const fs::path dir = fs::temp_directory_path() / "stentsim_label_nii_units";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  im->SetSpacing(kSp[0] / 1000, kSp[1] / 1000, kSp[2] / 1000);
  auto hdr = vtkSmartPointer<vtkNIFTIImageHeader>::New();
  hdr->SetXYZTUnits(vtkNIFTIImageHeader::UnitsMeter);
  auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
  w->SetInputData(im);
  w->SetNIFTIHeader(hdr);
  w->SetFileName((dir / "labels_m.nii").c_str());
  w->Write();
  ASSERT_EQ(nifti_spatial_units(dir / "labels_m.nii").value_or("none"), "m");
  auto run = [&](const std::string& units_line) {
    auto cfg = ConfigMap::from_string("label_image:\n  file: " + (dir / "labels_m.nii").string() +
                                          "\n  lumen_label: 1\n" + units_line,
                                      dir / "case.yaml");
    SegmentationInput in = parse_segmentation_input(cfg);
    Summary summary;
    run_segmentation_stage(in, dir / "lumen.vtp", dir / "wall.vtp", summary);
    return summary;
  };
  const Summary ok = run("");
  const double d = std::get<double>(ok.qois().at("lumen_reference_diameter").value);
  std::printf("NIfTI in metres (xyzt_units): reference diameter %.4f mm (true %.2f)\n", d, 2 * kR);
  EXPECT_NEAR(d, 2 * kR, 0.1 * kR);
  std::string msg;
  try {
    run("  units: mm\n");
  } catch (const InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("labels_m.nii"), std::string::npos) << msg;
  EXPECT_NE(msg.find("metres (xyzt_units)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("set it to m"), std::string::npos) << msg;
  EXPECT_NO_THROW(run("  units: m\n"));
  fs::remove_all(dir);
}

TEST(LabelImage, NrrdWithAnisotropicSpacings) {
  // VTK has no NRRD writer: a raw NRRD (header + bytes) written by hand.
  fs::path dir = fs::temp_directory_path() / "stentsim_label_nrrd";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  {
    std::ofstream f(dir / "labels.nrrd", std::ios::binary);
    f << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nspacings: " << kSp[0] << " " << kSp[1] << " " << kSp[2] << "\nencoding: raw\n\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), std::streamsize(kDim[0]) * kDim[1] * kDim[2]);
  }
  LabelSurfaceOptions o;
  o.labels = {1};
  TriSurface lumen = label_image_surface(dir / "labels.nrrd", o);
  const Vector3d a(0.5 * (kDim[0] - 1) * kSp[0], 0.5 * (kDim[1] - 1) * kSp[1], 0);
  TubeStats t = measure(lumen, a, Vector3d::UnitZ());
  std::printf("nrrd lumen: mean radius %.4f (rel %.2e), max deviation %.4f\n", t.mean_r, t.mean_r / kR - 1, t.max_dev);
  EXPECT_NEAR(t.mean_r, kR, 0.02 * kR);
  EXPECT_LT(t.max_dev, 0.08);
  fs::remove_all(dir);
}

namespace {

// An oblique rotation: 40 degrees about (1, 2, 2)/3.
Eigen::Matrix3d oblique_rotation() {
  return Eigen::AngleAxisd(40.0 * M_PI / 180.0, Vector3d(1, 2, 2).normalized()).toRotationMatrix();
}

// The cylinder's axis in the world: through index (cx, cy, 0) along index axis k.
void expect_tube_along(const TriSurface& lumen, const Eigen::Matrix3d& step, const Vector3d& origin, const char* what) {
  const Vector3d a = origin + step * Vector3d(0.5 * (kDim[0] - 1), 0.5 * (kDim[1] - 1), 0);
  const Vector3d d = step.col(2).normalized();
  TubeStats t = measure(lumen, a, d);
  const double exact = M_PI * kR * kR * t.length;
  std::printf("%s lumen: mean radius %.4f (rel %.2e), max deviation %.4f, length %.3f, volume rel %.2e\n", what,
              t.mean_r, t.mean_r / kR - 1, t.max_dev, t.length, t.volume / exact - 1);
  EXPECT_NEAR(t.mean_r, kR, 0.02 * kR) << what;
  EXPECT_LT(t.max_dev, 0.08) << what;
  EXPECT_NEAR(t.volume, exact, 0.03 * exact) << what;  // positive: outward normals even for a mirroring matrix
}

}  // namespace

// NRRD "space directions" (oblique, anisotropic) and "space origin": VTK 9.1's
// reader drops the rotation; the surface must come out along the rotated axis.
TEST(LabelImage, NrrdSpaceDirectionsRotateTheSurface) {
  fs::path dir = fs::temp_directory_path() / "stentsim_label_nrrd_dir";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  const Eigen::Matrix3d step = oblique_rotation() * Vector3d(kSp[0], kSp[1], kSp[2]).asDiagonal();
  const Vector3d origin(12.5, -40.0, 7.25);
  {
    std::ofstream f(dir / "labels.nrrd", std::ios::binary);
    f.precision(17);
    f << "NRRD0005\n# oblique acquisition\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\nsizes: " << kDim[0]
      << " " << kDim[1] << " " << kDim[2] << "\nspace directions:";
    for (int a = 0; a < 3; ++a) f << " (" << step(0, a) << "," << step(1, a) << "," << step(2, a) << ")";
    f << "\nkinds: domain domain domain\nencoding: raw\nspace origin: (" << origin.x() << "," << origin.y() << ","
      << origin.z() << ")\n\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), std::streamsize(kDim[0]) * kDim[1] * kDim[2]);
  }
  LabelSurfaceOptions o;
  o.labels = {1};
  expect_tube_along(label_image_surface(dir / "labels.nrrd", o), step, origin, "nrrd oblique");

  // A header with two directions for a 3-D image names the field.
  {
    std::ofstream f(dir / "bad.nrrd", std::ios::binary);
    f << "NRRD0005\ntype: uint8\ndimension: 3\nsizes: " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nspace dimension: 3\nspace directions: (0.1,0,0) (0,0.08,0) none\nencoding: raw\n\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), std::streamsize(kDim[0]) * kDim[1] * kDim[2]);
  }
  try {
    label_image_surface(dir / "bad.nrrd", o);
    ADD_FAILURE() << "no error for two space directions";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.nrrd: space directions"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected three 3-vectors"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// MetaImage TransformMatrix (rows: unit direction of each index axis, as ITK
// writes it) with a mirroring matrix (determinant -1), ElementSpacing and Offset.
TEST(LabelImage, MetaImageTransformMatrixRotatesAndMirrors) {
  fs::path dir = fs::temp_directory_path() / "stentsim_label_mha_dir";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  Eigen::Matrix3d directions = oblique_rotation();  // columns: axis directions
  directions.col(0) = -directions.col(0);           // mirror
  const Eigen::Matrix3d step = directions * Vector3d(kSp[0], kSp[1], kSp[2]).asDiagonal();
  const Vector3d origin(-3.0, 22.0, 101.5);
  auto write = [&](const fs::path& p, const std::string& matrix_line) {
    std::ofstream f(p, std::ios::binary);
    f.precision(17);
    f << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
      << matrix_line << "\nOffset = " << origin.x() << " " << origin.y() << " " << origin.z()
      << "\nCenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\nElementSpacing = " << kSp[0] << " " << kSp[1] << " "
      << kSp[2] << "\nDimSize = " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), std::streamsize(kDim[0]) * kDim[1] * kDim[2]);
  };
  std::ostringstream m;
  m.precision(17);
  m << "TransformMatrix =";
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c) m << " " << directions(c, a);
  write(dir / "labels.mha", m.str());
  LabelSurfaceOptions o;
  o.labels = {1};
  expect_tube_along(label_image_surface(dir / "labels.mha", o), step, origin, "mha mirrored oblique");

  write(dir / "bad.mha", "TransformMatrix = 2 0 0 0 1 0 0 0 1");
  try {
    label_image_surface(dir / "bad.mha", o);
    ADD_FAILURE() << "no error for a non-unit TransformMatrix row";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.mha: TransformMatrix: row 1"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

/// The InputError that reading label 1 of `f` ends in, or "no error".
std::string label_error_of(const fs::path& f) {
  LabelSurfaceOptions o;
  o.labels = {1};
  try {
    label_image_surface(f, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// A detached voxel file (MetaImage ElementDataFile, NRRD "data file:") that is a
// device or a pipe is refused before VTK opens it: reading /dev/zero would never
// end and a FIFO would block. A missing one is named too.
TEST(LabelImage, DetachedDataFileThatIsADeviceOrAPipeIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_label_detached_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
  auto mhd = [&](const std::string& name, const std::string& data) {
    std::ofstream f(dir / name);
    f << "ObjectType = Image\nNDims = 3\nDimSize = " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nElementSpacing = " << kSp[0] << " " << kSp[1] << " " << kSp[2] << "\nElementType = MET_UCHAR\nElementDataFile = " << data
      << "\n";
    return dir / name;
  };
  auto nhdr = [&](const std::string& name, const std::string& data) {
    std::ofstream f(dir / name);
    f << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << kDim[0] << " " << kDim[1] << " " << kDim[2] << "\nspacings: " << kSp[0]
      << " " << kSp[1] << " " << kSp[2] << "\nencoding: raw\ndata file: " << data << "\n\n";
    return dir / name;
  };
  for (const auto& [file, key, data] : std::vector<std::tuple<fs::path, std::string, std::string>>{
           {mhd("zero.mhd", "/dev/zero"), "ElementDataFile", "/dev/zero"},
           {mhd("pipe.mhd", "pipe"), "ElementDataFile", "pipe"},
           {nhdr("zero.nhdr", "/dev/zero"), "data file", "/dev/zero"},
           {nhdr("pipe.nhdr", "pipe"), "data file", "pipe"}}) {
    const std::string e = label_error_of(file);
    EXPECT_NE(e.find(file.string() + ": " + key + " " + data + " is not a regular file"), std::string::npos) << e;
  }
  const std::string e = label_error_of(mhd("missing.mhd", "nothing.raw"));
  EXPECT_NE(e.find("ElementDataFile nothing.raw is missing"), std::string::npos) << e;
  fs::remove_all(dir);
}

// A label image cut short (a copy that did not finish) is named as such, in each
// format, instead of surfacing the zeros VTK fills in; a zero spacing is named.
TEST(LabelImage, TruncatedFilesAndZeroSpacingAreNamed) {
  const fs::path dir = fs::temp_directory_path() / "stentsim_label_truncated";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  const std::streamsize voxels = std::streamsize(kDim[0]) * kDim[1] * kDim[2];
  auto cut = [](const fs::path& f, std::uintmax_t keep) { fs::resize_file(f, keep); };
  // NIfTI (uncompressed and gzip), written by VTK, then cut in the voxel data.
  for (const char* name : {"labels.nii", "labels.nii.gz"}) {
    auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
    w->SetInputData(im);
    w->SetFileName((dir / name).c_str());
    w->Write();
    cut(dir / name, fs::file_size(dir / name) / 2);
    const std::string e = label_error_of(dir / name);
    EXPECT_NE(e.find(name), std::string::npos) << e;
    EXPECT_NE(e.find("cut short or damaged"), std::string::npos) << e;
  }
  // Raw NRRD and MetaImage (.mha, data in the file).
  {
    std::ofstream f(dir / "labels.nrrd", std::ios::binary);
    f << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nspacings: " << kSp[0] << " " << kSp[1] << " " << kSp[2] << "\nencoding: raw\n\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), voxels / 2);
  }
  std::string e = label_error_of(dir / "labels.nrrd");
  EXPECT_NE(e.find("labels.nrrd"), std::string::npos) << e;
  EXPECT_NE(e.find("cut short or damaged"), std::string::npos) << e;
  {
    auto w = vtkSmartPointer<vtkMetaImageWriter>::New();
    w->SetInputData(im);
    w->SetCompression(false);
    w->SetFileName((dir / "labels.mha").c_str());
    w->Write();
  }
  cut(dir / "labels.mha", fs::file_size(dir / "labels.mha") - std::uintmax_t(voxels / 2));
  e = label_error_of(dir / "labels.mha");
  EXPECT_NE(e.find("labels.mha"), std::string::npos) << e;
  EXPECT_NE(e.find("cut short or damaged"), std::string::npos) << e;
  // A zero spacing in the header.
  {
    std::ofstream f(dir / "flat.nrrd", std::ios::binary);
    f << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nspacings: " << kSp[0] << " 0 " << kSp[2] << "\nencoding: raw\n\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), voxels);
  }
  e = label_error_of(dir / "flat.nrrd");
  EXPECT_NE(e.find("axis 2 has zero spacing"), std::string::npos) << e;
  // ... in a MetaImage header (ElementSpacing) and in a NIfTI one (pixdim[3], the z axis).
  {
    std::ofstream f(dir / "flat.mha", std::ios::binary);
    f << "ObjectType = Image\nNDims = 3\nDimSize = " << kDim[0] << " " << kDim[1] << " " << kDim[2]
      << "\nElementSpacing = " << kSp[0] << " 0 " << kSp[2] << "\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
    f.write(static_cast<const char*>(im->GetScalarPointer()), voxels);
  }
  e = label_error_of(dir / "flat.mha");
  EXPECT_NE(e.find("flat.mha"), std::string::npos) << e;
  EXPECT_NE(e.find("ElementSpacing = '0.1 0 0.15'"), std::string::npos) << e;
  EXPECT_NE(e.find("non-zero"), std::string::npos) << e;
  {
    auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
    w->SetInputData(im);
    w->SetFileName((dir / "flat.nii").c_str());
    w->Write();
  }
  {
    // NIfTI-1: float pixdim[8] at byte 76; pixdim[3] is the third axis's spacing.
    std::fstream f(dir / "flat.nii", std::ios::in | std::ios::out | std::ios::binary);
    const float zero_spacing = 0.0f;
    f.seekp(76 + 3 * 4);
    f.write(reinterpret_cast<const char*>(&zero_spacing), 4);
  }
  e = label_error_of(dir / "flat.nii");
  EXPECT_NE(e.find("flat.nii"), std::string::npos) << e;
  EXPECT_NE(e.find("pixdim[3] is 0: axis 3 has zero spacing"), std::string::npos) << e;
  fs::remove_all(dir);
}

// Damaged headers that crashed or hung VTK 9.1's readers, or stentsim behind them
// (found by test_fuzz_label_images), are input errors naming the file and field.
TEST(LabelImage, DamagedHeadersAreInputErrorsNotCrashes) {
  const fs::path dir = fs::temp_directory_path() / "stentsim_label_damaged";
  fs::create_directories(dir);
  const double zero[3] = {0, 0, 0};
  auto im = cylinder(zero);
  const std::string voxels(static_cast<const char*>(im->GetScalarPointer()), std::size_t(kDim[0]) * kDim[1] * kDim[2]);
  auto write = [](const fs::path& f, const std::string& bytes) { std::ofstream(f, std::ios::binary) << bytes; };
  auto slurp = [](const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  // NIfTI: 11 bytes inserted inside the header shift datatype, bitpix, pixdim and
  // vox_offset (segfault in vtkNIFTIImageReader::RequestInformation).
  {
    auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
    w->SetInputData(im);
    w->SetFileName((dir / "good.nii").c_str());
    w->Write();
    std::string nii = slurp(dir / "good.nii");
    write(dir / "shifted.nii", nii.insert(71, std::string(11, '\xfc')));
  }
  std::string e = label_error_of(dir / "shifted.nii");
  EXPECT_NE(e.find("shifted.nii: NIfTI magic is not 'n+1'"), std::string::npos) << e;
  // NRRD without a dimension (segfault reading the voxels) and with a NUL in its header
  // (VTK loses the data offset: the read never ended).
  const std::string nrrd_tail = "sizes: " + std::to_string(kDim[0]) + " " + std::to_string(kDim[1]) + " " +
                                std::to_string(kDim[2]) + "\nspacings: 0.1 0.1 0.1\nencoding: raw\n";
  write(dir / "nodim.nrrd", "NRRD0004\ntype: uint8\n" + nrrd_tail + "\n" + voxels);
  e = label_error_of(dir / "nodim.nrrd");
  EXPECT_NE(e.find("nodim.nrrd: NRRD field 'sizes' comes before 'dimension: 3'"), std::string::npos) << e;
  write(dir / "nul.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nkind: domain" + std::string(1, '\0') + "domain\n" + nrrd_tail +
                              "\n" + voxels);
  e = label_error_of(dir / "nul.nrrd");
  EXPECT_NE(e.find("nul.nrrd: the NRRD header holds a NUL byte"), std::string::npos) << e;
  // MetaImage with NDims = 2^32 - 1 (MetaIO never returned).
  const std::string mha_tail = "\nDimSize = " + std::to_string(kDim[0]) + " " + std::to_string(kDim[1]) + " " +
                               std::to_string(kDim[2]) + "\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + voxels;
  write(dir / "ndims.mha", "ObjectType = Image\nNDims = 4294967295\nElementSpacing = 0.1 0.1 0.1" + mha_tail);
  e = label_error_of(dir / "ndims.mha");
  EXPECT_NE(e.find("ndims.mha: MetaImage NDims = '4294967295' -- expected 3"), std::string::npos) << e;
  // A spacing so large along one axis that the end cuts leave nothing (segfault on the
  // empty piece list); the header itself is valid. A 14 x 14 x 30 cylinder, as the fuzz seed.
  std::string small(14 * 14 * 30, '\0');
  for (int k = 3; k <= 26; ++k)
    for (int j = 0; j < 14; ++j)
      for (int i = 0; i < 14; ++i) small[std::size_t(i + 14 * (j + 14 * k))] = std::hypot(i - 6.5, j - 6.5) < 3.5 ? 1 : 0;
  write(dir / "wide.mha", "ObjectType = Image\nNDims = 3\nElementSpacing = 4294967295.5 0.5 0.5\nDimSize = 14 14 30\n"
                          "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + small);
  e = label_error_of(dir / "wide.mha");
  EXPECT_NE(e.find("wide.mha: nothing of the labelled region is left between the two end cuts"), std::string::npos) << e;
  fs::remove_all(dir);
}
