#pragma once
// Follower pressure on a body's surface faces (DESIGN.md §5: Nanson's formula
// J F^-T N0 dA, pressure acting against the current outward normal), scaled
// by a load curve. Consistent non-symmetric tangent (surface_kernel.hpp).
#include <string>
#include <vector>

#include "solver/fem/boundary_faces.hpp"
#include "solver/terms/load_curve.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

class FollowerPressure : public Term {
 public:
  /// `faces` index the body's nodes and point outward; pressure(t) = magnitude * curve(t).
  FollowerPressure(std::string name, const SolidBody& body, std::vector<fem::Face> faces, double magnitude,
                   LoadCurve curve);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  /// A face turned to its cell's side (face_orientation.hpp): the surface is inside out.
  std::string rejects(const SystemState& state) const override;
  double pressure(double time) const { return magnitude_ * curve_(time); }
  const std::vector<fem::Face>& faces() const { return faces_; }

 private:
  template <class S>
  void add_face(const fem::Face& f, const SystemState& state, double p, Assembler& out, bool tangent) const;
  std::string name_;
  const SolidBody& body_;
  std::vector<fem::Face> faces_;
  double magnitude_;
  LoadCurve curve_;
  std::vector<char> outward_;  // per face: it looks away from its cell in the reference
};

}  // namespace stentsim::solver
