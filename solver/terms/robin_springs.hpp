#pragma once
// Omnidirectional Robin springs on a body's surface faces: traction -k u per
// reference area (paper Section 2.1/4.1: the artery's cut faces and the
// balloon ends; k in N/mm^3, DESIGN.md §4, §8).
#include <string>
#include <vector>

#include "solver/fem/boundary_faces.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

class RobinSprings : public Term {
 public:
  RobinSprings(std::string name, const SolidBody& body, std::vector<fem::Face> faces, double stiffness);
  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;

 private:
  template <class S>
  void add_face(const fem::Face& f, const SystemState& state, Assembler& out) const;
  std::string name_;
  const SolidBody& body_;
  std::vector<fem::Face> faces_;
  double stiffness_;
};

}  // namespace stentsim::solver
