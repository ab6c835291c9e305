// The PLplot adapter writes real PNG and SVG files, headless, atomically, and
// rejects figures it cannot draw before PLplot sees them.
#include <gtest/gtest.h>
#include <pugixml.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <thread>

#include <unistd.h>

#include "common/error.hpp"
#include "workflows/plots/figure.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using namespace stentsim::plots;

namespace {

fs::path fresh_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / ("stentsim-test-plots-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A figure with everything the adapter offers: lines, markers, both, a gap,
// log y axis, units, legend and a highlighted (Pareto-like) front.
Figure full_figure() {
  Figure f;
  f.title = "Stent diameter vs. pressure";
  f.x = {"balloon pressure", "MPa", false, {}, {}, {}};
  f.y = {"peak stress", "MPa", true, {}, {}, {}};
  Series a{"intima", {}, {}, Style::lines, Marker::automatic};
  Series b{"media", {}, {}, Style::markers, Marker::square};
  Series c{"adventitia", {}, {}, Style::lines_and_markers, Marker::automatic};
  for (int i = 0; i <= 20; ++i) {
    const double p = 0.1 * i + 0.1;
    a.x.push_back(p);
    a.y.push_back(std::exp(2 * p));
    b.x.push_back(p);
    b.y.push_back(0.5 * std::exp(1.5 * p));
    c.x.push_back(p);
    c.y.push_back(i == 10 ? std::numeric_limits<double>::quiet_NaN() : 0.2 * std::exp(p));
  }
  f.series = {a, b, c};
  f.highlights.push_back({"Pareto front", {0.5, 1.0, 1.5}, {0.5, 0.8, 1.9}, Marker::diamond, true, false});
  return f;
}

}  // namespace

TEST(Plots, WritesValidPngAndSvgHeadless) {
  ::unsetenv("DISPLAY");  // the cairo devices must not need an X server
  const auto dir = fresh_dir("valid");
  const Figure f = full_figure();
  write_png(f, dir / "fig.png");
  write_svg(f, dir / "fig.svg");

  const std::string png = read_bytes(dir / "fig.png");
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(png.size(), 10u * 1024) << "a 900x600 figure with text and curves is more than 10 KB";

  pugi::xml_document doc;
  const auto parsed = doc.load_file((dir / "fig.svg").c_str());
  ASSERT_TRUE(parsed) << parsed.description();
  EXPECT_STREQ(doc.document_element().name(), "svg");
  std::size_t paths = 0;
  for (auto n : doc.select_nodes("//*[local-name()='path']")) (void)n, ++paths;
  EXPECT_GT(paths, 20u) << "axes, curves, markers and glyphs are paths";
  EXPECT_GT(fs::file_size(dir / "fig.svg"), 10u * 1024);

  // No temporary files left beside the outputs.
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) (void)e, ++files;
  EXPECT_EQ(files, 2u);
  fs::remove_all(dir);
}

TEST(Plots, DataChangesTheImage) {
  // Guards against an adapter that ignores its data: different series, different pixels.
  const auto dir = fresh_dir("data");
  Figure f = full_figure();
  write_png(f, dir / "a.png");
  f.series[0].y[5] *= 50;
  write_png(f, dir / "b.png");
  EXPECT_NE(read_bytes(dir / "a.png"), read_bytes(dir / "b.png"));
  fs::remove_all(dir);
}

TEST(Plots, CategoricalAxisAndWriteFigureByExtension) {
  const auto dir = fresh_dir("cat");
  Figure f;
  f.title = "Narrowest lumen diameter";
  f.x.label = "case";
  f.x.tick_labels = {"mild-30", "moderate-50", "severe-70"};
  f.y = {"diameter", "mm", false, 0.0, {}, {}};
  f.series.push_back({"value", {0, 1, 2}, {2.1, 1.5, std::nan("")}, Style::markers, Marker::circle});
  f.highlights.push_back({"failed (expected)", {2}, {0.0}, Marker::cross, false, true});
  write_figure(f, dir / "cat.png");
  write_figure(f, dir / "cat.svg");
  EXPECT_GT(fs::file_size(dir / "cat.png"), 5u * 1024);
  EXPECT_THROW(write_figure(f, dir / "cat.jpg"), InputError);
  fs::remove_all(dir);
}

TEST(Plots, RejectsFiguresItCannotDraw) {
  const auto dir = fresh_dir("bad");
  Figure empty;
  EXPECT_THROW(write_png(empty, dir / "x.png"), InputError);

  Figure mismatch = full_figure();
  mismatch.series[0].y.pop_back();
  EXPECT_THROW(write_png(mismatch, dir / "x.png"), InputError);

  Figure neg = full_figure();
  neg.series[1].y[3] = -1.0;  // log y axis
  EXPECT_THROW(write_png(neg, dir / "x.png"), InputError);

  EXPECT_FALSE(fs::exists(dir / "x.png"));
  fs::remove_all(dir);
}

TEST(Plots, ConcurrentCallersAreSerialized) {
  // PLplot is global state: two threads drawing at once must both get a whole file.
  const auto dir = fresh_dir("threads");
  const Figure f = full_figure();
  std::thread t1([&] { for (int i = 0; i < 3; ++i) write_png(f, dir / "t1.png"); });
  std::thread t2([&] { for (int i = 0; i < 3; ++i) write_svg(f, dir / "t2.svg"); });
  t1.join();
  t2.join();
  EXPECT_EQ(read_bytes(dir / "t1.png").substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  pugi::xml_document doc;
  EXPECT_TRUE(doc.load_file((dir / "t2.svg").c_str()));
  fs::remove_all(dir);
}
