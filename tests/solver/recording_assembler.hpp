#pragma once
// An Assembler that keeps every block it is given, in order: for tests that
// compare what two assemblies add (the same blocks in the same order), which a
// summing assembler cannot tell apart when an entry has at most two terms.
#include <Eigen/Core>

#include <vector>

#include "solver/terms/term.hpp"

namespace stentsim::solver::test {

class RecordingAssembler : public Assembler {
 public:
  struct Block {
    std::vector<GlobalDof> dofs;
    Eigen::VectorXd r;
    Eigen::MatrixXd k;
    bool operator==(const Block& o) const { return dofs == o.dofs && r == o.r && k.rows() == o.k.rows() && k == o.k; }
  };
  explicit RecordingAssembler(bool tangent = true) : tangent_(tangent) {}
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& r,
           const Eigen::Ref<const Eigen::MatrixXd>& k) override {
    blocks.push_back({std::vector<GlobalDof>(dofs.begin(), dofs.end()), r, k});
  }
  bool wants_tangent() const override { return tangent_; }
  std::vector<Block> blocks;

 private:
  bool tangent_ = true;
};

}  // namespace stentsim::solver::test
