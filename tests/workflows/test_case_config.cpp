// Case files: validation of every section, init examples load and validate.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>

#include "common/error.hpp"
#include "common/files.hpp"
#include "workflows/case_config.hpp"
#include "workflows/case_stages.hpp"
#include "workflows/init_case.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using namespace stentsim::workflows;

namespace {
fs::path temp_dir() {
  auto d = fs::temp_directory_path() / ("stentsim-case-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
std::string load_error(const std::string& text) {
  const auto f = temp_dir() / "bad.yaml";
  files::write_atomic(f, text);
  try {
    load_case(f);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(CaseConfig, EveryExampleLoadsAndValidates) {
  const auto dir = temp_dir() / "init";
  fs::remove_all(dir);
  for (const char* scene : {"free-expansion", "generic-artery", "patient"}) {
    const auto f = write_example_case(dir, scene);
    const auto c = load_case(f);
    EXPECT_EQ(to_string(c.scene), std::string(scene));
    EXPECT_EQ(c.work_dir, (dir / (std::string(scene) + ".work")).lexically_normal());
    EXPECT_THROW(write_example_case(dir, scene), InputError);  // never overwrites
  }
  EXPECT_FALSE(load_case(dir / "free-expansion.yaml").placed);
  // The curved free expansion: a free-expansion scene whose device is placed along its input's centerline.
  const auto curved = load_case(write_example_case(dir, "free-expansion-curved"));
  EXPECT_EQ(curved.scene, Scene::free_expansion);
  EXPECT_TRUE(curved.placed);
  EXPECT_DOUBLE_EQ(curved.simulation.balloon_end_springs, 1000.0);
  std::vector<std::string> plan;
  for (const auto& st : stages_for(curved)) plan.push_back(st.name);
  EXPECT_EQ(plan, (std::vector<std::string>{"segmentation", "centerline", "placement", "balloon", "stent", "solve", "report"}));
  const auto c = load_case(dir / "patient.yaml");
  EXPECT_NEAR(c.simulation.diastolic_pressure, 85 * 133.322387415e-6, 1e-15);
  EXPECT_DOUBLE_EQ(c.simulation.pressure_max, 1.01);
  EXPECT_DOUBLE_EQ(c.mesh.size, 0.8);
  EXPECT_EQ(c.simulation.load_steps, 10);
  EXPECT_EQ(c.simulation.min_load_steps, 2);
  // The paper's resolution ships as an example of its own.
  const auto paper = load_case(fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/patient-paper.yaml");
  EXPECT_EQ(paper.scene, Scene::patient);
  EXPECT_DOUBLE_EQ(paper.mesh.size, 0.25);
  EXPECT_EQ(paper.simulation.load_steps, 100);
  fs::remove_all(dir);
}

TEST(CaseConfig, BadFilesGiveErrorsThatNameFileLineKeyAndExpectation) {
  auto msg = load_error("scene: patient\nmesh:\n  size: 0.25 mm\n  elemnt: tet4\n");
  EXPECT_NE(msg.find("bad.yaml:4:3: mesh.elemnt: unknown key"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'element'"), std::string::npos) << msg;
  msg = load_error("mesh: {size: 1 mm}\n");
  EXPECT_NE(msg.find("scene: required text is missing"), std::string::npos) << msg;
  msg = load_error("scene: hospital\n");
  EXPECT_NE(msg.find("'hospital' is not one of"), std::string::npos) << msg;
  msg = load_error("scene: patient\nsimulation:\n  pressure_max: 13 mm\n");
  EXPECT_NE(msg.find("simulation.pressure_max"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a pressure"), std::string::npos) << msg;
  const std::string in = "input: {phantom: {preset: case2-rca}}\n";
  msg = load_error("scene: patient\n" + in + "simulation:\n  linear_solver: gmres_amg_block\n  ranks: 2\n");
  EXPECT_NE(msg.find("bad.yaml:5:10: simulation.ranks"), std::string::npos) << msg;
  EXPECT_NE(msg.find("gmres_amg_block runs on one MPI rank"), std::string::npos) << msg;
  msg = load_error("scene: patient\n" + in + "simulation:\n  linear_solver: gmres_lu\n  ranks: 2\n");
  EXPECT_NE(msg.find("gmres_lu runs on one MPI rank"), std::string::npos) << msg;
  EXPECT_EQ(load_error("scene: patient\n" + in + "simulation:\n  linear_solver: gmres_ilu\n  ranks: 2\n"), "");
  msg = load_error("scene: patient\nsimulation:\n  load_steps: 4\n  min_load_steps: 5\n");
  EXPECT_NE(msg.find("simulation.min_load_steps"), std::string::npos) << msg;
  EXPECT_NE(msg.find("at most load_steps (4)"), std::string::npos) << msg;
  msg = load_error("scene: patient\nsimulation:\n  load_steps: 0\n");
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
  msg = load_error("scene: patient\nsimulation:\n  load_steps: many\n");
  EXPECT_NE(msg.find("expected an integer, got 'many'"), std::string::npos) << msg;
  msg = load_error("scene: generic-artery\ninput:\n  phantom: {preset: case2-rca}\n");
  EXPECT_NE(msg.find("has no artery input"), std::string::npos) << msg;
  msg = load_error("scene: patient\nscene: generic-artery\n");
  EXPECT_NE(msg.find("duplicate key 'scene'"), std::string::npos) << msg;
  msg = load_error("scene: generic-artery\nmesh:\n  generic: {outer_diameter: 1 mm}\n");
  EXPECT_NE(msg.find("less than outer_diameter"), std::string::npos) << msg;
  // A generic artery too large to allocate: refused by mesh.max_elements with its count, not std::bad_alloc.
  msg = load_error("scene: generic-artery\nmesh:\n  generic: {elements_around: 4096, elements_along: 100000}\n");
  EXPECT_NE(msg.find("mesh.generic.elements_along"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1.64e+09 hex8, more than mesh.max_elements = 1e+06"), std::string::npos) << msg;
  // A resampling spacing that would put millions of points on the centerline, or skip a lesion.
  for (const char* spacing : {"1e-6 mm", "1 m"}) {
    msg = load_error("scene: patient\n" + in + "centerline:\n  spacing: " + spacing + "\n");
    EXPECT_NE(msg.find("bad.yaml:4:12: centerline.spacing"), std::string::npos) << msg;
  }
  msg = load_error("scene: patient\nmesh:\n  max_elements: 0\n");
  EXPECT_NE(msg.find("mesh.max_elements"), std::string::npos) << msg;
}

TEST(CaseConfig, EveryScenesStagesAreDesignStagesInDesignOrder) {
  const auto dir = temp_dir() / "names";
  fs::remove_all(dir);
  const auto& names = all_stage_names();
  EXPECT_EQ(names, (std::vector<std::string>{"segmentation", "centerline", "placement", "balloon", "stent", "mesh",
                                             "fibers", "solve", "report"}));
  for (const char* scene : {"free-expansion", "generic-artery", "patient"}) {
    const auto c = load_case(write_example_case(dir, scene));
    long last = -1;
    for (const auto& st : stages_for(c)) {
      const long pos = std::find(names.begin(), names.end(), st.name) - names.begin();
      ASSERT_LT(pos, static_cast<long>(names.size())) << scene << ": unknown stage " << st.name;
      EXPECT_GT(pos, last) << scene << ": " << st.name << " out of order";
      last = pos;
      if (std::string(scene) != "patient")
        for (const char* artery_only : {"segmentation", "centerline"}) EXPECT_NE(st.name, artery_only) << scene;
      if (std::string(scene) == "free-expansion")
        for (const char* artery_only : {"mesh", "fibers"}) EXPECT_NE(st.name, artery_only) << scene;
    }
  }
  fs::remove_all(dir);
}

TEST(CaseConfig, WorkDirMustBeAFolderOfItsOwn) {
  auto msg = load_error("scene: patient\ninput: {phantom: {preset: case2-rca}}\nwork_dir: .\n");
  EXPECT_NE(msg.find("work_dir: must be a folder of its own"), std::string::npos) << msg;
}
