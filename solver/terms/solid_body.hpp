#pragma once
// A solid body: a volume mesh (hex8, tet4, tet10 in any mix), a material per
// cell and fiber directions per cell. Implements Term for its internal forces
// and owns the viscous history of its quadrature points. Surface loads and
// springs on the body are separate terms that read its node DOFs.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/mesh_data.hpp"
#include "solver/materials/material.hpp"
#include "solver/terms/term.hpp"

namespace stentsim::solver {

struct SolidBodySpec {
  std::string name;
  MeshData mesh;                    // points and cells; non-volume cells are ignored
  std::vector<Material> materials;  // referenced by cell_material
  std::vector<int> cell_material;   // one per mesh cell; -1 = not part of this solid
  /// Optional local frame per mesh cell (e_radial, e_circumferential,
  /// e_longitudinal) that fiber angles refer to. Required when a material has
  /// fiber families given by angle.
  std::vector<std::array<Vec3, 3>> cell_frames;
  /// Optional fiber directions per mesh cell from a fiber field (the fibers
  /// stage's Fiber1, Fiber2, ...): family f of the cell's material, when given
  /// by angle, takes cell_fibers[c][f] (f < fibers_per_cell) instead of the
  /// direction rebuilt from cell_frames and the angle.
  std::vector<std::array<Vec3, kMaxFiberFamilies>> cell_fibers;
  int fibers_per_cell = 0;
};

/// Per-cell output of a solid body.
struct SolidCellFields {
  std::vector<Mat3> cauchy;  // volume mean over the cell
  std::vector<Mat3> strain;  // Green-Lagrange, volume mean
  /// Largest first principal Cauchy stress over the cell's quadrature points
  /// (the Gauss-point maximum, DESIGN.md §6); 0 for cells without an element.
  std::vector<double> max_principal_gauss;
};

class SolidBody : public Term {
 public:
  /// DOFs of node i are first_dof + 3 i + {0,1,2}.
  SolidBody(SolidBodySpec spec, GlobalDof first_dof);

  std::string name() const override { return name_; }
  void assemble(const SystemState& state, Assembler& out) override;
  /// With MPI, each rank updated the viscous history of its own elements only:
  /// commit sums the owned slots over ranks so that every rank holds all of it
  /// (stress output and checkpoints are written by rank 0).
  void commit() override;
  void rollback() override { trial_ = committed_; }
  /// Viscous history per quadrature point (Q, S_inf; 12 numbers per slot) for restart.
  bool has_history() const override { return !committed_.empty(); }
  void save_history(HistoryArchive& out, const std::string& prefix) const override;
  void load_history(const HistoryArchive& in, const std::string& prefix) override;

  std::size_t num_nodes() const { return mesh_.points.size(); }
  GlobalDof num_dofs() const { return 3 * static_cast<GlobalDof>(num_nodes()); }
  GlobalDof first_dof() const { return first_dof_; }
  GlobalDof dof(std::size_t node, int component) const { return first_dof_ + 3 * static_cast<GlobalDof>(node) + component; }
  const MeshData& mesh() const { return mesh_; }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<int>& cell_material() const { return cell_material_; }
  std::size_t num_elements() const { return elements_.size(); }
  /// Current position of node i.
  Vec3 position(const Eigen::VectorXd& u, std::size_t node) const;
  /// Cell means of stress and strain at the committed state.
  SolidCellFields cell_fields(const Eigen::VectorXd& u) const;
  /// Fiber directions used for cell c (one per family of its material).
  const std::array<Vec3, kMaxFiberFamilies>& fiber_directions(std::size_t cell) const { return fiber_dirs_[cell]; }

 private:
  struct Element {
    std::size_t cell;         // index in the mesh
    int material;
    long long history = -1;   // first quadrature-point history slot, -1 = none
  };
  template <class E>
  void assemble_element(const Element& el, const SystemState& state, Assembler& out, bool tangent);
  void assemble_any(const Element& el, const SystemState& state, Assembler& out, bool tangent);
  template <class E>
  void cell_average(const Element& el, const Eigen::VectorXd& u, Mat3& cauchy, Mat3& strain, double& max_principal) const;
  [[noreturn]] void fail(const Element& el, const char* type, int point, int corner, const char* why) const;

  std::string name_;
  MeshData mesh_;
  std::vector<Material> materials_;
  std::vector<int> cell_material_;
  std::vector<std::array<Vec3, kMaxFiberFamilies>> fiber_dirs_;  // per mesh cell
  std::vector<Element> elements_;
  GlobalDof first_dof_;
  std::vector<ViscousHistory> committed_, trial_;
  int rank_ = 0, ranks_ = 1;  // element partition of the last assembly
  // Threaded assembly (made on first use): chunks of kChunk consecutive elements_,
  // their colours, and each chunk's first element's place in the coloured order.
  static constexpr std::size_t kChunk = 64;
  void colour_chunks();
  std::vector<std::vector<std::uint32_t>> chunk_colours_;
  std::vector<std::size_t> chunk_order_;
};

}  // namespace stentsim::solver
