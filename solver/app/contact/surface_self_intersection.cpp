#include "solver/app/contact/surface_self_intersection.hpp"

#include <fmt/format.h>

#include "common/log.hpp"
#include "common/self_intersection.hpp"

namespace stentsim::solver {
namespace {

class SurfaceSelfIntersectionCheck : public RunObserver {
 public:
  SurfaceSelfIntersectionCheck(const contact::ContactSurface& surface, std::string body) : surface_(surface), body_(std::move(body)) {
    for (const auto& f : surface_.faces())
      for (const auto& t : contact::linear_triangles(f)) triangles_.push_back(t);
  }
  void start(const Eigen::VectorXd& u, bool restarted) override {
    if (!restarted) check(u, 0.0, "in the initial state");
  }
  void step(const StepRecord& r, const Eigen::VectorXd& u) override { check(u, r.time, fmt::format("at t = {:.4g}", r.time)); }
  std::string checkpoint_name() const override { return "self_intersection/" + body_; }
  void save(HistoryArchive& out, const std::string& prefix) const override {
    out.put(prefix + "pairs", static_cast<double>(worst_pairs_));
    out.put(prefix + "first_time", first_time_);
  }
  void load(const HistoryArchive& in, const std::string& prefix) override {
    worst_pairs_ = static_cast<std::size_t>(in.get_scalar(prefix + "pairs"));
    first_time_ = in.get_scalar(prefix + "first_time");
  }
  void summarize(Summary& s, const RunEnd&) const override {
    s.set("self_intersection_pairs_max_" + body_, static_cast<double>(worst_pairs_));
    s.set("self_intersection_first_time_" + body_, first_time_);
  }

 private:
  void check(const Eigen::VectorXd& u, double time, const std::string& when) {
    std::vector<Vec3> x(surface_.num_nodes());
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] = surface_.reference(int(i));
      for (int c = 0; c < 3; ++c) {
        const GlobalDof g = surface_.dof(int(i), c);
        if (g >= 0 && g < u.size()) x[i][c] += u[g];
      }
    }
    const auto pairs = self_intersecting_triangles(x, triangles_, kSelfIntersectionLimit);
    if (pairs.empty()) return;
    const auto& t = triangles_[std::size_t(pairs[0].first)];
    const Vec3 at = (x[std::size_t(t[0])] + x[std::size_t(t[1])] + x[std::size_t(t[2])]) / 3.0;
    log::warn("body '{}': its contact surface intersects itself {} (self-contact is not modelled): {}{} pairs of triangles, "
              "the first near ({:.3f}, {:.3f}, {:.3f}) mm",
              body_, when, pairs.size() >= kSelfIntersectionLimit ? "at least " : "", pairs.size(), at.x(), at.y(), at.z());
    worst_pairs_ = std::max(worst_pairs_, pairs.size());
    if (first_time_ < 0) first_time_ = time;
  }
  const contact::ContactSurface& surface_;
  std::string body_;
  std::vector<std::array<int, 3>> triangles_;
  std::size_t worst_pairs_ = 0;
  double first_time_ = -1.0;
};

}  // namespace

std::unique_ptr<RunObserver> make_surface_self_intersection_check(const contact::ContactSurface& surface, std::string body) {
  return std::make_unique<SurfaceSelfIntersectionCheck>(surface, std::move(body));
}

}  // namespace stentsim::solver
