#pragma once
// Label images (issue 3): NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr) and
// MetaImage (.mha, .mhd) through VTK's readers; a label's surface by discrete
// flying edges with volume-preserving windowed-sinc smoothing, in the image's
// physical coordinates, opened at the vessel's two ends by planar cuts.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

struct LabelSurfaceOptions {
  std::vector<int> labels;     // voxels with any of these labels are inside (lumen: {1}; outer wall: {1, 2})
  int smoothing_iterations = 20;
  double passband = 0.05;      // windowed-sinc pass band (smaller: smoother)
  double end_trim = 0;         // mm cut off each end (past the rounded cap); 0: 3 × the largest voxel size + 0.5 × radius
  bool open_ends = true;       // false: the closed surface
  std::vector<int> axis_labels;  // voxels that place the end cuts (empty: `labels`); lumen and wall
                                 // surfaces cut with the same axis_labels get the same planes
};

/// The surface of the labelled region in physical coordinates (NIfTI: the
/// sform when set, else the qform; NRRD: space directions and space origin;
/// MetaImage: TransformMatrix, ElementSpacing and Offset; without directions,
/// origin and spacing). Open
/// ends: the vessel's axis ends are found from the voxel centroids of slabs
/// two and four radii in from each end, and the surface is cut by planes
/// normal to that axis `end_trim` inside the extreme voxel centre (all from
/// the `axis_labels` voxels). InputError naming the
/// file for an unknown extension, an unreadable file or no voxel with a label.
TriSurface label_image_surface(const std::filesystem::path& file, const LabelSurfaceOptions& options);

/// The spatial unit a NIfTI file's header states (xyzt_units & 7: "m", "mm",
/// "um"); nullopt for other formats or an unknown unit (0).
std::optional<std::string> nifti_spatial_units(const std::filesystem::path& file);

}  // namespace stentsim::segmentation
