#pragma once
// Child processes for every runner that starts them: the stage runner (a
// stage run in a forked child), the cohort pool (a `stentsim run` per case),
// the Slurm follower (sbatch, squeue, sacct), the error study (stentsim runs,
// under mpirun for ranks > 1), the stability suite (cases under a wall-clock
// limit) and the readers that hand a user's file to a library that may crash
// on it.
// One implementation of the parts they share:
//  - fork into a process group of its own (pgid = pid), so that a runner can
//    stop a child and everything it started (mpirun's ranks, gmsh) with one
//    kill(-pgid); the child dies with its parent (PR_SET_PDEATHSIG), so no
//    orphan keeps working on (or locking) a folder;
//  - the stop signals blocked across the fork, then the parent's handlers
//    reset and SIGINT, SIGTERM, SIGCHLD unblocked in the child
//    (common/stop_signals.hpp); stdin from /dev/null;
//  - stdout and stderr captured in a log file (or returned: run_captured),
//    environment set before exec;
//  - exit status, CPU time and peak memory from wait4()'s rusage, which
//    covers the child and its reaped descendants (ru_maxrss is the largest
//    single process, not a sum: MPI runs report their ranks themselves);
//  - a wall-clock limit: SIGTERM to the group and every descendant (a stage
//    may sit in a group of its own), SIGKILL after a grace period.
#include <sys/resource.h>
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace stentsim::process {

struct ChildSetup {
  std::filesystem::path cwd;  ///< working folder of the child (empty: the parent's)
  std::filesystem::path log;  ///< stdout and stderr go here (empty: inherited)
  bool append_log = false;    ///< append to the log instead of truncating it
  std::vector<std::pair<std::string, std::string>> env;  ///< variables set in the child
};

/// Forks a child set up as above that runs `body` and exits with its return
/// value (1 after an exception, whose text goes to stderr). The child never
/// returns into the caller. Throws ComputeError when fork fails.
pid_t spawn(const std::function<int()>& body, const ChildSetup& setup = {});

/// This program's executable (/proc/self/exe), to start stentsim itself as a
/// child (an MPI run, a study's runs). Throws ComputeError when unknown.
std::filesystem::path self_executable();

/// Forks and executes argv (execvpe: argv[0] is looked up in this process's
/// PATH, not one given in setup.env, unless it holds a '/'). Everything the child needs is built before the fork, so the
/// child allocates nothing: safe from a multithreaded parent. Exit 127 when
/// it cannot execute (the reason is in the log), 126 when the working folder
/// cannot be entered.
pid_t spawn_exec(const std::vector<std::string>& argv, const ChildSetup& setup = {});

/// The environment variables that keep every library in a stentsim child to
/// one thread, for runners whose children already fill the cores (a cohort's
/// cases, a study's runs, counted by ranks). OMP_NUM_THREADS covers OpenMP
/// (Kokkos/Trilinos, libgomp), OPENBLAS_NUM_THREADS OpenBLAS and
/// STENTSIM_THREADS our own threaded assembly; VTK's SMP tools ignore them:
/// Debian's VTK 9.1 runs vtkDiscreteFlyingEdges3D and
/// vtkWindowedSincPolyDataFilter (label-image segmentation) on its TBB backend,
/// which VTK_SMP_BACKEND_IN_USE=Sequential turns into one thread
/// (VTK_SMP_MAX_THREADS=1 caps the others). gmsh is set to one thread in code
/// (meshing/patient_mesh_gmsh.cpp).
std::vector<std::pair<std::string, std::string>> single_thread_environment();

/// How a child ended.
struct ChildEnd {
  int exit_code = -1;         ///< exit status when the child exited, else -1
  int signal = 0;             ///< the signal that ended it (0: it exited)
  bool timed_out = false;     ///< still running at its limit: ended by us
  double wall_s = 0;          ///< from start to reaped
  double cpu_s = 0;           ///< user + system time of the child and its reaped descendants
  double peak_memory_mb = 0;  ///< largest resident set among them (wait4's ru_maxrss)
  bool ok() const { return !timed_out && signal == 0 && exit_code == 0; }
  /// "exit status 3", "killed by signal 9 (Killed)", "timed out after 61 s".
  std::string describe() const;
};

struct CapturedRun {
  ChildEnd end;
  std::string output;  ///< stdout and stderr, interleaved as written
};

/// The ChildEnd of a reaped child from its wait status and rusage.
ChildEnd child_end(int wait_status, const rusage& usage, double wall_s);

struct Reaped {
  pid_t pid = -1;
  int wait_status = 0;
  rusage usage{};
};

/// A child that has ended, reaped without blocking (wait4(-1, WNOHANG)); nullopt
/// while none has. A loop sleeps in StopSignals::wait() in between (Mode::
/// wait_for_signal), which a child's end or a stop signal ends. Throws
/// ComputeError on an error (ECHILD included: call it only with children running).
std::optional<Reaped> poll_any();

/// Waits for `pid` (started at `start`). After `limit_s` seconds of wall clock
/// the child's group and descendants are ended by stop_and_reap (SIGTERM,
/// SIGKILL `grace_s` later, descendants left behind by a child that ended on
/// SIGTERM included); the run then counts as timed out whatever its status. A
/// timed-out child stuck after SIGKILL reads as killed by SIGKILL, unreaped.
ChildEnd wait_with_limit(pid_t pid, std::chrono::steady_clock::time_point start, double limit_s, double grace_s = 2.0);

/// Runs `read` on `file` in a child first (its output discarded, its exceptions
/// ignored: the caller's own read reports those) and throws InputError naming the
/// file when the child dies by a signal (or exits non-zero: a crash handler's exit),
/// is still reading after `limit_s` or needs more than `memory_bytes` beyond what
/// the process has mapped (the child's address space is capped). For
/// libraries that crash inside their own parsers on damaged input (VTK's XML
/// readers), where no check before them can see what they will trip on.
void probe_read_in_child(const std::filesystem::path& file, const std::string& what, const std::function<void()>& read,
                         double limit_s = 20, double memory_bytes = 2.0 * 1024 * 1024 * 1024);

/// Runs argv as spawn_exec does (setup.log is ignored), waits for it and
/// returns its stdout and stderr together: for short commands whose answer
/// the caller parses (sbatch, squeue). A stop signal does not cut the wait
/// short (the command is in a group of its own, out of reach of a Ctrl-C).
/// A command still running after `limit_s` (0: no limit) is ended as
/// stop_and_reap ends a child (SIGTERM, SIGKILL `grace_s` later) and returns
/// timed out, with what it wrote until then.
CapturedRun run_captured(const std::vector<std::string>& argv, const ChildSetup& setup = {}, double limit_s = 0.0,
                         double grace_s = 2.0);

/// Ends children when a runner cannot go on (an error, a study's stop, a time
/// limit): SIGTERM to each child's process group and every descendant (in
/// whatever group), SIGKILL to those still running `grace_s` later (a stage stuck
/// in a library that ignores SIGTERM); returns once every child is reaped and
/// every descendant has ended or been sent SIGKILL, with each reaped child's
/// status. Children that outlast their SIGKILL by `stuck_s` (uninterruptible
/// sleep on a hung file system) are named in a warning with the descendants
/// still running, and left: they have no entry.
std::vector<Reaped> stop_and_reap(const std::vector<pid_t>& pids, double grace_s = 30.0, double stuck_s = 10.0);

/// Sends `sig` to the child's process group and to every live descendant.
void signal_family(pid_t pid, int sig);

/// Every live descendant of `root` (from the ppid fields of /proc/*/stat).
std::vector<pid_t> descendants(pid_t root);

}  // namespace stentsim::process
