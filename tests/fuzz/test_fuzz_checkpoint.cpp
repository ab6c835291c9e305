// Mutation fuzzing of solver checkpoints (`stentsim solve --restart FILE`): a short
// run of the stent ring on its balloon (solid with viscous history, plastic beams,
// beam-to-surface contact, QoI observers) writes a checkpoint; each mutant is
// restarted from. A checksum ends the file, so most mutants change the payload and
// re-seal it (the checksum of the mutated payload), to reach the parser and the
// terms' history loading; the others are mutated as they are (the checksum must
// refuse them). Each restart either completes or is an InputError naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/files.hpp"
#include "common/log.hpp"
#include "common/summary.hpp"
#include "solver/app/solve.hpp"
#include "solver/io/scene.hpp"
#include "tests/fuzz/mutation.hpp"

using namespace stentsim;
using namespace stentsim::solver;
namespace fs = std::filesystem;

namespace {

const fs::path kExamples = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples";

// The example cut to two steps, with a checkpoint after each, its files named absolutely.
std::string short_scene() {
  std::string t = files::read_text(kExamples / "contact_ring_on_balloon.yaml");
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = t.find(from);
    if (at == std::string::npos) throw std::runtime_error("contact_ring_on_balloon.yaml has no '" + from + "'");
    t.replace(at, from.size(), to);
  };
  replace("file: data/balloon_3mm.vtu", "file: " + (kExamples / "data/balloon_3mm.vtu").string());
  replace("file: data/stent_ring_3el.vtu", "file: " + (kExamples / "data/stent_ring_3el.vtu").string());
  replace("end: 2, dt: 0.1", "end: 0.2, dt: 0.1");
  replace("times: {max: 1, after: 2}", "times: {max: 0.1, after: 0.2}");
  replace("output:\n  every: 1", "output:\n  every: 1\n  checkpoint_every: 1");
  replace("peak_time: 1", "peak_time: 0.1");
  return t;
}

}  // namespace

TEST(CheckpointFuzz, RestartsFromMutantsCompleteOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_checkpoint_fuzz_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  log::set_level(log::Level::error);
  files::write_atomic(dir / "scene.yaml", short_scene());
  const SceneDesc scene = read_scene(dir / "scene.yaml");
  SolveOptions first;
  first.output_dir = dir / "run";
  Summary summary;
  ASSERT_EQ(solve(scene, first, summary), 0);
  const std::string sealed = files::read_text(dir / "run/checkpoint.bin");
  const std::size_t sum = files::text_hash("").size();
  ASSERT_GT(sealed.size(), sum);
  const std::string payload = sealed.substr(0, sealed.size() - sum);
  ASSERT_EQ(files::text_hash(payload), sealed.substr(payload.size())) << "the checkpoint no longer ends in text_hash of the rest";

  auto restart = [&](const fs::path& f) {
    SolveOptions o;
    o.output_dir = dir / "resumed";
    o.restart = f;
    Summary s;
    ASSERT_EQ(solve(scene, o, s), 0);
  };
  restart(dir / "run/checkpoint.bin");  // the seed itself resumes
  const int n = fuzz::iterations();
  std::mt19937 gen(20261207);
  fuzz::judge("checkpoint (re-sealed payload)", n, [&](int) {
    const std::string m = fuzz::mutate(payload, gen);
    fuzz::write_file(dir / "mutant.bin", m + files::text_hash(m));
    return dir / "mutant.bin";
  }, restart);
  fuzz::judge("checkpoint (raw)", std::max(1, n / 4), [&](int) {
    fuzz::write_file(dir / "mutant.bin", fuzz::mutate(sealed, gen));
    return dir / "mutant.bin";
  }, restart);
  fs::remove_all(dir);
}
