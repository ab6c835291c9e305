#pragma once
// Dead surface traction: a fixed force per reference area t(t) = t0 * curve(t)
// on a body's faces, R_I = -int N_I t dA0 (no tangent). For benchmarks such
// as Cook's membrane and for prescribed edge loads.
#include <string>
#include <vector>

#include "solver/fem/boundary_faces.hpp"
#include "solver/terms/load_curve.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

class SurfaceTraction : public Term {
 public:
  SurfaceTraction(std::string name, const SolidBody& body, std::vector<fem::Face> faces, const Vec3& traction, LoadCurve curve);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;

 private:
  template <class S>
  void add_face(const fem::Face& f, const Vec3& t, Assembler& out) const;
  std::string name_;
  const SolidBody& body_;
  std::vector<fem::Face> faces_;
  Vec3 traction_;
  LoadCurve curve_;
};

}  // namespace stentsim::solver
