#pragma once
// A solid material: the sum of the strain-energy summands a body's cell tag
// names (DESIGN.md §5): an optional coupled neo-Hooke matrix or decoupled
// neo-Hooke matrix (svMultiPhysics's HGO form), any number of
// exponential fiber families (directions given per element by the body), and
// an optional generalized-Maxwell viscous branch acting on the total
// hyperelastic stress.
#include <optional>
#include <string>
#include <vector>

#include "solver/materials/coupled_neo_hooke.hpp"
#include "solver/materials/decoupled_neo_hooke.hpp"
#include "solver/materials/fiber_family.hpp"
#include "solver/materials/viscous_branch.hpp"

namespace stentsim::solver {

/// At most this many fiber families per material (keeps element loops allocation-free).
inline constexpr int kMaxFiberFamilies = 4;

/// A fiber family and where its direction comes from: an angle in the
/// (circumferential, longitudinal) plane of the element's local frame,
/// a_0 = cos(phi) e_circ + sin(phi) e_long, or a fixed global direction.
struct FiberFamilySpec {
  FiberFamily law;
  double angle_deg = 0.0;
  std::optional<Vec3> global_direction;
};

struct Material {
  std::string name;
  std::optional<CoupledNeoHooke> matrix;
  std::optional<DecoupledNeoHooke> decoupled_matrix;
  std::vector<FiberFamilySpec> fibers;
  std::optional<ViscousBranch> viscous;

  /// Hyperelastic S_inf and dS_inf/dE (when `tangent` is not null) at C;
  /// `fiber_dirs` holds one unit reference direction per fiber family.
  PointStatus elastic(const Mat3& cauchy_green, const Vec3* fiber_dirs, Vec6& stress, Mat6* tangent) const;
  /// Hyperelastic strain energy (for checks).
  double energy(const Mat3& cauchy_green, const Vec3* fiber_dirs) const;
  /// A one-line description of the parameters, for logs and summaries.
  std::string describe() const;
};

}  // namespace stentsim::solver
