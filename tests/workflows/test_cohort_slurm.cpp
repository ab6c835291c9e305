// The Slurm back-end of `stentsim cohort run`, for real: each test starts a
// private single-node Slurm (munged + slurmctld + slurmd, fresh state folder,
// free ports; test_cohort_slurm_cluster.sh) and always stops it.
// Skipped only when the Slurm binaries are absent and CI is unset.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
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

int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  const int port = ntohs(a.sin_port);
  ::close(s);
  return port;
}

const std::string kCluster = std::string(STENTSIM_TEST_SOURCE_DIR) + "/tests/workflows/test_cohort_slurm_cluster.sh";

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

class CohortSlurm : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have("sbatch") || !have("slurmctld") || !have("slurmd") || !have("munged")) {
      if (std::getenv("CI")) FAIL() << "CI is set but the Slurm binaries are missing: run scripts/install-deps.sh";
      GTEST_SKIP() << "Slurm not installed (sbatch, slurmctld, slurmd, munged from slurmctld slurmd slurm-client munge; "
                      "scripts/install-deps.sh installs them)";
    }
    const std::string tag = std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    cluster = fs::temp_directory_path() / ("stentsim-slurm-" + tag);
    dir = fs::temp_directory_path() / ("stentsim-cohort-slurm-" + tag);
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string cmd = kCluster + " start " + cluster.string() + " " + std::to_string(free_port()) + " " +
                            std::to_string(free_port()) + " " + std::to_string(::getpid());
    started = std::system(cmd.c_str()) == 0;
    ASSERT_TRUE(started) << "could not start the private Slurm cluster (" << cmd << ")";
    ::setenv("SLURM_CONF", (cluster / "slurm.conf").c_str(), 1);
    ASSERT_EQ(sh("init " + dir.string() + " --cohort").code, 0);
  }
  void TearDown() override {
    if (!cluster.empty()) std::system((kCluster + " stop " + cluster.string()).c_str());
    ::unsetenv("SLURM_CONF");
    if (!dir.empty()) fs::remove_all(dir);
  }
  std::string queue() {
    std::string out;
    FILE* p = ::popen("squeue -h -o %A 2>&1", "r");
    char buf[256];
    while (p && std::fgets(buf, sizeof buf, p)) out += buf;
    if (p) ::pclose(p);
    return out;
  }
  // Three phantom cases from the example cohort, with a given backend block.
  std::string cohort(const std::string& name, const std::string& backend) {
    const fs::path f = dir / (name + ".yaml");
    write_atomic(f, "name: " + name + "\ntemplate: patient.yaml\nworkers: 2\n" + backend +
                        "cases:\n"
                        "  - id: rca-seed1\n"
                        "  - id: straight\n    overrides: {input: {phantom: {preset: straight-healthy}}}\n"
                        "  - id: severe\n    overrides: {input: {phantom: {preset: severe-70}}}\n    expect_failure: placement\n");
    return f.string();
  }
  fs::path cluster, dir;
  bool started = false;
};

TEST_F(CohortSlurm, SameResultsAsLocalBackend) {
  const auto local = cohort("local", "");
  auto r = sh("cohort run " + local + " --until centerline");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto slurm = cohort("slurm", "backend: slurm\nslurm: {partition: debug, time_limit: \"10\", poll_interval_s: 0.2}\n");
  r = sh("cohort run " + slurm + " --until centerline");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("3 cases submitted to Slurm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 cases: 3 as expected, 0 unexpected"), std::string::npos) << r.out;
  const auto a = results(dir / "local.work/cohort_summary.csv");
  const auto b = results(dir / "slurm.work/cohort_summary.csv");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a, b);  // same statuses and same QoIs, case by case
  EXPECT_EQ(b.at("rca-seed1").at("status"), "done");
  EXPECT_FALSE(b.at("rca-seed1").at("centerline.min_radius [mm]").empty());
  // Each case ran as a Slurm job: its script, its Slurm output file, its exit code.
  EXPECT_TRUE(fs::exists(dir / "slurm.work/straight/slurm_job.sh"));
  EXPECT_EQ(read_text(dir / "slurm.work/straight/exit_code"), "0\n");
  EXPECT_NE(read_text(dir / "slurm.work/slurm_jobs.txt").find("severe "), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "slurm.work/plot_centerline.min_radius.png"));

  // A submission the cluster rejects is a clear error and leaves no jobs behind.
  const auto bad = cohort("bad", "backend: slurm\nslurm: {partition: nope}\n");
  r = sh("cohort run " + bad + " --until centerline");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("sbatch failed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("case 'rca-seed1'"), std::string::npos) << r.out;
  EXPECT_EQ(queue(), "");
}

TEST_F(CohortSlurm, InterruptCancelsSubmittedJobs) {
  // Hold every job in the queue (--hold), so the interrupt finds them pending.
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
    submitted = fs::exists(log) && read_text(log).find("submitted to Slurm") != std::string::npos;
  }
  EXPECT_TRUE(submitted) << read_text(log);
  const std::string q = queue();
  EXPECT_EQ(std::count(q.begin(), q.end(), '\n'), 3) << q;
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130) << read_text(log);
  EXPECT_NE(read_text(log).find("cancelled 3 Slurm job(s)"), std::string::npos) << read_text(log);
  // Cancelled jobs may still be listed as CANCELLED for a while; none may be pending or running.
  FILE* p = ::popen("squeue -h -t PENDING,RUNNING,COMPLETING -o %A", "r");
  char buf[256];
  std::string active;
  while (p && std::fgets(buf, sizeof buf, p)) active += buf;
  if (p) ::pclose(p);
  EXPECT_EQ(active, "");
}

TEST(CohortSlurmErrors, MissingSbatchIsAClearError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim-cohort-nosbatch-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ASSERT_EQ(sh("init " + dir.string() + " --cohort").code, 0);
  const fs::path f = dir / "c.yaml";
  write_atomic(f, "template: patient.yaml\nbackend: slurm\ncases:\n  - id: a\n");
  // An empty PATH: sbatch cannot be found (the binary itself is given by full path).
  Result r{0, ""};
  FILE* p = ::popen(("PATH=/nonexistent " + std::string(STENTSIM_TEST_BINARY) + " cohort run " + f.string() + " 2>&1").c_str(), "r");
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) r.out += buf;
  const int status = p ? ::pclose(p) : -1;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("'sbatch' not found in PATH"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

}  // namespace
