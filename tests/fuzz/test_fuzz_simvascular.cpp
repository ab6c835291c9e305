// Mutation fuzzing of the SimVascular readers: mutants of a path (.pth) and of a
// contour group (.ctgr), read and lofted as the segmentation stage does, either
// give a tube or an InputError naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "segmentation_io/simvascular_io.hpp"
#include "tests/fuzz/mutation.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(STENTSIM_TEST_SOURCE_DIR) / "tests/segmentation_io/data";

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// As the segmentation stage lofts them: loft errors name the contour file.
void loft(const fs::path& pth, const fs::path& ctgr) {
  const TriSurface s = loft_contours(read_simvascular_path(pth), read_simvascular_contours(ctgr), LoftOptions{}, ctgr.string());
  for (const auto& t : s.triangles)
    for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < s.points.size());
}

}  // namespace

TEST(SimVascularFuzz, MutantsReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_sv_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const int n = fuzz::iterations();
  std::mt19937 gen(20261204);
  const fs::path good_pth = kData / "straight_lad.pth", good_ctgr = kData / "straight_lad_lumen.ctgr";
  const std::string pth = slurp(good_pth), ctgr = slurp(good_ctgr);
  fuzz::judge("pth", n, [&](int) { fuzz::write_file(dir / "t.pth", fuzz::mutate(pth, gen)); return dir / "t.pth"; },
              [&](const fs::path& f) { loft(f, good_ctgr); });
  fuzz::judge("ctgr", n, [&](int) { fuzz::write_file(dir / "t.ctgr", fuzz::mutate(ctgr, gen)); return dir / "t.ctgr"; },
              [&](const fs::path& f) { loft(good_pth, f); });
  fs::remove_all(dir);
}
