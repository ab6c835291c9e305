#pragma once
// Index -> physical coordinates of NRRD and MetaImage label images, read from
// the header text itself. VTK 9.1's vtkNrrdReader and vtkMetaImageReader keep
// only origin and spacing (a vtkImageData without its direction matrix), so an
// oblique acquisition would come out rotated; the direction cosines are taken
// here instead:
//   NRRD (teem format 4-5): "space directions: (a,b,c) (d,e,f) (g,h,i)" give the
//     world step of each index axis (spacing included), "space origin" the
//     world position of voxel (0,0,0).
//   MetaImage (MetaIO/ITK): "TransformMatrix" (also "Rotation", "Orientation")
//     holds row by row the unit direction of each index axis, "ElementSpacing"
//     the step, "Offset" (also "Origin", "Position") the position of voxel 0.
// Coordinates stay in the file's own space (NRRD's `space`, MetaImage's LPS):
// no RAS/LPS flip is applied.
#include <Eigen/Core>

#include <filesystem>
#include <optional>

namespace stentsim::segmentation {

struct IndexToWorld {
  Eigen::Matrix3d step = Eigen::Matrix3d::Identity();  // column a: world displacement of one voxel along index axis a
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();    // world position of voxel (0, 0, 0)
  Eigen::Vector3d operator()(const Eigen::Vector3d& index) const { return origin + step * index; }
};

/// The header's index-to-world map when it gives directions ("space
/// directions" / TransformMatrix); nullopt when it gives none (then origin and
/// spacing as VTK reads them are the whole geometry). InputError naming the
/// file and field for a malformed or degenerate direction set.
std::optional<IndexToWorld> nrrd_index_to_world(const std::filesystem::path& header);
std::optional<IndexToWorld> metaimage_index_to_world(const std::filesystem::path& header);

}  // namespace stentsim::segmentation
