// The solver's part of checkpoint.bin: every named field back as written, the
// predictor's state included, and a checkpoint without that state (written
// before the predictor existed) read as "no guess for the first step".
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "common/error.hpp"
#include "common/files.hpp"
#include "solver/app/checkpoint.hpp"
#include "solver/io/results_writer.hpp"

namespace stentsim::solver {
namespace {

TEST(SolverCheckpoint, RoundTripKeepsThePredictorState) {
  SolverCheckpoint c;
  c.u = Eigen::VectorXd::LinSpaced(5, 0.0, 1.0);
  c.time = 0.75, c.next_dt = 0.02, c.last_dt = 0.01;
  c.last_increment = Eigen::VectorXd::Constant(5, 0.125);
  c.counters.newton_iterations = 40, c.counters.linear_iterations = 41, c.counters.step_cuts = 2;
  c.counters.steps = 9, c.counters.predicted_steps = 7;
  HistoryArchive a;
  c.put(a);
  const SolverCheckpoint r = SolverCheckpoint::get(a, 5);
  EXPECT_EQ(r.u, c.u);
  EXPECT_EQ(r.last_increment, c.last_increment);
  EXPECT_EQ(r.time, 0.75);
  EXPECT_EQ(r.next_dt, 0.02);
  EXPECT_EQ(r.last_dt, 0.01);
  EXPECT_EQ(r.counters.steps, 9);
  EXPECT_EQ(r.counters.predicted_steps, 7);
  EXPECT_EQ(r.counters.step_cuts, 2);
  EXPECT_THROW(SolverCheckpoint::get(a, 6), InputError);  // another model
}

// --restart with a FIFO or a device (a checkpoint name pointing at /dev/zero) is an input
// error at once, not a read without end.
TEST(SolverCheckpoint, AFifoOrADeviceIsNotReadAsACheckpoint) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / ("stentsim-ckpt-fifo-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  ASSERT_EQ(::mkfifo((d / "pipe.bin").c_str(), 0600), 0);
  std::filesystem::create_symlink("/dev/zero", d / "zero.bin");
  for (const char* f : {"pipe.bin", "zero.bin"}) {
    try {
      HistoryArchive::read(d / f);
      ADD_FAILURE() << f << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(d);
}

TEST(SolverCheckpoint, WithoutPredictorStateResumesWithoutAGuess) {
  SolverCheckpoint c;
  c.u = Eigen::VectorXd::Ones(3);
  HistoryArchive a;
  c.put(a);  // an empty last increment: the first step of a run
  SolverCheckpoint r = SolverCheckpoint::get(a, 3);
  EXPECT_EQ(r.last_increment.size(), 0);
  HistoryArchive old;
  for (const char* k : {"solver/time", "solver/next_dt", "solver/newton_iterations", "solver/linear_iterations",
                        "solver/step_cuts", "solver/steps"})
    old.put(k, 1.0);
  old.put("solver/u", std::span<const double>(c.u.data(), 3));
  r = SolverCheckpoint::get(old, 3);
  EXPECT_EQ(r.last_increment.size(), 0);
  EXPECT_EQ(r.last_dt, 0.0);
  EXPECT_EQ(r.counters.predicted_steps, 0);
}

// A restart's results writer continues from its checkpoint: what the interrupted run wrote
// after it (later frames, a frame cut short) is removed and the PVD lists the checkpoint's
// frames again.
TEST(ResultsWriterRestart, RemovesWhatTheInterruptedRunWroteAfterItsCheckpoint) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("stentsim-writer-restart-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  MeshData m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.add_cell(CellType::tetra, {0, 1, 2, 3});
  HistoryArchive ck;
  {
    ResultsWriter w(dir);
    w.history_header({"step", "time"});
    w.write_frame(0, 0.0, {{"body", m}});
    w.history_row({1, 0.5});
    w.write_frame(1, 0.5, {{"body", m}});
    w.save(ck);  // the checkpoint after step 1
    w.history_row({2, 1.0});
    w.write_frame(2, 1.0, {{"body", m}});  // then interrupted, a frame half written
    files::write_atomic(dir / "results/.body_00003.vtu.tmp-1", "cut short");
  }
  ResultsWriter resumed(dir);
  resumed.load(ck);
  EXPECT_TRUE(fs::exists(dir / "results/body_00000.vtu"));
  EXPECT_TRUE(fs::exists(dir / "results/body_00001.vtu"));
  EXPECT_FALSE(fs::exists(dir / "results/body_00002.vtu"));
  EXPECT_FALSE(fs::exists(dir / "results/.body_00003.vtu.tmp-1"));
  const std::string pvd = files::read_text(dir / "results.pvd");
  EXPECT_NE(pvd.find("body_00001.vtu"), std::string::npos) << pvd;
  EXPECT_EQ(pvd.find("body_00002.vtu"), std::string::npos) << pvd;
  EXPECT_EQ(files::read_text(dir / "history.csv"), "step,time\n1,0.5\n");
  EXPECT_EQ(resumed.frames(), 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stentsim::solver
