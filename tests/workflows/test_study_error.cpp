// Error study (issue 11): Richardson/GCI and fitted orders on synthetic data,
// study-file validation, the analytic references of the shipped scenes, and
// the runner on a cheap command (phantom segmentation, ~0.5 s a run):
// caching, core limit, CSV columns, plots, --dry-run / --yes; file names in
// the base resolved against their origin; peak memory of MPI runs summed over
// ranks (a 2-rank solve of a small tube).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "common/error.hpp"
#include "common/summary.hpp"
#include "tests/workflows/cli_runner.hpp"
#include "workflows/study/analytic_references.hpp"
#include "workflows/study/convergence.hpp"
#include "workflows/study/error_study.hpp"
#include "workflows/study/input_paths.hpp"
#include "workflows/study/study_config.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using namespace stentsim::study;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_test_study_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& f, const std::string& text) {
  std::ofstream(f) << text;
}

std::string read(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A study over the phantom segmentation: the QoI true_min_radius does not
// depend on the knob, which is all the runner tests need.
fs::path phantom_study(const fs::path& dir, const std::string& values, const std::string& extra = "") {
  write(dir / "phantom.yaml", "input:\n  phantom: {preset: straight-healthy, circumferential_points: 32}\n");
  write(dir / "study.yaml", "name: seg\nbase: phantom.yaml\ncommands: [[segmentation, \"{input}\", --out, \"{run}\"]]\n"
                            "qoi: true_min_radius\nreference: {type: value, value: 1.0}\ntolerance: 0.9\n"
                            "knobs:\n  - name: points\n    key: input.phantom.circumferential_points\n    values: " +
                                values + "\n" + extra);
  return dir / "study.yaml";
}

}  // namespace

TEST(StudyConvergence, RichardsonRecoversKnownOrderAndLimit) {
  // f = 2 + 0.3 h^2 at h = 0.4, 0.2, 0.1 (ratio 2): p = 2, limit 2.
  const std::vector<double> h{0.4, 0.2, 0.1};
  std::vector<double> f;
  for (double x : h) f.push_back(2 + 0.3 * x * x);
  const Richardson r = richardson(h, f, 2.0);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.observed_order, 2.0, 1e-10);
  EXPECT_NEAR(r.extrapolated, 2.0, 1e-12);
  EXPECT_NEAR(r.ratio, 2.0, 1e-12);
  // GCI_fine = 1.25 |(f1 - f2)/f1| / (r^p - 1) (Roache).
  const double f1 = f[2], f2 = f[1];
  EXPECT_NEAR(r.gci_fine, 1.25 * std::abs((f1 - f2) / f1) / 3.0, 1e-14);
  // Order 3 data against a theoretical order 1.5: 3 > 1.5 x 1.5, not asymptotic, no extrapolation.
  std::vector<double> g;
  for (double x : h) g.push_back(1 + x * x * x);
  const Richardson nr = richardson(h, g, 1.5);
  EXPECT_FALSE(nr.ok);
  EXPECT_FALSE(nr.asymptotic);
  EXPECT_NEAR(nr.observed_order, 3.0, 1e-10);
  EXPECT_NE(nr.message.find("not asymptotic"), std::string::npos);
  // No theoretical order: never judged against itself, never extrapolated.
  const Richardson unjudged = richardson(h, f, std::nullopt);
  EXPECT_FALSE(unjudged.ok);
  EXPECT_FALSE(unjudged.asymptotic);
  EXPECT_NE(unjudged.message.find("not judged"), std::string::npos) << unjudged.message;
}

TEST(StudyConvergence, RichardsonRejectsBadRatiosAndOscillation) {
  EXPECT_FALSE(richardson({0.12, 0.1, 0.0833333}, {1.1, 1.05, 1.02}, 2.0).ok);  // ratio 1.2 < 1.5
  const Richardson uneven = richardson({0.4, 0.2, 0.05}, {1.2, 1.1, 1.0}, 2.0);
  EXPECT_FALSE(uneven.ok);
  EXPECT_NE(uneven.message.find("not constant"), std::string::npos);
  EXPECT_FALSE(richardson({0.4, 0.2, 0.1}, {1.2, 0.9, 1.1}, 2.0).ok);  // oscillating
}

TEST(StudyConvergence, FittedAndPairwiseOrders) {
  const std::vector<double> h{0.3, 0.15, 0.075};
  std::vector<double> e;
  for (double x : h) e.push_back(3 * std::pow(x, 1.5));
  ASSERT_TRUE(fitted_order(h, e).has_value());
  EXPECT_NEAR(*fitted_order(h, e), 1.5, 1e-12);
  for (double p : pairwise_orders(h, e)) EXPECT_NEAR(p, 1.5, 1e-12);
  EXPECT_FALSE(fitted_order({0.1}, {0.01}).has_value());
}

TEST(StudyConfigFile, ErrorsNameFileAndKey) {
  const fs::path d = fresh_dir("config");
  write(d / "phantom.yaml", "input:\n  phantom: {preset: straight-healthy}\n");
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    write(d / "bad.yaml", text);
    try {
      load_study(d / "bad.yaml");
      ADD_FAILURE() << "no error for: " << text;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("bad.yaml"), std::string::npos) << msg;
      EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
  };
  const std::string head = "base: phantom.yaml\nqoi: x\nreference: {type: value, value: 1}\n";
  expect_error(head + "knobs: [{name: a, key: input.phantom.seed, values: [1]}]\nbogus: 1\n", "bogus");
  expect_error(head + "knobs: [{name: a, key: input.nothing.seed, values: [1]}]\n", "input.nothing.seed");
  expect_error(head + "knobs: [{name: a, key: input.phantom.seed, values: [1], h: [0.1, 0.2]}]\n", "h");
  expect_error(head + "knobs: [{name: a, key: input.phantom.seed, values: [1]}]\ngrid: [a, b]\n", "grid");
  expect_error("base: missing.yaml\nqoi: x\nreference: {type: value, value: 1}\nknobs: []\n", "base");
  expect_error(head + "knobs: [{name: a, key: input.phantom.seed, values: [1], colour: red}]\n", "colour");
  expect_error("base: phantom.yaml\nqoi: x\nreference: {type: richardson, knob: a}\n"
               "knobs: [{name: a, key: input.phantom.seed, values: [1, 2]}]\n",
               "Richardson");
  // A Richardson reference needs the theoretical order of its knob.
  expect_error("base: phantom.yaml\nqoi: x\nreference: {type: richardson, knob: a}\n"
               "knobs: [{name: a, key: input.phantom.seed, values: [1, 2, 3], h: [0.4, 0.2, 0.1]}]\n",
               "knobs.a.theoretical_order");
  // Per-setting orders name a setting label of another knob.
  expect_error(head + "knobs: [{name: a, key: input.phantom.seed, values: [1, 2], h: [0.2, 0.1],"
                      " theoretical_order: {default: 2, curvd: 3}},\n        {name: b, key: input.phantom.preset, values: [x], labels: [curved]}]\n",
               "'curvd'");
  fs::remove_all(d);
}

TEST(StudyReferences, ShippedScenesMatchClosedForms) {
  const fs::path src(STENTSIM_TEST_SOURCE_DIR);
  const fs::path d = fresh_dir("refs");
  // Tube: the example's own value (0.12 MPa, E = 1, nu = 0.45): 1.176890 mm.
  write(d / "tube.yaml", "base: " + (src / "examples/tube_inflation.yaml").string() +
                             "\nqoi: inner_radius_at_pmax\nreference: {type: tube_plane_strain}\n"
                             "knobs: [{name: n, key: bodies.0.mesh.generate.radial, values: [2]}]\n");
  const StudyConfig tube = load_study(d / "tube.yaml");
  EXPECT_NEAR(analytic_reference(tube, tube.base).at(0), 1.176890, 1e-6);
  // Roll-up by 2 pi: the tip returns to the root and has turned by 2 pi.
  write(d / "beam.yaml", "base: " + (src / "examples/beam_rollup.yaml").string() +
                             "\nqoi: tip_position\nreference: {type: beam_rollup}\nerror: absolute\n"
                             "knobs: [{name: n, key: bodies.0.beam.generate.elements, values: [8]}]\n");
  StudyConfig beam = load_study(d / "beam.yaml");
  const auto tip = analytic_reference(beam, beam.base);
  ASSERT_EQ(tip.size(), 3u);
  for (double x : tip) EXPECT_NEAR(x, 0.0, 1e-9);
  beam.qoi = "tip_rotation_angle";
  EXPECT_NEAR(analytic_reference(beam, beam.base).at(0), 2 * M_PI, 1e-9);
  fs::remove_all(d);
}

TEST(StudyRunner, CachesRunsAndRerunsOnlyNewPoints) {
  const fs::path d = fresh_dir("cache");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult first;
  ASSERT_EQ(run_error_study(phantom_study(d, "[16, 24]"), o, log, &first), 0) << log.str();
  EXPECT_EQ(first.stats.executed, 3);  // base (32) + 16 + 24
  EXPECT_EQ(first.stats.cached, 0);
  ErrorStudyResult second;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &second), 0);
  EXPECT_EQ(second.stats.executed, 0);
  EXPECT_EQ(second.stats.cached, 3);
  // A new knob value: only that point runs.
  ErrorStudyResult third;
  ASSERT_EQ(run_error_study(phantom_study(d, "[16, 24, 40]"), o, log, &third), 0);
  EXPECT_EQ(third.stats.executed, 1);
  EXPECT_EQ(third.stats.cached, 3);
  // A row from another binary version is recomputed unless --reuse-timings.
  const fs::path result = run_dir(o.out_dir, third.plan.runs.back()) / "result.yaml";
  std::string text = read(result);
  const auto pos = text.find("binary_version: ");
  ASSERT_NE(pos, std::string::npos);
  text.insert(pos + 16, "old-");
  write(result, text);
  o.reuse_timings = true;
  ErrorStudyResult reused;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &reused), 0);
  EXPECT_EQ(reused.stats.executed, 0);
  o.reuse_timings = false;
  ErrorStudyResult redone;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &redone), 0);
  EXPECT_EQ(redone.stats.executed, 1);
  fs::remove_all(d);
}

TEST(StudyRunner, NeverMoreRanksInFlightThanCores) {
  const fs::path d = fresh_dir("cores");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out1";
  o.jobs = 4;
  o.cores = 1;
  std::ostringstream log;
  ErrorStudyResult one;
  ASSERT_EQ(run_error_study(phantom_study(d, "[16, 24, 40]"), o, log, &one), 0) << log.str();
  EXPECT_EQ(one.stats.executed, 4);
  EXPECT_EQ(one.stats.max_ranks_in_flight, 1);
  o.cores = 2;
  o.out_dir = d / "out2";
  ErrorStudyResult two;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &two), 0);
  EXPECT_EQ(two.stats.max_ranks_in_flight, 2);  // two at once, never three
  // A run needing more ranks than cores is refused before anything runs.
  o.out_dir = d / "out3";
  phantom_study(d, "[16]", "  - name: ranks\n    key: \"@ranks\"\n    values: [3]\n");
  EXPECT_THROW(run_error_study(d / "study.yaml", o, log), InputError);
  EXPECT_FALSE(fs::exists(d / "out3" / "runs"));
  fs::remove_all(d);
}

TEST(StudyRunner, WritesCsvMarkdownAndPlots) {
  const fs::path d = fresh_dir("report");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult r;
  ASSERT_EQ(run_error_study(phantom_study(d, "[16, 24]", "    h: [0.4, 0.2]\n"), o, log, &r), 0) << log.str();
  const std::string csv = read(o.out_dir / "study.csv");
  const std::string header = csv.substr(0, csv.find('\n'));
  for (const char* col : {"run", "label", "status", "points", "qoi", "value", "reference", "error", "wall_time_s", "cpu_time_s",
                          "peak_memory_mb", "ranks", "host", "nproc", "load_average", "binary_version", "pareto", "qoi.true_min_radius"})
    EXPECT_NE(("," + header + ",").find(std::string(",") + col + ","), std::string::npos) << col << " in " << header;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);  // header + 3 runs
  for (const auto& row : r.results) {
    EXPECT_EQ(row.status, "ok");
    EXPECT_GT(row.wall_s, 0);
    EXPECT_GT(row.peak_memory_mb, 1);
  }
  for (double e : r.outcome.error) EXPECT_TRUE(std::isfinite(e) && e > 0);
  EXPECT_FALSE(r.outcome.pareto.empty());
  ASSERT_TRUE(r.outcome.cheapest.has_value());  // tolerance 0.9 on a relative error < 1
  for (const char* f : {"error_vs_wall_time.png", "error_vs_wall_time.svg", "error_vs_h.png", "error_vs_h.svg", "study.md"}) {
    ASSERT_TRUE(fs::exists(o.out_dir / f)) << f;
    EXPECT_GT(fs::file_size(o.out_dir / f), 1000u) << f;
  }
  const std::string md = read(o.out_dir / "study.md");
  EXPECT_NE(md.find("Cheapest within tolerance"), std::string::npos);
  EXPECT_NE(md.find("Pareto front"), std::string::npos);

  // summary.yaml like every other tool: counts, orders, cheapest run, time and memory.
  const auto sum = stentsim::Summary::read(o.out_dir / "summary.yaml");
  auto q = [&](const std::string& name) -> const stentsim::Qoi* {
    const auto it = sum.qois().find(name);
    return it == sum.qois().end() ? nullptr : &it->second;
  };
  ASSERT_NE(q("runs"), nullptr);
  EXPECT_EQ(std::get<double>(q("runs")->value), 3.0);
  EXPECT_EQ(std::get<double>(q("runs_failed")->value), 0.0);
  EXPECT_EQ(std::get<double>(q("runs_executed")->value) + std::get<double>(q("runs_cached")->value), 3.0);
  ASSERT_NE(q("cheapest_run"), nullptr);
  EXPECT_EQ(std::get<std::string>(q("cheapest_run")->value), r.plan.runs[*r.outcome.cheapest].label);
  ASSERT_NE(q("cheapest_wall_time"), nullptr);
  EXPECT_EQ(q("cheapest_wall_time")->unit, "s");
  int orders = 0;
  for (const auto& [name, v] : sum.qois())
    if (name.rfind("fitted_order.", 0) == 0) ++orders;
  int fitted = 0;
  for (const auto& l : r.outcome.lines) fitted += l.fitted_order ? 1 : 0;
  EXPECT_EQ(orders, fitted);
  EXPECT_GT(sum.wall_time_s(), 0.0);
  EXPECT_GT(sum.peak_memory_mb(), 0.0);
  fs::remove_all(d);
}

TEST(StudyCli, DryRunListsRunsAndManyRunsNeedYes) {
  const fs::path d = fresh_dir("cli");
  std::string many = "[";
  for (int i = 0; i < 60; ++i) many += (i ? ", " : "") + std::to_string(100 + i);
  phantom_study(d, many + "]");
  const auto dry = stentsim::testing::run_stentsim("study error " + (d / "study.yaml").string() + " --dry-run --out " + (d / "out").string());
  EXPECT_EQ(dry.code, 0) << dry.out;
  EXPECT_NE(dry.out.find("61 runs"), std::string::npos) << dry.out;
  EXPECT_NE(dry.out.find("--yes"), std::string::npos) << dry.out;
  const auto refused = stentsim::testing::run_stentsim("study error " + (d / "study.yaml").string() + " --out " + (d / "out").string());
  EXPECT_EQ(refused.code, 2) << refused.out;
  EXPECT_NE(refused.out.find("--yes"), std::string::npos) << refused.out;
  EXPECT_FALSE(fs::exists(d / "out" / "runs"));
  const auto bad = stentsim::testing::run_stentsim("study error " + (d / "nothing.yaml").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  fs::remove_all(d);
}

TEST(StudyConfigFile, RelativeFilesResolveAgainstTheirOrigin) {
  // The base names its mesh relative to itself; a knob value names a file
  // relative to the study file; words that are no file stay words.
  const fs::path d = fresh_dir("paths");
  fs::create_directories(d / "cases");
  fs::create_directories(d / "meshes");
  write(d / "cases" / "mesh.vtu", "coarse");
  write(d / "meshes" / "fine.vtu", "fine");
  write(d / "cases" / "scene.yaml", "bodies:\n  - mesh: {file: mesh.vtu, element: tet10}\n");
  write(d / "study.yaml", "base: cases/scene.yaml\nqoi: x\nreference: {type: value, value: 1}\n"
                          "knobs: [{name: m, key: bodies.0.mesh.file, values: [meshes/fine.vtu, cases/mesh.vtu]}]\n");
  const StudyConfig s = load_study(d / "study.yaml");
  EXPECT_EQ(fs::path(s.base["bodies"][0]["mesh"]["file"].as<std::string>()), fs::absolute(d / "cases" / "mesh.vtu").lexically_normal());
  EXPECT_EQ(s.base["bodies"][0]["mesh"]["element"].as<std::string>(), "tet10");
  EXPECT_EQ(fs::path(s.knobs[0].values[0][0].as<std::string>()), fs::absolute(d / "meshes" / "fine.vtu").lexically_normal());
  // The second knob value is the base's own mesh, named from the study's folder: the same run.
  const StudyPlan p = plan_study(s);
  EXPECT_EQ(p.runs.size(), 2u);
  // A run reads the file: changed content is a new run (new key).
  const std::string key = p.runs[0].key;
  write(d / "cases" / "mesh.vtu", "coarse, edited");
  EXPECT_NE(plan_study(load_study(d / "study.yaml")).runs[0].key, key);
  fs::remove_all(d);
}

TEST(StudyRunner, BaseNamingItsMeshRelativeToItselfRuns) {
  // The shipped contrast bar names contrast_bar.vtu beside itself; the study
  // sits one folder up and runs the copy in OUT/runs/<key>/.
  const fs::path src = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples" / "studies" / "stability";
  const fs::path d = fresh_dir("relmesh");
  fs::create_directories(d / "cases");
  for (const char* f : {"contrast_bar.yaml", "contrast_bar.vtu"}) fs::copy_file(src / f, d / "cases" / f);
  write(d / "study.yaml", "base: cases/contrast_bar.yaml\nqoi: max_displacement\nreference: {type: value, value: 0.3}\n"
                          "knobs: [{name: dt, key: solver.time.dt, values: [0.25]}]\n");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult r;
  EXPECT_EQ(run_error_study(d / "study.yaml", o, log, &r), 0) << log.str();
  ASSERT_EQ(r.results.size(), 1u);
  EXPECT_EQ(r.results[0].status, "ok") << r.results[0].message;
  // The pulled end moved 0.3 mm along the bar; the largest displacement adds
  // the soft half's lateral contraction (0.3037 mm measured).
  EXPECT_GE(r.outcome.value[0], 0.3 - 1e-9);
  EXPECT_LT(r.outcome.value[0], 0.31);
  fs::remove_all(d);
}

TEST(StudyRunner, RankMemoryIsSummedWhenReported) {
  RunResult r;
  r.peak_memory_mb = 130;  // wait4: the largest process of mpirun's tree
  r.qoi[kPerRankMemoryQoi] = {100, 120};
  apply_rank_memory(r, 2);
  EXPECT_DOUBLE_EQ(r.peak_memory_mb, 220);
  EXPECT_EQ(r.peak_memory_rule, "sum over 2 ranks");
  RunResult unreported;
  unreported.peak_memory_mb = 130;
  apply_rank_memory(unreported, 2);
  EXPECT_DOUBLE_EQ(unreported.peak_memory_mb, 130);
  EXPECT_NE(unreported.peak_memory_rule.find("largest"), std::string::npos);
  RunResult one;
  one.peak_memory_mb = 50;
  one.qoi[kPerRankMemoryQoi] = {48};
  apply_rank_memory(one, 1);
  EXPECT_DOUBLE_EQ(one.peak_memory_mb, 50);  // one process: wait4's value
}

TEST(StudyRunner, MpiRunReportsMemorySummedOverRanks) {
  // A small tube solved on 1 and 2 ranks: each rank writes its own peak into
  // summary.yaml and the 2-rank row is their sum.
  const fs::path d = fresh_dir("mpi");
  write(d / "study.yaml", "base: " + (fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/tube_inflation.yaml").string() +
                              "\noverrides: {bodies.0.mesh.generate.radial: 2, bodies.0.mesh.generate.circumferential: 6}\n"
                              "qoi: inner_radius_at_pmax\nreference: {type: tube_plane_strain}\n"
                              "knobs: [{name: ranks, key: \"@ranks\", values: [2]}]\n");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  o.cores = 2;
  std::ostringstream log;
  ErrorStudyResult r;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &r), 0) << log.str();
  ASSERT_EQ(r.plan.runs.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const RunResult& res = r.results[i];
    const int ranks = r.plan.runs[i].ranks;
    ASSERT_EQ(res.status, "ok") << res.message;
    ASSERT_TRUE(res.qoi.count(kPerRankMemoryQoi)) << "summary.yaml has no per-rank memory";
    const auto& per_rank = res.qoi.at(kPerRankMemoryQoi);
    ASSERT_EQ(static_cast<int>(per_rank.size()), ranks);
    double sum = 0;
    for (double m : per_rank) {
      EXPECT_GT(m, 5) << "a rank's peak memory in MB";
      sum += m;
    }
    if (ranks == 1) {
      EXPECT_EQ(res.peak_memory_rule, "wait4");
    } else {
      EXPECT_EQ(res.peak_memory_rule, "sum over 2 ranks");
      EXPECT_GE(res.peak_memory_mb, sum - 1e-9);
      EXPECT_GT(res.peak_memory_mb, 1.5 * std::max(per_rank[0], per_rank[1]));  // not the largest process alone
    }
  }
  // Both solves agree (the 2-rank partition sums the same residual).
  EXPECT_NEAR(r.outcome.value[0], r.outcome.value[1], 1e-9);
  EXPECT_NE(read(o.out_dir / "study.csv").find("sum over 2 ranks"), std::string::npos);
  fs::remove_all(d);
}

TEST(StudyCli, DryRunEstimatesFromBaseTimeBeforeAnythingRan) {
  // h knob with cost exponent 2, but the base has no h of its own (32 points is
  // neither listed setting), so no run is scaled from it: each run is estimated
  // at the base's 2 s: 3 runs (base, 16, 64 points), 6 s in all.
  const fs::path d = fresh_dir("estimate");
  phantom_study(d, "[16, 64]", "    h: [0.4, 0.2]\n    cost_exponent: 2\n");
  const auto none = stentsim::testing::run_stentsim("study error " + (d / "study.yaml").string() + " --dry-run --out " + (d / "out").string());
  EXPECT_EQ(none.code, 0) << none.out;
  EXPECT_NE(none.out.find("give base_time"), std::string::npos) << none.out;
  std::ofstream(d / "study.yaml", std::ios::app) << "base_time: 2 s\n";
  const auto est = stentsim::testing::run_stentsim("study error " + (d / "study.yaml").string() + " --dry-run --out " + (d / "out").string());
  EXPECT_EQ(est.code, 0) << est.out;
  // base 2 s; points=16 (h 0.4) nearest the base (one knob differs, the base has no h): 2 s; points=64 likewise.
  EXPECT_NE(est.out.find("~2.0 s"), std::string::npos) << est.out;
  EXPECT_NE(est.out.find("estimated time to run: 6 s (from the study's base_time 2 s)"), std::string::npos) << est.out;
  fs::remove_all(d);
}

TEST(StudyRunner, QoiMissingFromSummaryIsAFailedRowNamingIt) {
  // A typo'd QoI: every run succeeds, none writes 'true_min_radios'. The rows
  // fail with the QoI, the run and "did you mean 'true_min_radius'", the
  // study exits 1 (and the CLI non-zero), study.md lists the failures.
  const fs::path d = fresh_dir("qoi_typo");
  phantom_study(d, "[16]");
  std::string text = read(d / "study.yaml");
  text.replace(text.find("qoi: true_min_radius"), 20, "qoi: true_min_radios");
  write(d / "study.yaml", text);
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult r;
  EXPECT_EQ(run_error_study(d / "study.yaml", o, log, &r), 1) << log.str();
  EXPECT_EQ(r.stats.failed, 2);
  ASSERT_EQ(r.results.size(), 2u);
  for (std::size_t i = 0; i < r.results.size(); ++i) {
    const auto& row = r.results[i];
    EXPECT_EQ(row.status, "failed");
    EXPECT_NE(row.message.find("'true_min_radios'"), std::string::npos) << row.message;
    EXPECT_NE(row.message.find(r.plan.runs[i].key.substr(0, 8)), std::string::npos) << row.message;
    EXPECT_NE(row.message.find("did you mean 'true_min_radius'"), std::string::npos) << row.message;
    EXPECT_FALSE(std::isfinite(r.outcome.error[i]));
  }
  EXPECT_NE(log.str().find("did not write qoi 'true_min_radios'"), std::string::npos) << log.str();
  EXPECT_NE(read(o.out_dir / "study.md").find("Failed runs"), std::string::npos);
  // The runs themselves stay cached: fixing the name needs no re-run.
  const auto cli = stentsim::testing::run_stentsim("study error " + (d / "study.yaml").string() + " --out " + (d / "out").string());
  EXPECT_NE(cli.code, 0) << cli.out;
  EXPECT_NE(cli.out.find("true_min_radios"), std::string::npos) << cli.out;
  write(d / "study.yaml", read(d / "study.yaml").replace(text.find("true_min_radios"), 15, "true_min_radius"));
  ErrorStudyResult fixed;
  EXPECT_EQ(run_error_study(d / "study.yaml", o, log, &fixed), 0) << log.str();
  EXPECT_EQ(fixed.stats.executed, 0);
  EXPECT_EQ(fixed.stats.failed, 0);
  fs::remove_all(d);
}

namespace {
// Results for a plan whose QoI along `knob` is f(h) = 1 + h^p, no process run.
std::vector<RunResult> synthetic_results(const StudyConfig& s, const StudyPlan& plan, const std::string& knob, double p) {
  std::vector<RunResult> results(plan.runs.size());
  for (std::size_t i = 0; i < plan.runs.size(); ++i) {
    results[i].status = "ok";
    results[i].wall_s = 1.0 + static_cast<double>(i);
    const auto h = run_h(s, plan.runs[i], knob);
    const double hh = h ? *h : 0.1;  // the base is the finest setting here
    results[i].qoi[s.qoi] = {1.0 + std::pow(hh, p)};
  }
  return results;
}
}  // namespace

TEST(StudyConvergence, RichardsonStudyOutsideTheOrderBandIsNotExtrapolated) {
  // Observed order 3 against theoretical 1 (band 0.5-1.5): "not asymptotic",
  // the reference is the finest run (no extrapolation). Against 3: extrapolated to 1.
  const fs::path d = fresh_dir("band");
  write(d / "phantom.yaml", "input:\n  phantom: {preset: straight-healthy, circumferential_points: 64}\n");
  auto study = [&](const std::string& order) {
    write(d / "study.yaml", "base: phantom.yaml\nqoi: q\nreference: {type: richardson, knob: n}\nerror: absolute\n"
                            "knobs: [{name: n, key: input.phantom.circumferential_points, values: [16, 32, 64], h: [0.4, 0.2, 0.1],"
                            " theoretical_order: " + order + "}]\n");
    return load_study(d / "study.yaml");
  };
  const StudyConfig s1 = study("1");
  const StudyPlan plan = plan_study(s1);
  ASSERT_EQ(plan.runs.size(), 3u);
  const StudyOutcome o1 = evaluate_study(s1, plan, synthetic_results(s1, plan, "n", 3.0));
  EXPECT_NE(o1.reference_note.find("NOT done"), std::string::npos) << o1.reference_note;
  EXPECT_NE(o1.reference_note.find("not asymptotic"), std::string::npos) << o1.reference_note;
  ASSERT_EQ(o1.lines.size(), 1u);
  ASSERT_TRUE(o1.lines[0].richardson.has_value());
  EXPECT_FALSE(o1.lines[0].richardson->ok);
  EXPECT_NEAR(o1.lines[0].richardson->observed_order, 3.0, 1e-9);
  EXPECT_NEAR(o1.reference[0].at(0), 1.001, 1e-12);  // the finest run's value, not the limit 1
  const StudyConfig s3 = study("3");
  const StudyOutcome o3 = evaluate_study(s3, plan, synthetic_results(s3, plan, "n", 3.0));
  EXPECT_NE(o3.reference_note.find("Richardson extrapolation"), std::string::npos) << o3.reference_note;
  EXPECT_NEAR(o3.reference[0].at(0), 1.0, 1e-9);
  EXPECT_TRUE(o3.lines[0].richardson->ok);
  fs::remove_all(d);
}

TEST(StudyConfigFile, TheoreticalOrderPerSettingJudgesEachGridLine) {
  // The shipped tube study: tet10-curved lines against 3, the others against 2.
  const StudyConfig s = load_study(fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/studies/tube.yaml");
  const Knob* h = nullptr;
  for (const auto& k : s.knobs)
    if (k.name == "h") h = &k;
  ASSERT_NE(h, nullptr);
  EXPECT_EQ(theoretical_order_for(s, *h, {}), 2.0);                // base: hex8
  EXPECT_EQ(theoretical_order_for(s, *h, {{"element", 1}}), 2.0);  // tet10 straight
  EXPECT_EQ(theoretical_order_for(s, *h, {{"element", 2}}), 3.0);  // tet10-curved
  const StudyPlan plan = plan_study(s);
  const StudyOutcome o = evaluate_study(s, plan, synthetic_results(s, plan, "h", 3.0));
  int curved = 0;
  for (const auto& line : o.lines)
    if (line.label.find("tet10-curved") != std::string::npos && line.knob == "h") {
      ++curved;
      EXPECT_EQ(line.theoretical_order, 3.0);
      ASSERT_TRUE(line.richardson.has_value());
      EXPECT_TRUE(line.richardson->ok) << line.richardson->message;
    }
  EXPECT_EQ(curved, 1);
}

TEST(StudyConfigFile, ShippedStudiesLoadPlanAndEstimate) {
  // Every study in examples/studies loads, plans and gives a dry-run estimate
  // from its base_time; the other YAML files there are some study's base.
  const fs::path dir = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples" / "studies";
  std::vector<fs::path> studies, others;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".yaml") (YAML::LoadFile(e.path().string())["knobs"] ? studies : others).push_back(e.path());
  EXPECT_GE(studies.size(), 3u);
  std::set<fs::path> bases;
  const fs::path out = fresh_dir("shipped");
  for (const auto& f : studies) {
    SCOPED_TRACE(f.string());
    StudyConfig s;
    ASSERT_NO_THROW(s = load_study(f));
    bases.insert(fs::weakly_canonical(s.base_file));
    EXPECT_TRUE(s.base_time_s.has_value()) << "no base_time";
    StudyPlan plan;
    ASSERT_NO_THROW(plan = plan_study(s));
    EXPECT_GE(plan.runs.size(), 3u);
    for (const auto& k : s.knobs)
      if (k.h.size() >= 3) {
        EXPECT_TRUE(theoretical_order_for(s, k, {}).has_value()) << k.name << ": an h series without theoretical_order";
      }
    ErrorStudyOptions o;
    o.binary = STENTSIM_TEST_BINARY;
    o.dry_run = true;
    o.out_dir = out / f.stem();
    std::ostringstream log;
    ASSERT_EQ(run_error_study(f, o, log), 0) << log.str();
    EXPECT_NE(log.str().find("from the study's base_time"), std::string::npos) << log.str();
    EXPECT_EQ(log.str().find("unknown"), std::string::npos) << log.str();
    EXPECT_FALSE(fs::exists(o.out_dir / "runs"));
  }
  for (const auto& f : others) EXPECT_TRUE(bases.count(fs::weakly_canonical(f))) << f << " is neither a study nor a study's base";
  fs::remove_all(out);
}

TEST(StudyConvergence, RichardsonOfAQoiTendingToZeroGivesOnlyAnAbsoluteGci) {
  // f = 0.3 h^2 -> 0: Roache's GCI divides by f1 (0.003 against 0.048 at the
  // coarsest); it is reported undefined and the absolute GCI is given instead.
  const std::vector<double> h{0.4, 0.2, 0.1};
  std::vector<double> f;
  for (double x : h) f.push_back(0.3 * x * x * 1e-2);
  const Richardson r = richardson(h, f, 2.0);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.tends_to_zero);
  EXPECT_NEAR(r.extrapolated, 0.0, 1e-15);
  EXPECT_TRUE(std::isnan(r.gci_fine));
  EXPECT_NEAR(r.gci_fine_absolute, 1.25 * std::abs(f[2] - f[1]) / 3.0, 1e-18);
  EXPECT_NE(r.message.find("tends to 0"), std::string::npos) << r.message;
  // Away from 0 both are given and the relative one is Roache's.
  const Richardson away = richardson(h, {2 + f[0], 2 + f[1], 2 + f[2]}, 2.0);
  EXPECT_FALSE(away.tends_to_zero);
  EXPECT_NEAR(away.gci_fine, away.gci_fine_absolute / (2 + f[2]), 1e-15);
}

TEST(StudyReport, RelativeErrorAgainstAVanishingReferenceIsReportedAbsoluteWithANote) {
  // QoI = h^2 against a reference 0 (and 1e-15, a closed form's round-off):
  // relative errors would divide by 0 or by round-off. The study reports
  // absolute errors / error_scale, says so in the outcome, study.md, the CSV
  // (error_kind) and the log, and the order is still measured.
  const fs::path d = fresh_dir("vanishing");
  write(d / "phantom.yaml", "input:\n  phantom: {preset: straight-healthy, circumferential_points: 64}\n");
  auto study = [&](const std::string& ref) {
    write(d / "study.yaml", "base: phantom.yaml\nqoi: q\nreference: {type: value, value: " + ref + "}\nerror_scale: 2\n"
                            "knobs: [{name: n, key: input.phantom.circumferential_points, values: [16, 32, 64], h: [0.4, 0.2, 0.1],"
                            " theoretical_order: 2}]\n");
    return load_study(d / "study.yaml");
  };
  for (const std::string ref : {"0", "1.0e-15"}) {
    SCOPED_TRACE(ref);
    const StudyConfig s = study(ref);
    const StudyPlan plan = plan_study(s);
    std::vector<RunResult> results(plan.runs.size());
    for (std::size_t i = 0; i < plan.runs.size(); ++i) {
      results[i].status = "ok";
      results[i].wall_s = 1.0 + static_cast<double>(i);
      const double h = run_h(s, plan.runs[i], "n").value_or(0.1);
      results[i].qoi["q"] = {h * h};
    }
    StudyOutcome o;
    ASSERT_NO_THROW(o = evaluate_study(s, plan, results));
    EXPECT_FALSE(o.relative_error);
    EXPECT_NE(o.error_note.find("tends to 0"), std::string::npos) << o.error_note;
    EXPECT_NE(o.error_note.find("ABSOLUTE"), std::string::npos) << o.error_note;
    for (std::size_t i = 0; i < plan.runs.size(); ++i)
      EXPECT_NEAR(o.error[i], std::abs(results[i].qoi["q"][0] - std::stod(ref)) / 2, 1e-15);
    ASSERT_TRUE(o.lines.at(0).fitted_order.has_value());
    EXPECT_NEAR(*o.lines[0].fitted_order, 2.0, 1e-6);
    const auto files = write_report(s, plan, results, o, d / "out");
    const std::string md = read(files.markdown), csv = read(files.csv);
    EXPECT_NE(md.find("**Note:** relative error refused"), std::string::npos) << md;
    EXPECT_NE(md.find("error: absolute / 2"), std::string::npos) << md;
    EXPECT_NE(csv.find(",absolute,"), std::string::npos) << csv;
    EXPECT_EQ(csv.find(",relative,"), std::string::npos) << csv;
  }
  // A reference away from 0 keeps the relative error, without a note.
  const StudyConfig s = study("0.5");
  const StudyPlan plan = plan_study(s);
  std::vector<RunResult> results(plan.runs.size());
  for (auto& r : results) r.status = "ok", r.wall_s = 1, r.qoi["q"] = {0.5 + 0.01};
  const StudyOutcome o = evaluate_study(s, plan, results);
  EXPECT_TRUE(o.relative_error);
  EXPECT_TRUE(o.error_note.empty());
  EXPECT_NEAR(o.error[0], 0.02, 1e-12);
  fs::remove_all(d);
}

TEST(StudyRunner, RowsFromAnotherHostAreRecomputedUnlessReuseTimings) {
  // Issue 11: cached rows from another host are recomputed unless
  // --reuse-timings (the binary-version case is in CachesRunsAndRerunsOnlyNewPoints).
  const fs::path d = fresh_dir("host");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult first;
  ASSERT_EQ(run_error_study(phantom_study(d, "[16]"), o, log, &first), 0) << log.str();
  ASSERT_EQ(first.stats.executed, 2);
  const std::string here = first.results[1].host;
  const fs::path result = run_dir(o.out_dir, first.plan.runs[1]) / "result.yaml";
  std::string text = read(result);
  const auto pos = text.find("host: ");
  ASSERT_NE(pos, std::string::npos);
  text.insert(pos + 6, "another-machine-");
  write(result, text);
  o.reuse_timings = true;
  ErrorStudyResult reused;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &reused), 0) << log.str();
  EXPECT_EQ(reused.stats.executed, 0);
  EXPECT_EQ(reused.results[1].host, "another-machine-" + here);  // the row keeps its own host
  EXPECT_NE(read(o.out_dir / "study.csv").find("another-machine-"), std::string::npos);
  o.reuse_timings = false;
  ErrorStudyResult redone;
  ASSERT_EQ(run_error_study(d / "study.yaml", o, log, &redone), 0) << log.str();
  EXPECT_EQ(redone.stats.executed, 1);
  EXPECT_EQ(redone.stats.cached, 1);
  EXPECT_EQ(redone.results[1].host, here);
  EXPECT_FALSE(redone.results[1].cached);
  EXPECT_EQ(read(result).find("another-machine-"), std::string::npos);
  fs::remove_all(d);
}

TEST(StudyReport, FittedOrderLineSharesItsSeriesColourAndIsInTheLegend) {
  // Issue 11 review: the fit lines took the next palette colour and had no
  // legend entry. Each fit must be dashed, in its markers' colour, and named
  // "<line> fit p = <order>".
  const StudyConfig s = load_study(fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/studies/tube.yaml");
  const StudyPlan plan = plan_study(s);
  const StudyOutcome o = evaluate_study(s, plan, synthetic_results(s, plan, "h", 3.0));
  const plots::Figure f = error_vs_h_figure(s, o);
  int fits = 0;
  std::set<int> colours;
  for (std::size_t i = 0; i < f.series.size(); ++i) {
    const auto& ser = f.series[i];
    if (!ser.dashed) {
      EXPECT_EQ(ser.style, plots::Style::markers);
      EXPECT_TRUE(colours.insert(ser.colour).second) << "each line its own colour: " << ser.label;
      continue;
    }
    ++fits;
    ASSERT_GT(i, 0u);
    const auto& data = f.series[i - 1];
    EXPECT_EQ(ser.colour, data.colour) << ser.label;
    EXPECT_GE(ser.colour, 0);
    EXPECT_EQ(ser.label.rfind(data.label + " fit p = ", 0), 0u) << ser.label;
  }
  EXPECT_GE(fits, 3) << "hex8, tet10, tet10-curved lines along h";
}

TEST(StudyRunner, StenosisSiteErrorOnAHealthyPhantomIsAFailedRow) {
  // The healthy phantom has no stenosis: the centerline tool leaves
  // stenosis_site_error out of summary.yaml (it used to write 0, "perfect"),
  // so a study asking for it gets a failed row naming the QoI.
  const fs::path d = fresh_dir("healthy_site");
  write(d / "phantom.yaml", "input:\n  phantom: {preset: straight-healthy, circumferential_points: 16}\n");
  write(d / "study.yaml",
        "name: healthy\nbase: phantom.yaml\n"
        "commands:\n  - [segmentation, \"{input}\", --out, \"{run}\"]\n"
        "  - [centerline, --lumen, \"{run}/lumen.vtp\", --out, \"{run}/centerline.vtp\", --true-centerline, \"{run}/centerline_true.vtp\"]\n"
        "qoi: stenosis_site_error\nreference: {type: qoi_is_error}\nerror: absolute\n"
        "knobs:\n  - name: points\n    key: input.phantom.circumferential_points\n    values: [16]\n");
  ErrorStudyOptions o;
  o.binary = STENTSIM_TEST_BINARY;
  o.out_dir = d / "out";
  std::ostringstream log;
  ErrorStudyResult r;
  EXPECT_EQ(run_error_study(d / "study.yaml", o, log, &r), 1) << log.str();
  ASSERT_FALSE(r.results.empty());
  for (const auto& row : r.results) {
    EXPECT_EQ(row.status, "failed");
    EXPECT_NE(row.message.find("stenosis_site_error"), std::string::npos) << row.message;
    EXPECT_EQ(row.qoi.count("inscribed_radius_error_max"), 1u) << "the run itself succeeded";
  }
  fs::remove_all(d);
}
