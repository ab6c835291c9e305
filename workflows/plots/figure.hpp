#pragma once
// A small plotting adapter: 2-D figures (several series, linear or log axes,
// labels with units, legend, highlighted points) written as PNG or SVG.
// The drawing library (PLplot, cairo devices) stays in figure.cpp; this header
// only describes what to draw. Rendering is serialized inside the adapter
// because PLplot keeps global state and is not thread-safe.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace stentsim::plots {

/// How a series is drawn.
enum class Style { lines, markers, lines_and_markers };

/// Marker shapes (cycled per series when left at `automatic`).
enum class Marker { automatic, circle, square, triangle, diamond, cross };

/// One data series. Non-finite (NaN/inf) y values are gaps: lines break there
/// and no marker is drawn, so a failed case simply has no point.
struct Series {
  std::string label;  ///< legend text; empty = not in the legend
  std::vector<double> x;
  std::vector<double> y;
  Style style = Style::lines;
  Marker marker = Marker::automatic;
  /// Palette slot (0-9); -1 = the series' position. Series sharing a slot
  /// share colour and automatic marker (e.g. data and its fitted line).
  int colour = -1;
  bool dashed = false;  ///< dashed line (a fit or a guide, not data)
};

/// Points drawn on top of every series, larger and outlined (e.g. a Pareto
/// front, or the failed cases of a cohort). `connect` joins them in x order.
struct Highlight {
  std::string label;  ///< legend text; empty = not in the legend
  std::vector<double> x;
  std::vector<double> y;
  Marker marker = Marker::circle;
  bool connect = false;
  bool warning_colour = false;  ///< red instead of the highlight gold
  /// Drawn before the series (a marked set, e.g. a Pareto front, that must
  /// not hide the lines running through it); default: on top.
  bool beneath_series = false;
};

struct Axis {
  std::string label;  ///< e.g. "lumen diameter"
  std::string unit;   ///< e.g. "mm"; printed as "label [unit]"; empty = dimensionless
  bool log = false;   ///< base-10 log scale; every plotted value must then be > 0
  std::optional<double> min, max;  ///< fixed range; otherwise data range + 5 % margin
  /// Categorical ticks: tick_labels[i] is written at x = i (integer ticks only).
  std::vector<std::string> tick_labels;
};

struct Figure {
  std::string title;
  Axis x, y;
  std::vector<Series> series;
  std::vector<Highlight> highlights;
  int width_px = 900;
  int height_px = 600;
  bool legend = true;
};

/// A labelled tick: where (in data units) and the text written there.
struct Tick {
  double value;
  std::string label;
};

/// Labelled ticks for a base-10 log axis shown over [lo, hi] (data units,
/// 0 < lo < hi). PLplot's own log axes number whole decades only, so an axis
/// inside one decade (wall times of 2-6 s) would carry no numbers at all.
/// This picks the sparsest of 1x10^k, {1,2,5}x10^k, {1..9}x10^k that gives at
/// least three ticks in range (thinning whole decades when there are too
/// many); when even {1..9}x10^k gives fewer than three, evenly spaced 1-2-5
/// steps inside the range if they give more. Labels are plain decimals ("0.02", "5000")
/// within 1e-3..1e4, otherwise mantissa x 10^k in PLplot's superscript syntax.
std::vector<Tick> log_axis_ticks(double lo, double hi);

/// How a title is laid out above the plot.
struct TitleLayout {
  std::vector<std::string> lines;  ///< one or two lines
  double scale = 1.0;              ///< character height relative to the default
};

/// Fits `title` into `width_chars` default-size character widths: unchanged
/// when it fits; else broken into two lines at the space nearest the middle;
/// then shrunk (not below 0.7); and as a last resort cut with "...".
/// Every returned line times `scale` is at most `width_chars` wide.
TitleLayout fit_title(const std::string& title, double width_chars);

/// "label [unit]" (or just the label when the unit is empty).
std::string axis_title(const Axis& axis);

/// Writes the figure as PNG (device pngcairo), atomically (temporary name in
/// the same folder, then rename). Throws InputError for a figure that cannot be
/// drawn (no data, mismatched x/y sizes, non-positive values on a log axis) and
/// ComputeError when the device fails to produce the file.
void write_png(const Figure& figure, const std::filesystem::path& target);

/// Same as write_png with the svgcairo device.
void write_svg(const Figure& figure, const std::filesystem::path& target);

/// Writes PNG or SVG by the target's extension (".png" / ".svg").
void write_figure(const Figure& figure, const std::filesystem::path& target);

}  // namespace stentsim::plots
