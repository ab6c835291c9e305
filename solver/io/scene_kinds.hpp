#pragma once
// The extension points of the scene format. A condition, a quantity of
// interest or a contact pair is a kind: a name (the entry's `type`), a reader
// that turns its YAML entry into a spec, and the spec, which knows how to add
// its terms, constraints and outputs to a model. Each kind lives in a file of
// its own and is listed once in its family's registry
// (solver/app/conditions/registry.cpp, qoi/registry.cpp, contact/registry.cpp);
// read_scene and the model builder only loop over specs.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "solver/io/scene.hpp"

namespace stentsim::solver {

struct BuiltModel;  // solver/app/built_model.hpp
class RunObserver;  // solver/app/run_observer.hpp

/// What a kind's reader may consult: the scene read so far (bodies and load
/// curves come first) and checks that fail with the entry's file:line:key.
class SceneReader {
 public:
  explicit SceneReader(SceneDesc& scene) : scene(scene) {}
  SceneDesc& scene;

  /// The body named by `key`; `beam` set: it must be a beam (true) or a solid (false) body.
  const BodyDesc& body(ConfigMap& c, const std::string& key, std::optional<bool> beam, const std::string& type) const;
  /// `key` names a load curve ("" when absent and optional).
  std::string curve(ConfigMap& c, const std::string& key, bool required) const;
  /// A beam node selection that selects something.
  beams::BeamNodeSelector beam_nodes(ConfigMap& c, const std::string& key, const BodyDesc& body) const;
  static Vec3 vec3(ConfigMap& m, const std::string& key, std::optional<Vec3> def = std::nullopt);
  /// `key: {origin, direction}` (default: the z axis through the origin), direction normalized.
  static void axis(ConfigMap& c, const std::string& key, Vec3& origin, Vec3& direction);
};

class ConditionSpec {
 public:
  virtual ~ConditionSpec() = default;
  std::string name, body;
  /// Once solver.time is read: times a step must end on (e.g. a release) and checks against the time span.
  virtual void add_stops(const SceneDesc& scene, std::vector<double>& stops) const {}
  /// Unknowns of its own (Lagrange multipliers), allocated before the constraints are sized.
  virtual GlobalDof own_dofs(const BuiltModel& model) const { return 0; }
  /// Adds terms and constraints; `first_own_dof` is the first of own_dofs() (−1 if none).
  virtual void build(const SceneDesc& scene, BuiltModel& model, GlobalDof first_own_dof) const = 0;
};

class QoiSpec {
 public:
  virtual ~QoiSpec() = default;
  std::string name, body;
  /// Writes summary keys without its name as prefix (recoil_percent, D_max …):
  /// a scene holds at most one such QoI.
  virtual bool unprefixed() const { return false; }
  /// The observer that evaluates it during the run and writes its summary entries.
  virtual std::unique_ptr<RunObserver> observer(const SceneDesc& scene, const BuiltModel& model) const = 0;
};

class ContactSpec {
 public:
  virtual ~ContactSpec() = default;
  std::string name;
  /// Adds the pair's term, its outputs (an observer) and checks its initial state.
  virtual void build(const SceneDesc& scene, BuiltModel& model) const = 0;
};

template <class Spec>
struct SceneKind {
  std::string type;
  std::function<std::shared_ptr<Spec>(ConfigMap& entry, SceneReader& reader)> read;
};
using ConditionKind = SceneKind<ConditionSpec>;
using QoiKind = SceneKind<QoiSpec>;
using ContactKind = SceneKind<ContactSpec>;

const std::vector<ConditionKind>& condition_kinds();
const std::vector<QoiKind>& qoi_kinds();
const std::vector<ContactKind>& contact_kinds();

}  // namespace stentsim::solver
