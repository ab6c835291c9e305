// The Slurm back-end of `stentsim cohort run`, for real, on the private
// single-node Slurm that the CTest fixture `slurm_cluster` starts before these
// tests and stops after them (test_cohort_slurm_cluster.sh; SLURM_CONF points
// at it). Skipped only when Slurm is not installed and CI is unset.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/files.hpp"
#include "tests/workflows/cli_runner.hpp"

namespace fs = std::filesystem;
using stentsim::files::read_text;
using stentsim::files::write_atomic;

namespace {

using Result = stentsim::testing::CliResult;
Result sh(const std::string& args) { return stentsim::testing::run_stentsim(args); }

bool have(const char* tool) { return std::system((std::string("command -v ") + tool + " >/dev/null 2>&1").c_str()) == 0; }

std::string capture(const std::string& cmd) {
  std::string out;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  char buf[512];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  if (p) ::pclose(p);
  return out;
}

// Tasks still pending, running or completing (one line each).
std::string active_queue() { return capture("squeue -h -r -t PENDING,RUNNING,COMPLETING,CONFIGURING -o %i"); }

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// CSV -> case id -> column -> value, for the columns that do not depend on timing.
std::map<std::string, std::map<std::string, std::string>> results(const fs::path& csv) {
  std::map<std::string, std::map<std::string, std::string>> out;
  std::istringstream in(read_text(csv));
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::string cur;
    bool q = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char ch = line[i];
      if (q && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') cur += '"', ++i;
      else if (ch == '"') q = !q;
      else if (ch == ',' && !q) cells.push_back(cur), cur.clear();
      else cur += ch;
    }
    cells.push_back(cur);
    return cells;
  };
  std::string line;
  std::getline(in, line);
  const auto header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    for (std::size_t i = 1; i < header.size() && i < cells.size(); ++i)
      if (header[i].find("time") == std::string::npos && header[i] != "message") out[cells[0]][header[i]] = cells[i];
  }
  return out;
}

// case id -> Slurm task id, from the cohort manifest.
std::map<std::string, std::string> tasks_of(const fs::path& work) {
  std::map<std::string, std::string> t;
  const YAML::Node m = YAML::LoadFile((work / "cohort_manifest.yaml").string());
  for (const auto& kv : m["slurm_tasks"]) t[kv.first.as<std::string>()] = kv.second["job"].as<std::string>();
  return t;
}

// The status line of one case in `cohort status` output, runs of spaces squeezed to one.
std::string status_line(const std::string& out, const std::string& id) {
  std::istringstream in(out);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(id + " ", 0) == 0) {
      std::string q;
      for (char ch : l)
        if (ch != ' ' || q.empty() || q.back() != ' ') q += ch;
      return q;
    }
  return "";
}

class CohortSlurm : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* conf = std::getenv("SLURM_CONF");
    if (!conf || !fs::exists(conf)) {
      const bool installed = have("sbatch") && have("slurmctld") && have("slurmd") && have("munged");
      if (installed || std::getenv("CI"))
        FAIL() << (installed ? "Slurm is installed but the fixture cluster is not running (run the tests through ctest: "
                               "fixture cohort_slurm_cluster_start)"
                             : "CI is set but Slurm is missing: run scripts/install-deps.sh");
      GTEST_SKIP() << "Slurm not installed (sbatch, slurmctld, slurmd, munged from slurmctld slurmd slurm-client munge; "
                      "scripts/install-deps.sh installs them)";
    }
    cluster = fs::path(conf).parent_path();
    dir = cluster.parent_path() / "slurm-cohort-tests" / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir);
    fs::create_directories(dir);
    ASSERT_EQ(sh("init " + dir.string() + " --cohort").code, 0);
  }
  void TearDown() override {
    // Leave the shared cluster idle for the next test.
    if (cluster.empty()) return;
    std::system("ids=$(squeue -h -o %A); [ -n \"$ids\" ] && scancel $ids");
    for (int i = 0; i < 100 && !active_queue().empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    fs::remove_all(dir);
  }
  // Three phantom cases from the example cohort, with a given backend block.
  std::string cohort(const std::string& name, const std::string& backend) {
    const fs::path f = dir / (name + ".yaml");
    write_atomic(f, "name: " + name + "\ntemplate: patient.yaml\nworkers: 2\n" + backend +
                        "cases:\n"
                        "  - id: rca-seed1\n"
                        "  - id: straight\n    overrides: {input: {phantom: {preset: straight-healthy}}, "
                        "device: {placement: {site_abscissa: 10 mm}}}\n"
                        "  - id: severe\n    overrides: {input: {phantom: {preset: severe-70}}}\n    expect_failure: placement\n");
    return f.string();
  }
  fs::path cluster, dir;
};

// All three cases up to placement, where severe-70 fails as it declares
// (expect_failure: placement): the array's results equal the local pool's.
TEST_F(CohortSlurm, JobArrayGivesTheLocalResults) {
  const auto local = cohort("local", "");
  auto r = sh("cohort run " + local + " --until placement");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto slurm = cohort("slurm", "backend: slurm\nslurm: {partition: debug, time_limit: \"10\", memory: 500M, poll_interval_s: 0.2}\n");
  // A dry run shows the array and submits nothing.
  const std::string jobs_before = capture("squeue -h -t all -o %i");
  r = sh("cohort run " + slurm + " --until placement --dry-run");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("(dry run, nothing is submitted): 3 cases: 3 to submit"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'--array=0-2'"), std::string::npos) << r.out;
  EXPECT_EQ(active_queue(), "");
  EXPECT_EQ(capture("squeue -h -t all -o %i"), jobs_before);  // not even a probe job
  EXPECT_FALSE(fs::exists(dir / "slurm.work/cohort_manifest.yaml"));

  r = sh("cohort run " + slurm + " --until placement");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("probe job"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("submitted job array"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(3 task(s) of 1 rank(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("severe               failed as expected at placement"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 cases: 3 as expected, 0 unexpected"), std::string::npos) << r.out;
  // The waiting line carries an ETA once a task has finished (median stage times).
  EXPECT_TRUE(std::regex_search(r.out, std::regex("slurm: [0-9]+ pending, [0-9]+ running, [12]/3 finished, ETA [0-9]+ s")))
      << r.out;
  const auto a = results(dir / "local.work/cohort_summary.csv");
  const auto b = results(dir / "slurm.work/cohort_summary.csv");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a, b);  // same statuses, exit codes and QoIs, case by case
  EXPECT_EQ(b.at("rca-seed1").at("status"), "done");
  EXPECT_EQ(b.at("severe").at("status"), "failed as expected");
  EXPECT_EQ(b.at("severe").at("failed_stage"), "placement");
  EXPECT_EQ(b.at("severe").at("exit_code"), "1");
  EXPECT_FALSE(b.at("rca-seed1").at("centerline.min_radius [mm]").empty());
  EXPECT_FALSE(b.at("rca-seed1").at("placement.placement_min_clearance [mm]").empty());
  // One array: tasks <job>_0.._2 in cohort order, each with its exit-code file and Slurm output.
  const auto t = tasks_of(dir / "slurm.work");
  ASSERT_EQ(t.size(), 3u);
  const std::string job = t.at("rca-seed1").substr(0, t.at("rca-seed1").find('_'));
  EXPECT_EQ(t.at("rca-seed1"), job + "_0");
  EXPECT_EQ(t.at("straight"), job + "_1");
  EXPECT_EQ(t.at("severe"), job + "_2");
  EXPECT_EQ(read_text(dir / "slurm.work/straight/exit_code"), "0 " + job + "_1\n");
  EXPECT_EQ(read_text(dir / "slurm.work/severe/exit_code"), "1 " + job + "_2\n");
  EXPECT_NE(read_text(dir / ("slurm.work/slurm/slurm-" + job + "_1.out")).find("case straight: exit 0"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "slurm.work/plot_centerline.min_radius.png"));
  r = sh("cohort status " + slurm);
  EXPECT_NE(status_line(r.out, "severe").find(t.at("severe") + " failed as expected"), std::string::npos) << r.out;

  // A submission the cluster rejects is a clear error and leaves no jobs behind.
  const auto bad = cohort("bad", "backend: slurm\nslurm: {partition: nope}\n");
  r = sh("cohort run " + bad + " --until centerline");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("sbatch failed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("nope"), std::string::npos) << r.out;
  EXPECT_EQ(active_queue(), "");
}

// --no-wait, `cohort status`, a lost task, and re-runs that attach to queued
// tasks and resubmit only the lost case. Tasks are held (--hold) so that they
// are certainly pending while the test looks at them.
TEST_F(CohortSlurm, NoWaitStatusLostTaskAndReattach) {
  const auto f = cohort("held", "backend: slurm\nslurm: {extra_sbatch_options: \"--hold\", poll_interval_s: 0.2}\n");
  const fs::path work = dir / "held.work";
  auto r = sh("cohort run " + f + " --until centerline --no-wait");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("3 to submit"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not waiting (--no-wait)"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(work / "cohort_summary.csv"));  // nothing finished yet
  const auto t1 = tasks_of(work);
  ASSERT_EQ(t1.size(), 3u);
  EXPECT_EQ(lines(active_queue()), 3) << active_queue();

  // The straight case's task leaves the queue without running: lost.
  capture("scancel " + t1.at("straight"));
  for (int i = 0; i < 50 && lines(active_queue()) > 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  r = sh("cohort status " + f);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(status_line(r.out, "rca-seed1").find(t1.at("rca-seed1") + " pending"), std::string::npos) << r.out;
  EXPECT_NE(status_line(r.out, "straight").find(t1.at("straight") + " failed (lost: time, memory or node)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("lost: time, memory or node (Slurm task " + t1.at("straight")), std::string::npos) << r.out;

  // Re-run: attaches to the two pending tasks, resubmits only the lost case.
  r = sh("cohort run " + f + " --until centerline --no-wait");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1 to submit, 2 queued or running (attached), 0 up to date"), std::string::npos) << r.out;
  const auto t2 = tasks_of(work);
  EXPECT_EQ(t2.at("rca-seed1"), t1.at("rca-seed1"));
  EXPECT_EQ(t2.at("severe"), t1.at("severe"));
  EXPECT_NE(t2.at("straight"), t1.at("straight"));
  EXPECT_EQ(lines(active_queue()), 3) << active_queue();

  // Release everything; a waiting run attaches to all three and submits nothing.
  for (const auto& job : {t1.at("rca-seed1"), t2.at("straight")}) capture("scontrol release " + job.substr(0, job.find('_')));
  r = sh("cohort run " + f + " --until centerline");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("submitted job array"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 cases: 3 as expected, 0 unexpected"), std::string::npos) << r.out;
  EXPECT_EQ(results(work / "cohort_summary.csv").at("straight").at("status"), "done");
  r = sh("cohort status " + f);
  EXPECT_NE(status_line(r.out, "straight").find(t2.at("straight") + " done"), std::string::npos) << r.out;

  // Everything up to date: no probe, no submission.
  r = sh("cohort run " + f + " --until centerline");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("0 to submit, 0 queued or running (attached), 3 up to date"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("probe job"), std::string::npos) << r.out;
}

// A work folder the compute node does not see (the fixture's slurmd runs with
// an empty tmpfs over <cluster>/hidden): the probe job stops the run before
// any case is submitted.
TEST_F(CohortSlurm, ProbeJobStopsWhenNodesCannotSeeTheWorkFolder) {
  if (fs::exists(cluster / "hidden_unsupported"))
    GTEST_SKIP() << "mount namespaces not permitted here: the fixture could not hide a folder from slurmd";
  const fs::path hidden = cluster / "hidden" / "probe.work";
  const auto f = cohort("probe", "backend: slurm\nwork_dir: " + hidden.string() + "\nslurm: {poll_interval_s: 0.2}\n");
  const auto r = sh("cohort run " + f + " --until centerline");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("the Slurm compute nodes cannot use this cohort: probe job"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("could not read the token file " + (hidden / "slurm/probe_token").string()), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("submitted job array"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(hidden / "cohort_manifest.yaml"));
  EXPECT_EQ(active_queue(), "");
}

TEST_F(CohortSlurm, InterruptCancelsSubmittedTasks) {
  // Hold every task in the queue (--hold), so the interrupt finds them pending.
  const auto f = cohort("cancel", "backend: slurm\nslurm: {extra_sbatch_options: \"--hold\", poll_interval_s: 0.2}\n");
  const fs::path log = dir / "cancel.out";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen(log.c_str(), "w", stdout);
    ::dup2(1, 2);
    ::execl(STENTSIM_TEST_BINARY, STENTSIM_TEST_BINARY, "cohort", "run", f.c_str(), "--until", "centerline", nullptr);
    ::_exit(127);
  }
  bool submitted = false;
  for (int i = 0; i < 300 && !submitted; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    submitted = fs::exists(log) && read_text(log).find("submitted job array") != std::string::npos;
  }
  EXPECT_TRUE(submitted) << read_text(log);
  EXPECT_EQ(lines(active_queue()), 3) << active_queue();
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130) << read_text(log);
  EXPECT_NE(read_text(log).find("cancelled 3 Slurm task(s)"), std::string::npos) << read_text(log);
  EXPECT_EQ(active_queue(), "");  // cancelled tasks may be listed as CANCELLED, never pending or running
}

// A folder holding an `squeue` that fails (as when the controller restarts)
// on its first `fail` calls from the follower (the `%i %T` query), then hands
// over to the real one; `fail` < 0: always.
fs::path failing_squeue(const fs::path& dir, int fail) {
  const fs::path bin = dir / "shim";
  fs::create_directories(bin);
  const std::string real = capture("command -v squeue");
  write_atomic(bin / "squeue", "#!/bin/bash\n"
                               "n=$(cat " + (bin / "count").string() + " 2>/dev/null || echo 0)\n"
                               "case \" $* \" in *\" %i %T \"*)\n"
                               "  if [ " + std::to_string(fail) + " -lt 0 ] || [ \"$n\" -lt " + std::to_string(fail) + " ]; then\n"
                               "    echo $((n + 1)) > " + (bin / "count").string() + "\n"
                               "    echo 'squeue: error: Unable to contact slurm controller (connect failure)' >&2; exit 1\n"
                               "  fi;;\n"
                               "esac\n"
                               "exec " + real.substr(0, real.find('\n')) + " \"$@\"\n");
  fs::permissions(bin / "squeue", fs::perms::owner_all);
  return bin;
}

// squeue failing for a few polls does not end the follower (it used to cancel
// the whole array): it waits, says so, and the cases finish as usual.
TEST_F(CohortSlurm, AQueueThatStopsAnsweringForAWhileIsWaitedOut) {
  const auto f = cohort("blip", "backend: slurm\nslurm: {poll_interval_s: 0.2}\n");
  const fs::path bin = failing_squeue(dir, 3);
  const std::string out = capture("PATH=" + bin.string() + ":$PATH " + std::string(STENTSIM_TEST_BINARY) + " cohort run " + f +
                                  " --until centerline 2>&1; echo exit=$?");
  EXPECT_NE(out.find("squeue failed (exit 1): squeue: error: Unable to contact slurm controller"), std::string::npos) << out;
  EXPECT_NE(out.find("trying again for up to 300 s"), std::string::npos) << out;
  EXPECT_NE(out.find("slurm: squeue answers again"), std::string::npos) << out;
  EXPECT_EQ(out.find("cancelled"), std::string::npos) << out;
  EXPECT_NE(out.find("3 cases: 3 as expected, 0 unexpected"), std::string::npos) << out;
  EXPECT_NE(out.find("exit=0"), std::string::npos) << out;
  EXPECT_EQ(read_text(bin / "count"), "3\n");
}

// A queue that stays silent past slurm.queue_patience_s ends the follower with
// an error that says how to follow up, and the tasks are left to run.
TEST_F(CohortSlurm, AQueueSilentPastItsPatienceLeavesTheTasksRunning) {
  const auto f = cohort("silent", "backend: slurm\nslurm: {extra_sbatch_options: \"--hold\", poll_interval_s: 0.2, queue_patience_s: 1}\n");
  const fs::path bin = failing_squeue(dir, -1);
  const std::string out = capture("PATH=" + bin.string() + ":$PATH " + std::string(STENTSIM_TEST_BINARY) + " cohort run " + f +
                                  " --until centerline 2>&1; echo exit=$?");
  EXPECT_NE(out.find("submitted job array"), std::string::npos) << out;
  EXPECT_NE(out.find("the submitted tasks were left to run: follow them with `stentsim cohort status " + f + "`"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("cancelled"), std::string::npos) << out;
  EXPECT_NE(out.find("exit=1"), std::string::npos) << out;
  EXPECT_EQ(lines(active_queue()), 3) << active_queue();  // still held in the queue
}

TEST(CohortSlurmErrors, MissingSbatchIsAClearError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-nosbatch-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ASSERT_EQ(sh("init " + dir.string() + " --cohort").code, 0);
  const fs::path f = dir / "c.yaml";
  write_atomic(f, "template: patient.yaml\nbackend: slurm\ncases:\n  - id: a\n");
  // An empty PATH: sbatch cannot be found (the binary itself is given by full path).
  const std::string out = capture("PATH=/nonexistent " + std::string(STENTSIM_TEST_BINARY) + " cohort run " + f.string() + " 2>&1" +
                                  "; echo exit=$?");
  EXPECT_NE(out.find("exit=1"), std::string::npos) << out;
  EXPECT_NE(out.find("'sbatch' not found in PATH"), std::string::npos) << out;
  // --no-wait without the slurm back-end is an input error (exit 2).
  write_atomic(f, "template: patient.yaml\ncases:\n  - id: a\n");
  const auto r = sh("cohort run " + f.string() + " --no-wait");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--no-wait needs the slurm back-end"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

}  // namespace
