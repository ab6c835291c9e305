#pragma once
// The centerline the placement reads (DESIGN.md §1: centerline.vtp, a single
// polyline with VMTK's point arrays MaximumInscribedSphereRadius, Abscissas,
// ParallelTransportNormals), with linear interpolation by abscissa.
#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"

namespace stentsim::device_gen {

struct Centerline {
  std::string source;  // file name, for messages
  std::vector<Eigen::Vector3d> points;
  std::vector<double> abscissa;  // strictly increasing, mm
  std::vector<double> radius;    // maximum inscribed sphere radius, mm
  std::vector<Eigen::Vector3d> normals;

  double begin() const { return abscissa.front(); }
  double end() const { return abscissa.back(); }
  Eigen::Vector3d point_at(double s) const;
  double radius_at(double s) const;
  Eigen::Vector3d normal_at(double s) const;
  /// Mean of the radius over [s - w/2, s + w/2] (clipped to the centerline).
  double smoothed_radius(double s, double window) const;

 private:
  std::size_t segment(double s, double& t) const;
};

/// Validates and converts poly data; `source` names the file in errors.
Centerline centerline_from_mesh(const MeshData& mesh, const std::string& source);
/// Reads centerline.vtp. Throws InputError naming the file and the array.
Centerline read_centerline(const std::filesystem::path& file);

}  // namespace stentsim::device_gen
