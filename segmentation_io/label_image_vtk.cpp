// Label image → surface through VTK (readers, discrete flying edges,
// windowed-sinc smoothing); see label_image.hpp.
#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageReader.h>
#include <vtkNew.h>
#include <vtkNIFTIImageHeader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNrrdReader.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <optional>
#include <algorithm>
#include <cmath>

#include "common/error.hpp"
#include "common/files.hpp"
#include "segmentation_io/branch_extraction.hpp"
#include "segmentation_io/image_header_checks.hpp"
#include "segmentation_io/image_header_geometry.hpp"
#include "segmentation_io/label_image.hpp"
#include "common/vtk_read_errors.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

namespace {

// Reads through `r`; InputError naming the file when VTK reported an error.
template <class Reader>
vtkSmartPointer<vtkImageData> read_voxels(Reader* r, const std::string& name, const char* kind) {
  vtkNew<VtkReadErrors> errors;
  r->AddObserver(vtkCommand::ErrorEvent, errors);
  r->SetFileName(name.c_str());
  r->Update();
  if (!errors->first.empty() || r->GetErrorCode() != 0) {
    const std::string& what = errors->first;
    throw InputError(fmt::format("{}: the {} voxel data could not be read ({}): is the file cut short or damaged?", name, kind,
                                 what.empty() ? "VTK error code " + std::to_string(r->GetErrorCode()) : what));
  }
  return r->GetOutput();
}

bool ends_with(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

}  // namespace

TriSurface label_image_surface(const std::filesystem::path& file, const LabelSurfaceOptions& o) {
  const std::string name = file.string();
  files::require_regular_file(file, "label image");
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  vtkSmartPointer<vtkImageData> image;
  vtkSmartPointer<vtkMatrix4x4> to_world;  // NIfTI sform/qform (data coordinates → world)
  std::optional<IndexToWorld> header_geometry;  // NRRD/MetaImage direction cosines (VTK 9.1 drops them)
  if (ends_with(lower, ".nii") || ends_with(lower, ".nii.gz")) {
    auto r = vtkSmartPointer<vtkNIFTIImageReader>::New();
    if (!r->CanReadFile(name.c_str())) throw InputError(fmt::format("{}: not a readable NIfTI file", name));
    check_nifti_header(file);  // VTK's reader trusts the header and crashes on a damaged one
    image = read_voxels(r.Get(), name, "NIfTI");
    if (r->GetSFormMatrix()) to_world = r->GetSFormMatrix();
    else if (r->GetQFormMatrix()) to_world = r->GetQFormMatrix();
  } else if (ends_with(lower, ".nrrd") || ends_with(lower, ".nhdr")) {
    auto r = vtkSmartPointer<vtkNrrdReader>::New();
    if (!r->CanReadFile(name.c_str())) throw InputError(fmt::format("{}: not a readable NRRD file", name));
    check_nrrd_header(file);  // VTK's reader trusts the header (field order, sizes, data file patterns)
    image = read_voxels(r.Get(), name, "NRRD");
    header_geometry = nrrd_index_to_world(file);
  } else if (ends_with(lower, ".mha") || ends_with(lower, ".mhd")) {
    auto r = vtkSmartPointer<vtkMetaImageReader>::New();
    if (!r->CanReadFile(name.c_str())) throw InputError(fmt::format("{}: not a readable MetaImage file", name));
    check_metaimage_header(file);  // MetaIO reports a short read on stderr only
    image = read_voxels(r.Get(), name, "MetaImage");
    header_geometry = metaimage_index_to_world(file);
  } else {
    throw InputError(fmt::format("{}: unknown label image type (expected .nii, .nii.gz, .nrrd, .nhdr, .mha or .mhd)",
                                 name));
  }
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  int dims[3] = {0, 0, 0};
  if (image) image->GetDimensions(dims);
  if (!scalars || dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
    throw InputError(fmt::format("{}: the image holds no 3-D voxel data", name));
  double spacing[3], origin[3];
  image->GetSpacing(spacing);
  image->GetOrigin(origin);
  for (int a = 0; a < 3 && !header_geometry; ++a)
    if (!(std::abs(spacing[a]) > 0) || !std::isfinite(spacing[a]))
      throw InputError(fmt::format("{}: the voxel spacing is ({:g}, {:g}, {:g}) mm: axis {} has {} spacing; the header's "
                                   "spacing (NIfTI pixdim, NRRD spacings, MetaImage ElementSpacing) must be positive",
                                   name, spacing[0], spacing[1], spacing[2], a + 1, std::isfinite(spacing[a]) ? "zero" : "no finite"));
  // Everything below works in index space and maps to the world at the end:
  // flying edges (vertices at edge midpoints) and windowed sinc (topological
  // weights) commute with an affine map, so the result equals working in
  // physical space, for any direction matrix.
  IndexToWorld index_to_world;
  if (header_geometry) {
    index_to_world = *header_geometry;
  } else {
    index_to_world.step = Eigen::Vector3d(spacing[0], spacing[1], spacing[2]).asDiagonal();
    index_to_world.origin = Vector3d(origin[0], origin[1], origin[2]);
    if (to_world) {  // NIfTI: the sform/qform acts on VTK's data coordinates origin + index * spacing
      Eigen::Matrix3d A;
      Vector3d b;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) A(r, c) = to_world->GetElement(r, c);
        b(r) = to_world->GetElement(r, 3);
      }
      index_to_world.step = A * index_to_world.step;
      index_to_world.origin = A * index_to_world.origin + b;
    }
  }
  // Binary mask padded by one empty voxel on every side, so the surface closes.
  const int nx = dims[0] + 2, ny = dims[1] + 2, nz = dims[2] + 2;
  auto mask = vtkSmartPointer<vtkImageData>::New();
  mask->SetDimensions(nx, ny, nz);
  mask->SetSpacing(1, 1, 1);
  mask->SetOrigin(-1, -1, -1);
  mask->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* m = static_cast<unsigned char*>(mask->GetScalarPointer());
  std::fill(m, m + std::size_t(nx) * ny * nz, 0);
  const std::vector<int>& axis_labels = o.axis_labels.empty() ? o.labels : o.axis_labels;
  std::vector<Vector3d> voxels;  // indices of the voxels that place the end cuts
  std::size_t labelled = 0;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        long idx = i + long(dims[0]) * (j + long(dims[1]) * k);
        int v = int(std::lround(scalars->GetTuple1(idx)));
        if (std::find(axis_labels.begin(), axis_labels.end(), v) != axis_labels.end())
          voxels.emplace_back(i, j, k);
        if (std::find(o.labels.begin(), o.labels.end(), v) == o.labels.end()) continue;
        m[(i + 1) + std::size_t(nx) * ((j + 1) + std::size_t(ny) * (k + 1))] = 1;
        ++labelled;
      }
  if (labelled == 0 || voxels.empty()) {
    std::string ls;
    for (int l : o.labels) ls += (ls.empty() ? "" : ", ") + std::to_string(l);
    throw InputError(fmt::format("{}: no voxel carries the label(s) {}", name, ls));
  }
  auto fe = vtkSmartPointer<vtkDiscreteFlyingEdges3D>::New();
  fe->SetInputData(mask);
  fe->SetValue(0, 1);
  fe->ComputeNormalsOff();
  fe->ComputeGradientsOff();
  fe->ComputeScalarsOff();
  // Windowed sinc (Taubin): removes the voxel staircase without shrinking.
  auto smooth = vtkSmartPointer<vtkWindowedSincPolyDataFilter>::New();
  smooth->SetInputConnection(fe->GetOutputPort());
  smooth->SetNumberOfIterations(o.smoothing_iterations);
  smooth->SetPassBand(o.passband);
  smooth->NormalizeCoordinatesOn();
  smooth->BoundarySmoothingOff();
  smooth->FeatureEdgeSmoothingOff();
  smooth->NonManifoldSmoothingOn();
  auto tri = vtkSmartPointer<vtkTriangleFilter>::New();
  tri->SetInputConnection(o.smoothing_iterations > 0 ? smooth->GetOutputPort() : fe->GetOutputPort());
  tri->PassVertsOff();
  tri->PassLinesOff();
  tri->Update();
  vtkPolyData* pd = tri->GetOutput();
  auto world = [&](const Vector3d& index) -> Vector3d { return index_to_world(index); };
  TriSurface s;
  s.points.reserve(std::size_t(pd->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) {
    double p[3];
    pd->GetPoint(i, p);
    s.points.push_back(world({p[0], p[1], p[2]}));
  }
  vtkCellArray* polys = pd->GetPolys();
  polys->InitTraversal();
  vtkIdType npts;
  const vtkIdType* ids;
  while (polys->GetNextCell(npts, ids))
    if (npts == 3) s.triangles.push_back({int(ids[0]), int(ids[1]), int(ids[2])});
  if (s.triangles.empty()) throw InputError(fmt::format("{}: the labelled region gives no surface", name));
  if (signed_volume(s) < 0)  // a mirroring direction matrix turns the triangles inside out
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  if (!o.open_ends) return s;

  // Open the two ends: vessel axis from the voxel centroids (world coordinates).
  for (auto& v : voxels) v = world(v);
  Vector3d c = Vector3d::Zero();
  for (const auto& v : voxels) c += v;
  c /= double(voxels.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& v : voxels) cov += (v - c) * (v - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Vector3d axis = eig.eigenvectors().col(2);
  double smin = 1e300, smax = -1e300;
  for (const auto& v : voxels) smin = std::min(smin, (v - c).dot(axis)), smax = std::max(smax, (v - c).dot(axis));
  const double voxel_volume = std::abs(index_to_world.step.determinant());
  const double length = smax - smin;
  const double radius = std::sqrt(voxels.size() * voxel_volume / (M_PI * std::max(length, 1e-9)));
  if (length < 4 * radius)
    throw InputError(fmt::format("{}: the labelled region is {:.3g} mm long and about {:.3g} mm in radius; a vessel "
                                 "segment with two open ends should be longer than four radii",
                                 name, length, radius));
  const double hmax = index_to_world.step.colwise().norm().maxCoeff();
  const double trim = o.end_trim > 0 ? o.end_trim : 3 * hmax + 0.5 * radius;
  auto slab_centroid = [&](double a, double b) {
    Vector3d sum = Vector3d::Zero();
    int n = 0;
    for (const auto& v : voxels) {
      double s = (v - c).dot(axis);
      if (s >= std::min(a, b) && s <= std::max(a, b)) sum += v, ++n;
    }
    return n ? Vector3d(sum / n) : c;
  };
  for (int end = 0; end < 2; ++end) {
    double e = end == 0 ? smin : smax, dir = end == 0 ? 1.0 : -1.0;
    Vector3d c0 = slab_centroid(e, e + dir * 2 * radius), c1 = slab_centroid(e + dir * 2 * radius, e + dir * 4 * radius);
    Vector3d inward = (c1 - c0).normalized();
    double extreme = 1e300;  // outermost voxel centre: the same for every surface cut with these voxels
    for (const auto& v : voxels) extreme = std::min(extreme, (v - c0).dot(inward));
    Vector3d plane_point = c0 + (extreme + trim) * inward;
    s = clip_by_plane(s, plane_point, -inward);
  }
  auto pieces = connected_pieces(s);
  if (pieces.empty())
    throw InputError(fmt::format("{}: nothing of the labelled region is left between the two end cuts ({:.3g} mm in from each "
                                 "end); is the voxel spacing right?", name, trim));
  return pieces.front();
}

std::optional<std::string> nifti_spatial_units(const std::filesystem::path& file) {
  std::string lower = file.string();
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (!(ends_with(lower, ".nii") || ends_with(lower, ".nii.gz")) || !std::filesystem::exists(file)) return std::nullopt;
  auto r = vtkSmartPointer<vtkNIFTIImageReader>::New();
  if (!r->CanReadFile(file.string().c_str())) return std::nullopt;
  check_nifti_header(file);
  r->SetFileName(file.string().c_str());
  r->UpdateInformation();
  switch (r->GetNIFTIHeader()->GetXYZTUnits() & 0x07) {
    case vtkNIFTIImageHeader::UnitsMeter: return "m";
    case vtkNIFTIImageHeader::UnitsMM: return "mm";
    case vtkNIFTIImageHeader::UnitsMicron: return "um";
    default: return std::nullopt;
  }
}

}  // namespace stentsim::segmentation
