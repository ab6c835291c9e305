#pragma once
// The 1 x 1 x 2 neo-Hooke block (E = 1 MPa, nu = 0.3) of the Newton,
// predictor and robustness tests, with its bottom (z = 0) and top (z = 2)
// faces; each test adds its supports and loads, then size_constraints().
#include <memory>
#include <vector>

#include "solver/assembly/model.hpp"
#include "solver/fem/boundary_faces.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/terms/solid_body.hpp"

namespace stentsim::solver {

struct NeoHookeBlock {
  Model model;
  SolidBody* body = nullptr;
  std::vector<fem::Face> bottom, top;
};

inline std::unique_ptr<NeoHookeBlock> make_neo_hooke_block(MeshData mesh) {
  auto b = std::make_unique<NeoHookeBlock>();
  SolidBodySpec spec;
  spec.name = "block";
  spec.mesh = std::move(mesh);
  Material m;
  m.name = "nh";
  m.matrix = CoupledNeoHooke::from_young_poisson(1.0, 0.3);
  spec.materials = {m};
  spec.cell_material.assign(spec.mesh.num_cells(), 0);
  const GlobalDof first = b->model.dofs.allocate("block", 3 * static_cast<GlobalDof>(spec.mesh.points.size()));
  b->body = &b->model.add_term<SolidBody>(spec, first);
  for (const auto& f : fem::boundary_faces(b->body->mesh())) {
    double zmax = -1, zmin = 10;
    for (int i = 0; i < f.count; ++i) {
      zmax = std::max(zmax, b->body->mesh().points[static_cast<std::size_t>(f.nodes[i])].z());
      zmin = std::min(zmin, b->body->mesh().points[static_cast<std::size_t>(f.nodes[i])].z());
    }
    if (zmax < 1e-9) b->bottom.push_back(f);
    if (zmin > 2 - 1e-9) b->top.push_back(f);
  }
  return b;
}

}  // namespace stentsim::solver
