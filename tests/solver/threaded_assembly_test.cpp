// Threaded element loops (solver/assembly/threads.hpp, colouring.hpp): a solid
// body's coloured assembly gives the serial matrix and residual to round-off,
// and the same bits on any thread count; entries outside the pattern join it in
// the coloured order; a failing element is reported alike on any count. The
// ordered loop (parallel_ordered) consumes its chunks in order from their own
// buffers and rethrows the first failure in that order.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <thread>
#include <string>

#include "solver/assembly/colouring.hpp"
#include "solver/assembly/global_system.hpp"
#include "solver/assembly/threads.hpp"
#include "solver/io/generated_meshes.hpp"
#include "solver/materials/presets.hpp"
#include "solver/terms/element_failure.hpp"
#include "solver/terms/solid_body.hpp"

using namespace stentsim;
using namespace stentsim::solver;

namespace {

// A tet10 block of the viscous, fibred media material; `viscous` on so that the
// trial history is written from several threads too.
SolidBody make_block(int n) {
  SolidBodySpec spec;
  spec.name = "block";
  spec.mesh = tet4_to_tet10(hex8_to_tet4(box_hex8(n, n, n + 1, 1.0, 1.0, 1.2)));
  spec.materials = {material_preset("media")};
  for (auto& f : spec.materials[0].fibers) f.global_direction = Vec3(0.3, 1.0, 0.2).normalized();
  spec.cell_material.assign(spec.mesh.num_cells(), 0);
  return SolidBody(std::move(spec), 0);
}

struct Assembled {
  Eigen::VectorXd residual, rhs;
  CsrMatrix matrix;
};

// Two tangent assemblies into one system (the first lays the pattern serially), the
// second on `threads` threads; `empty_pattern`: the second starts from no pattern at
// all, so every entry waits in a lane and joins at merge().
Assembled assemble(SolidBody& body, const Constraints& c, const Eigen::VectorXd& u, int threads, bool empty_pattern = false) {
  GlobalSystem sys(c);
  const Eigen::VectorXd prescribed = c.increments(Eigen::VectorXd::Zero(u.size()), 1.0);
  const SystemState state{u, 1.0, 0.1};
  const AssemblyThreads scope(threads);
  if (empty_pattern) {
    sys.begin(prescribed, true);
    if (auto* lanes = sys.concurrent()) lanes->laid(&body);
    sys.finish();
  } else {
    sys.begin(prescribed, true);
    body.assemble(state, sys);
    sys.finish();
  }
  sys.begin(prescribed, true);
  body.assemble(state, sys);
  sys.finish();
  return {sys.residual(), sys.rhs(), sys.matrix()};
}

// A smooth deformation with a little noise: no element inverts.
Eigen::VectorXd deformation(const SolidBody& body) {
  Eigen::VectorXd u = Eigen::VectorXd::Random(body.num_dofs()) * 1e-4;
  for (std::size_t i = 0; i < body.num_nodes(); ++i) {
    const Vec3& x = body.mesh().points[i];
    u.segment<3>(body.dof(i, 0)) += 0.05 * Vec3(x.x() * x.y(), x.y() * x.z(), x.z() * x.x());
  }
  return u;
}

Constraints bottom_fixed(const SolidBody& body) {
  Constraints c(body.num_dofs());
  for (std::size_t i = 0; i < body.num_nodes(); ++i)
    if (body.mesh().points[i].z() < 1e-12) {
      c.fix(body.dof(i, 0), [](double) { return 0.0; });
      c.fix(body.dof(i, 1), [](double) { return 0.0; });
      c.fix(body.dof(i, 2), [](double t) { return 0.01 * t; });  // prescribed: fixed columns go to the rhs
    }
  return c;
}

void expect_bitwise_equal(const Assembled& a, const Assembled& b) {
  ASSERT_EQ(a.matrix.row_ptr, b.matrix.row_ptr);
  ASSERT_EQ(a.matrix.cols, b.matrix.cols);
  EXPECT_TRUE(a.matrix.values == b.matrix.values);
  EXPECT_TRUE(a.residual == b.residual);
  EXPECT_TRUE(a.rhs == b.rhs);
}

void expect_round_off(const Assembled& serial, const Assembled& threaded) {
  ASSERT_EQ(serial.matrix.row_ptr, threaded.matrix.row_ptr);
  ASSERT_EQ(serial.matrix.cols, threaded.matrix.cols);
  double kmax = 0.0, kdiff = 0.0;
  for (std::size_t k = 0; k < serial.matrix.values.size(); ++k) {
    kmax = std::max(kmax, std::abs(serial.matrix.values[k]));
    kdiff = std::max(kdiff, std::abs(serial.matrix.values[k] - threaded.matrix.values[k]));
  }
  EXPECT_GT(kmax, 0.0);
  EXPECT_LT(kdiff, 1e-13 * kmax);
  EXPECT_LT((serial.residual - threaded.residual).lpNorm<Eigen::Infinity>(), 1e-13 * serial.residual.lpNorm<Eigen::Infinity>());
  EXPECT_LT((serial.rhs - threaded.rhs).lpNorm<Eigen::Infinity>(), 1e-13 * serial.rhs.lpNorm<Eigen::Infinity>());
}

}  // namespace

TEST(ColourByNodes, NoTwoItemsOfAColourShareANodeAndEachItemIsColouredOnce) {
  const SolidBody body = make_block(5);
  const MeshData& m = body.mesh();
  std::vector<std::vector<std::int64_t>> cells(m.num_cells());
  for (std::size_t c = 0; c < m.num_cells(); ++c) cells[c] = m.cell(c);
  const auto colours = colour_by_nodes(cells.size(), m.points.size(), [&](std::size_t i) { return std::span<const std::int64_t>(cells[i]); });
  std::vector<int> seen(cells.size(), 0);
  for (const auto& colour : colours) {
    ASSERT_FALSE(colour.empty());
    std::set<std::int64_t> nodes;
    for (std::size_t k = 0; k < colour.size(); ++k) {
      if (k > 0) {
        EXPECT_LT(colour[k - 1], colour[k]) << "in increasing order";
      }
      ++seen[colour[k]];
      for (const auto a : cells[colour[k]]) EXPECT_TRUE(nodes.insert(a).second) << "node " << a << " twice in a colour";
    }
  }
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "item " << i;
  std::printf("%zu tet10 in %zu colours\n", cells.size(), colours.size());
  // More colours than 64 widen the node masks: a star of 100 items around one node.
  const std::vector<std::int64_t> hub{0};
  const auto star = colour_by_nodes(100, 1, [&](std::size_t) { return std::span<const std::int64_t>(hub); });
  EXPECT_EQ(star.size(), 100u);
  // A chain a-b-c where only neighbours share a node: two colours, {a, c} and {b}.
  const std::vector<std::vector<std::int64_t>> chain{{0, 1}, {1, 2}, {2, 3}};
  const auto two = colour_by_nodes(3, 4, [&](std::size_t i) { return std::span<const std::int64_t>(chain[i]); });
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0], (std::vector<std::uint32_t>{0, 2}));
  EXPECT_EQ(two[1], (std::vector<std::uint32_t>{1}));
}

TEST(ThreadedAssembly, GivesTheSerialSystemToRoundOffAndTheSameBitsOnAnyThreadCount) {
  SolidBody body = make_block(6);
  const Constraints c = bottom_fixed(body);
  const Eigen::VectorXd u = deformation(body);
  const Assembled serial = assemble(body, c, u, 1);
  const Assembled two = assemble(body, c, u, 2);
  const Assembled three = assemble(body, c, u, 3);
  expect_round_off(serial, two);
  expect_bitwise_equal(two, three);
  // The coloured order differs from the serial one, so some entry must differ in its last
  // bits: otherwise the threaded path did not run.
  EXPECT_FALSE(serial.matrix.values == two.matrix.values) << "the threaded loop seems not to have run";
}

TEST(ThreadedAssembly, EntriesOutsideThePatternJoinItInTheColouredOrder) {
  SolidBody body = make_block(4);
  const Constraints c = bottom_fixed(body);
  const Eigen::VectorXd u = deformation(body);
  const Assembled serial = assemble(body, c, u, 1);
  const Assembled two = assemble(body, c, u, 2, true);
  const Assembled three = assemble(body, c, u, 3, true);
  expect_round_off(serial, two);
  expect_bitwise_equal(two, three);
  // And the same bits as the threaded assembly into a laid pattern.
  expect_bitwise_equal(two, assemble(body, c, u, 2));
}

TEST(ThreadedAssembly, AFailingElementIsReportedAlikeOnAnyThreadCount) {
  SolidBody body = make_block(4);
  const Constraints c(body.num_dofs());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(body.num_dofs());
  // Push one interior node through its neighbours: the elements around it invert.
  std::size_t inner = 0;
  for (std::size_t i = 0; i < body.num_nodes(); ++i)
    if ((body.mesh().points[i] - Vec3(0.5, 0.5, 0.6)).norm() < (body.mesh().points[inner] - Vec3(0.5, 0.5, 0.6)).norm()) inner = i;
  u(body.dof(inner, 2)) = 2.0;
  std::vector<std::string> messages;
  for (const int threads : {2, 3}) {
    GlobalSystem sys(c);
    const AssemblyThreads scope(threads);
    const SystemState state{u, 1.0, 0.1};
    const Eigen::VectorXd none = Eigen::VectorXd::Zero(u.size());
    sys.begin(none, true);
    if (auto* lanes = sys.concurrent()) lanes->laid(&body);
    sys.finish();
    sys.begin(none, true);
    try {
      body.assemble(state, sys);
      ADD_FAILURE() << "no element failed on " << threads << " threads";
    } catch (const ElementFailure& e) {
      messages.push_back(e.what());
    }
  }
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_EQ(messages[0], messages[1]);
  EXPECT_NE(messages[0].find("body 'block', element "), std::string::npos) << messages[0];
}

TEST(ParallelOrdered, ConsumesEveryChunkInOrderFromASlotNoOtherChunkHolds) {
  // Computes sleep a little, every third chunk longer, so later chunks finish their compute
  // early: the consumer must still see chunk order, each chunk's own buffer, every item once.
  for (const int threads : {1, 2, 3}) {
    const AssemblyThreads scope(threads);
    const int slots = ordered_slots();
    EXPECT_EQ(slots, threads == 1 ? 1 : 2 * threads);
    std::vector<std::vector<std::size_t>> buffer(static_cast<std::size_t>(slots));
    std::vector<std::size_t> consumed;
    std::atomic<int> busy{0}, most{0}, started{0};
    parallel_ordered(
        103, 5,
        [&](std::size_t begin, std::size_t end, int slot) {
          ++started;
          const int now = ++busy;
          for (int m = most.load(); now > m && !most.compare_exchange_weak(m, now);) {
          }
          // The first chunk waits (a few seconds at most) for a second compute to start, so the
          // overlap below does not depend on how fast a worker joins.
          if (threads > 1 && begin == 0)
            for (int k = 0; k < 5000 && started.load() < 2; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
          auto& b = buffer.at(static_cast<std::size_t>(slot));
          b.clear();
          for (std::size_t i = begin; i < end; ++i) b.push_back(i);
          std::this_thread::sleep_for(std::chrono::microseconds(begin % 3 == 0 ? 800 : 100));
          --busy;
        },
        [&](std::size_t begin, std::size_t end, int slot) {
          const auto& b = buffer.at(static_cast<std::size_t>(slot));
          ASSERT_EQ(b.size(), end - begin);
          for (std::size_t i = 0; i < b.size(); ++i) EXPECT_EQ(b[i], begin + i) << "slot " << slot << " was overwritten";
          consumed.insert(consumed.end(), b.begin(), b.end());
        });
    ASSERT_EQ(consumed.size(), 103u);
    for (std::size_t i = 0; i < consumed.size(); ++i) ASSERT_EQ(consumed[i], i) << threads << " threads";
    if (threads > 1) EXPECT_GT(most.load(), 1) << "the computes never overlapped";
  }
}

TEST(ParallelOrdered, RethrowsTheFirstFailureInChunkOrderAfterConsumingTheChunksBeforeIt) {
  for (const int threads : {1, 3}) {
    const AssemblyThreads scope(threads);
    std::vector<std::size_t> consumed;
    try {
      parallel_ordered(
          40, 2,
          [&](std::size_t begin, std::size_t, int) {
            // Chunk 9 fails at once, chunk 7 only after a while: in chunk order 7 comes first.
            if (begin == 14) {
              std::this_thread::sleep_for(std::chrono::milliseconds(20));
              throw ElementFailure("chunk 7");
            }
            if (begin == 18) throw ElementFailure("chunk 9");
          },
          [&](std::size_t begin, std::size_t, int) { consumed.push_back(begin / 2); });
      ADD_FAILURE() << "nothing thrown";
    } catch (const ElementFailure& e) {
      EXPECT_STREQ(e.what(), "chunk 7") << threads << " threads";
    }
    EXPECT_EQ(consumed, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6})) << threads << " threads";
  }
}

TEST(AssemblyThreads, ScopeSetsTheCountAndTheEnvironmentGivesTheDefault) {
  EXPECT_EQ(assembly_threads(), 1) << "1 outside a solve";
  {
    const AssemblyThreads scope(2);
    EXPECT_EQ(assembly_threads(), 2);
  }
  EXPECT_EQ(assembly_threads(), 1);
  ::setenv("STENTSIM_THREADS", "3", 1);
  EXPECT_EQ(default_assembly_threads(1), 3);
  ::setenv("STENTSIM_THREADS", "two", 1);
  try {
    default_assembly_threads(1);
    ADD_FAILURE() << "a malformed STENTSIM_THREADS was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("STENTSIM_THREADS = 'two'"), std::string::npos) << e.what();
  }
  ::unsetenv("STENTSIM_THREADS");
  EXPECT_GE(default_assembly_threads(1), 1);
  EXPECT_GE(default_assembly_threads(64), 1) << "at least one per rank";
}
