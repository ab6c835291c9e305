#pragma once
// The active set of a contact pair's points (beam Gauss points, slave nodes)
// at three states: the last converged one (committed), the last accepted
// Newton iterate, and the last tangent assembly. Chattering is counted
// between accepted iterates only, so a line-search trial that is assembled
// with its tangent and then rejected adds no change (newton.hpp: the full
// step is assembled with its tangent; Term::accept follows the accepted
// state's tangent assembly). A trial whose acceptance would exceed the limit
// is itself inadmissible (the pair throws there), so the line search backs off
// from a full step that would chatter.
#include <string>
#include <string_view>
#include <vector>

#include "solver/contact/owned_flags.hpp"
#include "solver/terms/history_archive.hpp"

namespace stentsim::solver::contact {

class ActiveSet {
 public:
  void resize(std::size_t points) {
    committed_.assign(points, 0);
    iterate_ = evaluated_ = committed_;
    changes_.assign(points, 0);
  }
  bool committed(std::size_t i) const { return committed_[i] != 0; }
  /// A tangent assembly found point i active or not: returns how many times the point
  /// changes within this step if that state is accepted.
  int evaluate(std::size_t i, bool active) {
    evaluated_[i] = active;
    return changes_[i] + (static_cast<bool>(iterate_[i]) != active ? 1 : 0);
  }
  struct Changes {
    int active = 0, entered = 0, left = 0;  // in the new iterate: the points this rank evaluated, the others as committed
  };
  /// Term::accept: the evaluated state is the new iterate; what changed from the last one.
  Changes accept() {
    Changes c;
    for (std::size_t i = 0; i < iterate_.size(); ++i) {
      if (iterate_[i] != evaluated_[i]) ++changes_[i], ++(evaluated_[i] ? c.entered : c.left);
      iterate_[i] = evaluated_[i];
      c.active += iterate_[i] != 0;
    }
    return c;
  }
  /// A debug line when the accepted iterate's active set changed.
  static void log_changes(std::string_view pair, const Changes& c);
  void begin_step() { std::fill(changes_.begin(), changes_.end(), 0); }
  /// Term::commit: the last tangent assembly's state converged (in Newton it is also the
  /// accepted iterate). Every rank evaluated its own items only (`per_item` points each).
  void commit(std::size_t per_item, int rank, int ranks) {
    iterate_ = evaluated_;
    gather_owned_flags(iterate_, per_item, rank, ranks);
    committed_ = evaluated_ = iterate_;
  }
  void rollback() { iterate_ = evaluated_ = committed_; }
  void save(HistoryArchive& out, const std::string& key) const {
    out.put(key, std::vector<double>(committed_.begin(), committed_.end()));
  }
  void load(const HistoryArchive& in, const std::string& key) {
    const auto& a = in.get(key, static_cast<long long>(committed_.size()));
    for (std::size_t i = 0; i < a.size(); ++i) committed_[i] = a[i] != 0.0;
    iterate_ = evaluated_ = committed_;
  }

 private:
  std::vector<char> committed_, iterate_, evaluated_;
  std::vector<int> changes_;  // per point, changes between accepted iterates in this step
};

}  // namespace stentsim::solver::contact
