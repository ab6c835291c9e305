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

// Issue 11 review: a log axis inside one decade (wall times 2-6 s) had no numbers.
TEST(Plots, LogAxisTicksLabelRangesInsideOneDecade) {
  const auto in_range = [](const std::vector<Tick>& t, double lo, double hi) {
    for (const auto& k : t)
      if (k.value < lo * (1 - 1e-9) || k.value > hi * (1 + 1e-9) || k.label.empty()) return false;
    return true;
  };
  const auto t = log_axis_ticks(2.1, 5.5);
  ASSERT_GE(t.size(), 2u);
  EXPECT_TRUE(in_range(t, 2.1, 5.5));
  EXPECT_EQ(t.front().label, "3");
  EXPECT_EQ(t.back().label, "5");

  const auto tube = log_axis_ticks(1.2, 8.7);  // the tube study's wall times
  EXPECT_GE(tube.size(), 3u);
  EXPECT_TRUE(in_range(tube, 1.2, 8.7));

  const auto bend = log_axis_ticks(1.45, 3.3);  // "2", "3" only from integer mantissas
  ASSERT_EQ(bend.size(), 4u);
  EXPECT_EQ(bend[0].label, "1.5");
  EXPECT_EQ(bend[3].label, "3");

  const auto narrow = log_axis_ticks(2.1, 2.9);  // between two integer mantissas
  ASSERT_GE(narrow.size(), 2u);
  EXPECT_TRUE(in_range(narrow, 2.1, 2.9));
  EXPECT_EQ(narrow.front().label, "2.2");

  const auto two_decades = log_axis_ticks(0.04, 3.0);  // 1-2-5 steps: 0.05 0.1 0.2 0.5 1 2
  ASSERT_EQ(two_decades.size(), 6u);
  EXPECT_EQ(two_decades[0].label, "0.05");
  EXPECT_EQ(two_decades[5].label, "2");

  const auto many = log_axis_ticks(1e-9, 1e3);  // 13 decades: thinned to <= 8, whole decades
  EXPECT_GE(many.size(), 3u);
  EXPECT_LE(many.size(), 8u);
  EXPECT_EQ(many.front().label, "10#u-9#d");
  EXPECT_EQ(log_axis_ticks(1.5e-5, 9e-5).front().label, "2×10#u-5#d");

  EXPECT_THROW(log_axis_ticks(0.0, 1.0), InputError);
  EXPECT_THROW(log_axis_ticks(2.0, 1.0), InputError);
}

namespace {
// Number of glyphs cairo placed in an SVG (each drawn character is a <use>).
std::size_t svg_glyphs(const fs::path& svg) {
  pugi::xml_document doc;
  if (!doc.load_file(svg.c_str())) return 0;
  std::size_t n = 0;
  for (auto u : doc.select_nodes("//*[local-name()='use']")) (void)u, ++n;
  return n;
}
}  // namespace

TEST(Plots, LogAxisInsideOneDecadeIsNumberedInTheImage) {
  // The same figure with x in 2.1-5.5 and in 2100-5500: every x tick label
  // gains three zeros ("3" -> "3000"), so the SVG must hold 3 more glyphs per
  // label. Without numbers on the axis (PLplot's decade-only labels) the two
  // images would have the same number of glyphs.
  const auto dir = fresh_dir("logticks");
  Figure f;
  f.title = "error vs wall time";
  f.x = {"wall time", "s", true, {}, {}, {}};
  f.y = {"error", "mm", true, {}, {}, {}};
  f.series.push_back({"hex8", {2.1, 3.3, 5.5}, {1e-2, 3e-3, 1e-3}, Style::lines_and_markers, Marker::automatic});
  write_svg(f, dir / "small.svg");
  const auto n_labels = log_axis_ticks(std::pow(10.0, std::log10(2.1) - 0.05 * std::log10(5.5 / 2.1)),
                                       std::pow(10.0, std::log10(5.5) + 0.05 * std::log10(5.5 / 2.1)))
                            .size();
  ASSERT_GE(n_labels, 2u);
  for (auto& x : f.series[0].x) x *= 1000;
  write_svg(f, dir / "large.svg");
  const auto small = svg_glyphs(dir / "small.svg"), large = svg_glyphs(dir / "large.svg");
  ASSERT_GT(small, 0u) << "cairo writes text as <use> glyph references";
  EXPECT_EQ(large - small, 3 * n_labels);
  fs::remove_all(dir);
}

TEST(Plots, FitTitleWrapsShrinksOrCuts) {
  const auto width = [](const TitleLayout& t) {
    std::size_t n = 0;
    for (const auto& l : t.lines) n = std::max(n, l.size());
    return static_cast<double>(n) * t.scale;
  };
  const auto fits = fit_title("short title", 40);
  ASSERT_EQ(fits.lines.size(), 1u);
  EXPECT_EQ(fits.lines[0], "short title");
  EXPECT_EQ(fits.scale, 1.0);

  // The tube study's title: longer than the page, wrapped at a middle space.
  const std::string tube = "tube: error of inner_radius_at_pmax against h (hex8, tet10, tet10-curved)";
  const auto wrapped = fit_title(tube, 50);
  ASSERT_EQ(wrapped.lines.size(), 2u);
  EXPECT_EQ(wrapped.lines[0] + " " + wrapped.lines[1], tube) << "nothing lost";
  EXPECT_LE(width(wrapped), 50.0);

  const auto shrunk = fit_title(tube, 32);  // halves of ~37 glyphs shrink to fit
  EXPECT_LT(shrunk.scale, 1.0);
  EXPECT_GE(shrunk.scale, 0.7);
  EXPECT_LE(width(shrunk), 32.0 + 1e-9);

  const auto cut = fit_title(std::string(200, 'x'), 30);  // no space to break at
  EXPECT_LE(width(cut), 30.0 + 1e-9);
  EXPECT_NE(cut.lines[0].find("..."), std::string::npos);
}
