#include "solver/app/contact/strut_overlap.hpp"

#include <fmt/format.h>

#include <cmath>
#include <unordered_map>

#include "common/log.hpp"

namespace stentsim::solver {
namespace {

class StrutOverlapCheck : public RunObserver {
 public:
  StrutOverlapCheck(const beams::BeamTerm& beam, double radius) : beam_(beam), radius_(radius) {
    reference_ = sample(Eigen::VectorXd::Zero(0));
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override {
    const auto x = sample(u);
    // Uniform bins of size 2R: overlapping pairs lie in the same or neighbouring bins.
    const double h = 2.0 * radius_;
    auto key = [&](const Vec3& p) {
      const auto c = (p / h).array().floor().cast<long long>();
      return (c[0] * 73856093LL) ^ (c[1] * 19349663LL) ^ (c[2] * 83492791LL);
    };
    std::unordered_multimap<long long, std::size_t> bins;
    for (std::size_t i = 0; i < x.size(); ++i) bins.emplace(key(x[i]), i);
    int count = 0;
    double closest = h;
    Vec3 where = Vec3::Zero();
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto range = bins.equal_range(key(x[i] + h * Vec3(dx, dy, dz)));
            for (auto it = range.first; it != range.second; ++it) {
              const std::size_t j = it->second;
              if (j <= i || (reference_[i] - reference_[j]).norm() <= 2.0 * h) continue;
              const double d = (x[i] - x[j]).norm();
              if (d >= h) continue;
              ++count;
              if (d < closest) closest = d, where = 0.5 * (x[i] + x[j]);
            }
          }
    if (count > 0) {
      log::warn("beam '{}': {} pairs of centerline points of different struts overlap at t = {:.4g} (beam-beam contact is not "
                "modelled); deepest {:.4g} mm at ({:.3f}, {:.3f}, {:.3f}) mm",
                beam_.name(), count, r.time, h - closest, where.x(), where.y(), where.z());
      worst_count_ = std::max(worst_count_, count);
      worst_depth_ = std::max(worst_depth_, h - closest);
    }
  }
  std::string checkpoint_name() const override { return "strut_overlap/" + beam_.name(); }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    out.put(prefix + "points", static_cast<double>(worst_count_));
    out.put(prefix + "depth", worst_depth_);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    worst_count_ = static_cast<int>(in.get_scalar(prefix + "points"));
    worst_depth_ = in.get_scalar(prefix + "depth");
  }
  void summarize(Summary& s, const RunEnd&) const override {
    s.set("strut_overlap_points_max_" + beam_.name(), static_cast<double>(worst_count_));
    s.set("strut_overlap_depth_max_" + beam_.name(), worst_depth_, "mm");
  }

 private:
  /// 4 centerline points per element (ξ = ±0.75, ±0.25); u empty: the reference.
  std::vector<Vec3> sample(const Eigen::VectorXd& u) const {
    std::vector<Vec3> pts;
    const auto& body = beam_.body();
    for (std::size_t e = 0; e < body.elements.size(); ++e) {
      const beams::ElementReference& r = beam_.reference(e);
      const std::vector<GlobalDof> d = beam_.element_dofs(e);
      for (double xi : {-0.75, -0.25, 0.25, 0.75}) {
        const beams::ShapePoint sp = r.at(xi);
        Vec3 p = Vec3::Zero();
        for (int k = 0; k < r.centerline_vectors(); ++k) {
          Vec3 xk = r.x0[static_cast<std::size_t>(k)];
          for (int c = 0; c < 3 && u.size() > 0; ++c) {
            const GlobalDof g = d[static_cast<std::size_t>(3 * k + c)];
            if (g >= 0) xk[c] += u[g];
          }
          p += sp.B[static_cast<std::size_t>(k)] * xk;
        }
        pts.push_back(p);
      }
    }
    return pts;
  }
  const beams::BeamTerm& beam_;
  double radius_;
  std::vector<Vec3> reference_;
  int worst_count_ = 0;
  double worst_depth_ = 0.0;
};

}  // namespace

std::unique_ptr<RunObserver> make_strut_overlap_check(const beams::BeamTerm& beam, double radius) {
  return std::make_unique<StrutOverlapCheck>(beam, radius);
}

}  // namespace stentsim::solver
