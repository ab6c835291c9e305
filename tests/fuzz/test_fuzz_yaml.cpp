// Mutation fuzzing of the YAML a user writes: case files (load_case) and solver
// scenes (read_scene, which also reads or generates the meshes they name), and
// hostile YAML built on purpose: deep nesting (flow and block) and alias bombs
// (an anchor repeated ten times per level, nine levels: 10^9 nodes if expanded).
// Each either reads or is an InputError naming the file, within 30 s.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/files.hpp"
#include "solver/io/scene.hpp"
#include "tests/fuzz/mutation.hpp"
#include "workflows/case_config.hpp"

using namespace stentsim;
namespace fs = std::filesystem;

namespace {

const fs::path kExamples = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples";


// YAML no parser should take long over or recurse without bound on.
std::vector<std::pair<std::string, std::string>> hostile(const std::string& prefix) {
  std::vector<std::pair<std::string, std::string>> out;
  for (int depth : {100, 1000, 10000, 100000}) {
    out.emplace_back("flow sequence " + std::to_string(depth), prefix + "x: " + std::string(depth, '[') + std::string(depth, ']') + "\n");
    std::string m = prefix + "x: ";
    for (int i = 0; i < depth; ++i) m += "{a: ";
    out.emplace_back("flow map " + std::to_string(depth), m + "1" + std::string(depth, '}') + "\n");
  }
  for (int depth : {100, 1000, 5000}) {
    std::string b = prefix + "x:\n";
    for (int i = 1; i <= depth; ++i) b += std::string(static_cast<std::size_t>(i), ' ') + "a:\n";
    out.emplace_back("block map " + std::to_string(depth), b);
    std::string s = prefix + "x:\n";
    for (int i = 1; i <= depth; ++i) s += std::string(static_cast<std::size_t>(i), ' ') + "-\n";
    out.emplace_back("block sequence " + std::to_string(depth), s);
  }
  std::string bomb = prefix + "l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int level = 1; level <= 9; ++level) {
    bomb += "l" + std::to_string(level) + ": &l" + std::to_string(level) + " [";
    for (int k = 0; k < 10; ++k) bomb += (k ? ", *l" : "*l") + std::to_string(level - 1);
    bomb += "]\n";
  }
  out.emplace_back("alias bomb", bomb);
  std::string maps = prefix + "m0: &m0 {a: 1, b: 2, c: 3, d: 4, e: 5, f: 6, g: 7, h: 8, i: 9, j: 10}\n";
  for (int level = 1; level <= 9; ++level) {
    maps += "m" + std::to_string(level) + ": &m" + std::to_string(level) + " {";
    for (int k = 0; k < 10; ++k) maps += (k ? ", k" : "k") + std::to_string(k) + ": *m" + std::to_string(level - 1);
    maps += "}\n";
  }
  out.emplace_back("alias bomb of maps", maps);
  out.emplace_back("merge-key bomb", maps + "top:\n  <<: *m9\n");
  out.emplace_back("self alias", prefix + "x: &x [*x]\n");
  out.emplace_back("undefined alias", prefix + "x: *nowhere\n");
  return out;
}

// `dir / name` holds each mutant; `named(name)` is the file its errors must name.
void fuzz_files(const std::string& kind, const std::vector<fs::path>& seeds, const fs::path& dir, std::mt19937& gen,
                const std::function<fs::path(const fs::path&)>& named, const std::function<void(const fs::path&)>& read) {
  const int n = fuzz::iterations();
  for (const fs::path& seed : seeds) {
    const std::string text = files::read_text(seed);
    const fs::path f = dir / seed.filename();
    fuzz::write_file(f, text);
    ASSERT_NO_THROW(read(named(seed.filename()))) << seed << " itself does not read";
    fuzz::judge(kind + " " + seed.stem().string(), n, [&](int) {
      fuzz::write_file(f, fuzz::mutate(text, gen));
      return named(seed.filename());
    }, read);
    // Hostile YAML after the seed's first line (a map key the reader will see), then the seed's own keys.
    const auto cases = hostile(text.substr(0, text.find('\n') + 1));
    std::size_t k = 0;
    fuzz::judge(kind + " hostile", static_cast<int>(cases.size()), [&](int i) {
      k = static_cast<std::size_t>(i);
      fuzz::write_file(f, cases[k].second);
      return named(seed.filename());
    }, [&](const fs::path& p) {
      SCOPED_TRACE(cases[k].first);
      read(p);
    });
  }
}

}  // namespace

TEST(YamlFuzz, CaseFilesReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_case_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::mt19937 gen(20261205);
  fuzz_files("case", {kExamples / "generic-artery.yaml", kExamples / "patient.yaml", kExamples / "free-expansion.yaml"}, dir, gen,
             [&](const fs::path& name) { return dir / name; }, [](const fs::path& f) { (void)workflows::load_case(f); });
  fs::remove_all(dir);
}

TEST(YamlFuzz, SceneFilesReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_scene_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::mt19937 gen(20261206);
  // Read as if they lived among the examples, so the mesh and stent files they name resolve.
  fuzz_files("scene", {kExamples / "tube_inflation.yaml", kExamples / "beam_rollup.yaml", kExamples / "contact_ring_on_balloon.yaml"},
             dir, gen, [](const fs::path& name) { return kExamples / name; },
             [&](const fs::path& f) { (void)solver::read_scene(files::read_text(dir / f.filename()), f); });
  fs::remove_all(dir);
}

// Found by the scene fuzz: a mesh or stent file that does not exist was named without the
// scene or its key ("examples/data/svent_ring_3el.vtu: file not found").
TEST(YamlFuzz, AMissingFileNamesTheSceneAndKey) {
  std::string text = files::read_text(kExamples / "contact_ring_on_balloon.yaml");
  for (const std::string& file : {"data/balloon_3mm.vtu", "data/stent_ring_3el.vtu"}) {
    std::string t = text;
    t.replace(t.find("file: " + file), 6 + file.size(), "file: data/nowhere.vtu");
    try {
      (void)solver::read_scene(t, kExamples / "missing.yaml");
      ADD_FAILURE() << "no error for a missing " << file;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("missing.yaml:"), std::string::npos) << m;
      EXPECT_NE(m.find(".file: no such file: "), std::string::npos) << m;
    }
  }
}
