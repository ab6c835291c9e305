#pragma once
// A dense Assembler for small test problems.
#include <Eigen/Core>

#include "solver/terms/term.hpp"

namespace stentsim::solver::test {

class DenseAssembler : public Assembler {
 public:
  explicit DenseAssembler(Eigen::Index n) : r(Eigen::VectorXd::Zero(n)), k(Eigen::MatrixXd::Zero(n, n)) {}
  void add(std::span<const GlobalDof> dofs, const Eigen::Ref<const Eigen::VectorXd>& re,
           const Eigen::Ref<const Eigen::MatrixXd>& ke) override {
    for (std::size_t i = 0; i < dofs.size(); ++i) {
      if (dofs[i] < 0) continue;
      r(dofs[i]) += re(static_cast<Eigen::Index>(i));
      if (ke.size() == 0) continue;
      for (std::size_t j = 0; j < dofs.size(); ++j)
        if (dofs[j] >= 0) k(dofs[i], dofs[j]) += ke(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  Eigen::VectorXd r;
  Eigen::MatrixXd k;
};

}  // namespace stentsim::solver::test
