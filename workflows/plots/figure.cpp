// PLplot adapter for figure.hpp. The only file that includes PLplot.
//
// PLplot keeps its state in global streams and is not thread-safe, so every
// figure is drawn under one process-wide mutex, in a fresh stream
// (plmkstrm ... plend1). The cairo devices (pngcairo, svgcairo) render
// without an X display. Figures are validated before PLplot sees them:
// PLplot's fatal errors call exit(), so bad input must never reach it.
#include "workflows/plots/figure.hpp"

#include <plplot.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <string_view>
#include <system_error>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::plots {
namespace {

std::mutex& plplot_mutex() {
  static std::mutex m;
  return m;
}

// Colour map 0: index 0 is the page background. Series colours are the
// colour-blind-friendly "tab10" palette.
enum Colour : int { background = 0, ink = 1, grid = 2, first_series = 3, n_series = 10,
                    highlight = 13, warning = 14, n_colours = 15 };
constexpr std::array<std::array<int, 3>, n_colours> palette{{
    {255, 255, 255}, {0, 0, 0}, {200, 200, 200},
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189},
    {140, 86, 75}, {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207},
    {255, 215, 0}, {200, 0, 0}}};

// Marker glyphs as UTF-8 (the cairo devices draw them from the system fonts).
const char* glyph(Marker m) {
  switch (m) {
    case Marker::circle: return "●";
    case Marker::square: return "■";
    case Marker::triangle: return "▲";
    case Marker::diamond: return "◆";
    case Marker::cross: return "✖";
    case Marker::automatic: break;
  }
  return "●";
}

Marker resolve(Marker m, std::size_t index) {
  if (m != Marker::automatic) return m;
  constexpr std::array<Marker, 4> cycle{Marker::circle, Marker::square, Marker::triangle,
                                        Marker::diamond};
  return cycle[index % cycle.size()];
}

// PLplot reads '#' as its escape character in text.
std::string plain(const std::string& s) {
  std::string out;
  for (char c : s) {
    out += c;
    if (c == '#') out += '#';
  }
  return out;
}

double to_axis(double v, bool log) { return log ? std::log10(v) : v; }

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
};

void check_points(const std::string& what, const std::vector<double>& x,
                  const std::vector<double>& y, const Figure& f) {
  if (x.size() != y.size())
    throw InputError("plot '" + f.title + "': " + what + " has " + std::to_string(x.size()) +
                     " x values but " + std::to_string(y.size()) + " y values");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;  // a gap
    if (f.x.log && x[i] <= 0)
      throw InputError("plot '" + f.title + "': " + what + " has x = " + std::to_string(x[i]) +
                       " on a log axis (values must be > 0)");
    if (f.y.log && y[i] <= 0)
      throw InputError("plot '" + f.title + "': " + what + " has y = " + std::to_string(y[i]) +
                       " on a log axis (values must be > 0)");
  }
}

// Axis limits in plotting coordinates (log10 for log axes).
std::pair<double, double> limits(const Axis& axis, const Range& data) {
  double lo, hi;
  if (axis.min && axis.max) {
    lo = to_axis(*axis.min, axis.log);
    hi = to_axis(*axis.max, axis.log);
  } else {
    Range r = data;
    if (r.empty()) r = Range{0.0, 1.0};
    double span = r.hi - r.lo;
    double pad = span > 0 ? 0.05 * span : std::max(std::abs(r.lo) * 0.1, axis.log ? 0.5 : 1.0);
    lo = axis.min ? to_axis(*axis.min, axis.log) : r.lo - pad;
    hi = axis.max ? to_axis(*axis.max, axis.log) : r.hi + pad;
  }
  if (!(lo < hi))
    throw InputError("plot axis '" + axis.label + "': range min must be below max");
  return {lo, hi};
}

void validate(const Figure& f) {
  if (f.width_px < 100 || f.height_px < 100 || f.width_px > 10000 || f.height_px > 10000)
    throw InputError("plot '" + f.title + "': size " + std::to_string(f.width_px) + "x" +
                     std::to_string(f.height_px) + " px out of range (100..10000)");
  if (f.series.empty() && f.highlights.empty())
    throw InputError("plot '" + f.title + "': no series to draw");
  for (const auto& s : f.series) check_points("series '" + s.label + "'", s.x, s.y, f);
  for (const auto& h : f.highlights) check_points("highlight '" + h.label + "'", h.x, h.y, f);
  for (const Axis* a : {&f.x, &f.y})
    if ((a->min && a->log && *a->min <= 0) || (a->max && a->log && *a->max <= 0))
      throw InputError("plot axis '" + a->label + "': a log axis needs a range > 0");
  if (!f.y.tick_labels.empty())
    throw InputError("plot '" + f.title + "': categorical tick labels are for the x axis only");
  if (!f.x.tick_labels.empty() && f.x.log)
    throw InputError("plot '" + f.title + "': categorical x ticks need a linear x axis");
}

bool device_available(const char* name) {
  int n = 128;
  std::vector<const char*> menu(n), dev(n);
  const char** pm = menu.data();
  const char** pd = dev.data();
  plgDevs(&pm, &pd, &n);
  for (int i = 0; i < n; ++i)
    if (pd[i] && std::string_view(pd[i]) == name) return true;
  return false;
}

// Records PLplot's non-fatal error messages for the figure being drawn.
std::string& abort_message() {
  static std::string m;
  return m;
}
void on_plabort(const char* message) { abort_message() = message ? message : "unknown"; }

// Draws one polyline per run of finite points (NaN = gap).
void draw_lines(const std::vector<double>& x, const std::vector<double>& y, const Figure& f) {
  std::vector<PLFLT> px, py;
  auto flush = [&] {
    if (px.size() >= 2) plline(static_cast<PLINT>(px.size()), px.data(), py.data());
    px.clear();
    py.clear();
  };
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      flush();
      continue;
    }
    px.push_back(to_axis(x[i], f.x.log));
    py.push_back(to_axis(y[i], f.y.log));
  }
  flush();
}

void draw_markers(const std::vector<double>& x, const std::vector<double>& y, const Figure& f,
                  const char* symbol) {
  std::vector<PLFLT> px, py;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    px.push_back(to_axis(x[i], f.x.log));
    py.push_back(to_axis(y[i], f.y.log));
  }
  if (!px.empty()) plstring(static_cast<PLINT>(px.size()), px.data(), py.data(), symbol);
}

struct LegendEntry {
  std::string text;
  PLINT opt;
  PLINT colour;
  std::string symbol;
  PLFLT symbol_scale;
  PLINT line_style = 1;  // PLplot pllsty number
};

// PLplot's line style 3: long dashes, readable at 2 px width.
constexpr PLINT dashed_style = 3;

void draw_legend(const std::vector<LegendEntry>& entries) {
  const auto n = static_cast<PLINT>(entries.size());
  std::vector<PLINT> opts, text_colours, line_colours, line_styles, symbol_colours, symbol_numbers;
  std::vector<PLFLT> line_widths, symbol_scales;
  std::vector<const char*> texts, symbols;
  for (const auto& e : entries) {
    opts.push_back(e.opt);
    text_colours.push_back(ink);
    line_colours.push_back(e.colour);
    line_styles.push_back(e.line_style);
    line_widths.push_back(2.0);
    symbol_colours.push_back(e.colour);
    symbol_scales.push_back(e.symbol_scale);
    symbol_numbers.push_back(1);
    texts.push_back(e.text.c_str());
    symbols.push_back(e.symbol.c_str());
  }
  PLFLT w = 0, h = 0;
  plschr(0.0, 0.8);
  pllegend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
           PL_POSITION_RIGHT | PL_POSITION_OUTSIDE, 0.02, 0.0, 0.06, background,
           ink, 1, 0, 0, n, opts.data(), 1.0, 1.0, 2.0, 0.0, text_colours.data(), texts.data(),
           nullptr, nullptr, nullptr, nullptr, line_colours.data(), line_styles.data(),
           line_widths.data(), symbol_colours.data(), symbol_scales.data(), symbol_numbers.data(),
           symbols.data());
  plschr(0.0, 1.0);
}

// Title metrics in default character heights: a glyph is ~0.75 heights wide
// in the cairo font at worst (digits, capitals); lines 1.6 heights apart, the
// lowest 2 heights above the plot (where pllab puts a title).
constexpr double title_glyph_w = 0.75, title_gap = 1.6, title_disp = 2.0;

// Writes the title lines centred on the page (not the viewport, which is
// narrowed by the legend), so a long title uses the whole width.
void draw_title(const TitleLayout& t, double vx0, double vx1) {
  const double centre = (0.5 - vx0) / (vx1 - vx0);
  plschr(0.0, t.scale);
  const auto n = t.lines.size();
  for (std::size_t i = 0; i < n; ++i)
    plmtex("t", title_disp + title_gap * static_cast<double>(n - 1 - i), centre, 0.5, plain(t.lines[i]).c_str());
  plschr(0.0, 1.0);
}

void render(const Figure& f, const char* device, const std::filesystem::path& file) {
  Range xr, yr;
  auto collect = [&](const std::vector<double>& x, const std::vector<double>& y) {
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
      xr.add(to_axis(x[i], f.x.log));
      yr.add(to_axis(y[i], f.y.log));
    }
  };
  for (const auto& s : f.series) collect(s.x, s.y);
  for (const auto& h : f.highlights) collect(h.x, h.y);
  const bool categorical = !f.x.tick_labels.empty();
  if (categorical) {  // every category gets its slot even when its value is missing
    xr.add(0.0);
    xr.add(static_cast<double>(f.x.tick_labels.size() - 1));
  }
  auto [x0, x1] = limits(f.x, xr);
  if (categorical && !(f.x.min && f.x.max)) {
    x0 = -0.5;
    x1 = static_cast<double>(f.x.tick_labels.size()) - 0.5;
  }
  const auto [y0, y1] = limits(f.y, yr);

  std::vector<LegendEntry> legend;
  std::size_t longest_legend = 0;
  for (const auto& s : f.series)
    if (!s.label.empty()) longest_legend = std::max(longest_legend, s.label.size());
  for (const auto& h : f.highlights)
    if (!h.label.empty()) longest_legend = std::max(longest_legend, h.label.size());
  const bool with_legend = f.legend && longest_legend > 0;
  std::size_t longest_tick = 0;
  for (const auto& t : f.x.tick_labels) longest_tick = std::max(longest_tick, t.size());

  PLINT stream = 0;
  plmkstrm(&stream);
  plsdev(device);
  plsfnam(file.c_str());
  plspage(0.0, 0.0, f.width_px, f.height_px, 0, 0);
  std::array<PLINT, n_colours> r{}, g{}, b{};
  for (int i = 0; i < n_colours; ++i) {
    r[i] = palette[i][0];
    g[i] = palette[i][1];
    b[i] = palette[i][2];
  }
  plscmap0(r.data(), g.data(), b.data(), n_colours);
  plinit();
  pladv(0);

  // Viewport: room on the right for the legend and at the bottom for the
  // category names written perpendicular to the axis. Sizes from the
  // character height (mm) and the page size (mm); a glyph is ~0.6 heights wide.
  PLFLT def_ht = 0, char_ht = 0, px0 = 0, px1 = 0, py0 = 0, py1 = 0;
  plgchr(&def_ht, &char_ht);
  plgspa(&px0, &px1, &py0, &py1);
  const double page_w = px1 - px0, page_h = py1 - py0;
  // The legend's width: text at the legend's 0.8 character scale, glyphs
  // up to ~0.75 heights wide (digits, "=", capitals in the cairo font; 0.6
  // clipped "tet10-curved (p = 2.91)" to "...(p = 2.9"), plus the symbol/line
  // sample, the offsets and the box padding.
  const double legend_w = (0.75 * 0.8 * static_cast<double>(longest_legend) + 7.0) * char_ht;
  const double right = with_legend ? std::max(0.45, 0.97 - legend_w / page_w - 0.06) : 0.95;
  const double tick_disp = 0.7;  // gap between axis and category names, in character heights
  const double names_ht = 0.62 * static_cast<double>(longest_tick) + tick_disp;
  const double bottom = categorical ? std::min(0.6, (names_ht + 3.0) * char_ht / page_h) : 0.12;
  // Log-axis numbers (log_axis_ticks). The y title moves out past the
  // longest number ("5×10⁻⁴" is wider than PLplot's own labels), and the
  // plot's left edge with it.
  const std::vector<Tick> xticks =
      f.x.log && !categorical ? log_axis_ticks(std::pow(10.0, x0), std::pow(10.0, x1)) : std::vector<Tick>{};
  const std::vector<Tick> yticks =
      f.y.log ? log_axis_ticks(std::pow(10.0, y0), std::pow(10.0, y1)) : std::vector<Tick>{};
  double longest_y = 0;
  for (const auto& t : yticks) {
    double n = 0;
    for (std::size_t i = 0; i < t.label.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(t.label[i]);
      if (c == '#') {  // "#u" / "#d": no glyph
        ++i;
        continue;
      }
      if ((c & 0xC0) != 0x80) n += 1;
    }
    longest_y = std::max(longest_y, n);
  }
  const double ytitle_disp = std::max(5.0, 0.75 * longest_y + 1.8);
  // The title may take two lines (fit_title); the plot top moves down for it.
  const double vx0 = std::max(0.11, (ytitle_disp + 1.0) * char_ht / page_w);
  const double vx1 = right;
  const TitleLayout title = fit_title(f.title, 0.94 * page_w / (title_glyph_w * char_ht));
  const double title_ht = (title_disp + title_gap * static_cast<double>(title.lines.size() - 1) + 1.0) *
                          title.scale * char_ht / page_h;
  plvpor(vx0, vx1, bottom, std::min(0.91, 1.0 - title_ht - 0.01));
  plwind(x0, x1, y0, y1);

  // Grid first (under the data), then the frame, ticks and numbers. A log
  // axis gets its numbers (and grid lines) from log_axis_ticks: PLplot's own
  // log labels sit on whole decades only and vanish inside one decade.
  plcol0(grid);
  plwidth(0.5);
  plbox(f.x.log ? "" : "g", categorical ? 1.0 : 0.0, categorical ? 1 : 0, f.y.log ? "" : "g", 0.0, 0);
  for (const auto& t : xticks) pljoin(std::log10(t.value), y0, std::log10(t.value), y1);
  for (const auto& t : yticks) pljoin(x0, std::log10(t.value), x1, std::log10(t.value));
  plcol0(ink);
  plwidth(1.0);
  const std::string xlog = f.x.log ? "l" : "";
  const std::string ylog = f.y.log ? "l" : "";
  const std::string ynum = f.y.log ? "" : "n";
  for (const auto& t : xticks)
    plmtex("b", 1.5, (std::log10(t.value) - x0) / (x1 - x0), 0.5, t.label.c_str());
  for (const auto& t : yticks)
    plmtex("lv", 0.5, (std::log10(t.value) - y0) / (y1 - y0), 1.0, t.label.c_str());
  if (categorical) {
    plbox("bct", 1.0, 1, ("bcstv" + ynum + ylog).c_str(), 0.0, 0);
    // Category names perpendicular to the bottom edge, ending at the axis.
    for (std::size_t i = 0; i < f.x.tick_labels.size(); ++i) {
      const double pos = (static_cast<double>(i) - x0) / (x1 - x0);
      plmtex("bv", tick_disp, pos, 1.0, plain(f.x.tick_labels[i]).c_str());
    }
    plmtex("b", names_ht + 1.8, 0.5, 0.5, plain(axis_title(f.x)).c_str());
    plmtex("l", ytitle_disp, 0.5, 0.5, plain(axis_title(f.y)).c_str());
  } else {
    plbox(("bcst" + std::string(f.x.log ? "" : "n") + xlog).c_str(), 0.0, 0,
          ("bcstv" + ynum + ylog).c_str(), 0.0, 0);
    pllab(plain(axis_title(f.x)).c_str(), "", "");
    plmtex("l", ytitle_disp, 0.5, 0.5, plain(axis_title(f.y)).c_str());
  }
  draw_title(title, vx0, vx1);

  std::vector<LegendEntry> highlight_legend;
  auto draw_highlight = [&](const Highlight& h) {
    const PLINT colour = h.warning_colour ? warning : highlight;
    const std::string symbol = glyph(h.marker == Marker::automatic ? Marker::circle : h.marker);
    if (h.connect) {
      std::vector<std::size_t> order(h.x.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(), [&](auto a, auto b) { return h.x[a] < h.x[b]; });
      std::vector<double> sx, sy;
      for (auto i : order) {
        sx.push_back(h.x[i]);
        sy.push_back(h.y[i]);
      }
      plcol0(colour);
      plwidth(1.5);
      draw_lines(sx, sy, f);
      plwidth(1.0);
    }
    // A dark outline (the glyph drawn larger in ink) under the coloured glyph.
    PLFLT def = 0, ht = 0;
    plgchr(&def, &ht);
    plschr(0.0, 1.6);
    plcol0(ink);
    draw_markers(h.x, h.y, f, symbol.c_str());
    plschr(0.0, 1.25);
    plcol0(colour);
    draw_markers(h.x, h.y, f, symbol.c_str());
    plschr(0.0, 1.0);
    if (!h.label.empty())
      highlight_legend.push_back({h.label, PL_LEGEND_SYMBOL | (h.connect ? PL_LEGEND_LINE : 0), colour,
                        symbol, 1.25});
  };
  for (const auto& h : f.highlights)
    if (h.beneath_series) draw_highlight(h);
  for (std::size_t i = 0; i < f.series.size(); ++i) {
    const auto& s = f.series[i];
    const std::size_t slot = s.colour >= 0 ? static_cast<std::size_t>(s.colour) : i;
    const PLINT colour = first_series + static_cast<PLINT>(slot % n_series);
    const std::string symbol = glyph(resolve(s.marker, slot));
    plcol0(colour);
    if (s.style != Style::markers) {
      plwidth(2.0);
      if (s.dashed) pllsty(dashed_style);
      draw_lines(s.x, s.y, f);
      pllsty(1);
      plwidth(1.0);
    }
    if (s.style != Style::lines) draw_markers(s.x, s.y, f, symbol.c_str());
    if (!s.label.empty()) {
      PLINT opt = 0;
      if (s.style != Style::markers) opt |= PL_LEGEND_LINE;
      if (s.style != Style::lines) opt |= PL_LEGEND_SYMBOL;
      legend.push_back({s.label, opt, colour, symbol, 1.0, s.dashed ? dashed_style : 1});
    }
  }
  for (const auto& h : f.highlights)
    if (!h.beneath_series) draw_highlight(h);
  legend.insert(legend.end(), highlight_legend.begin(), highlight_legend.end());
  if (with_legend && !legend.empty()) {
    for (auto& e : legend) e.text = plain(e.text);
    draw_legend(legend);
  }
  plend1();
}

void write_with(const Figure& figure, const char* device, const std::filesystem::path& target) {
  validate(figure);
  const auto tmp = files::temporary_name_for(target);
  {
    std::lock_guard lock(plplot_mutex());
    if (!device_available(device))
      throw ComputeError(std::string("plot: PLplot device '") + device +
                         "' is not available (install the Debian package plplot-driver-cairo)");
    abort_message().clear();
    plsabort(on_plabort);
    render(figure, device, tmp);
    plsabort(nullptr);
    if (!abort_message().empty()) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw ComputeError("plot '" + figure.title + "' for " + target.string() +
                         ": PLplot reported: " + abort_message());
    }
  }
  std::error_code ec;
  if (!std::filesystem::exists(tmp, ec) || std::filesystem::file_size(tmp, ec) == 0) {
    std::filesystem::remove(tmp, ec);
    throw ComputeError("plot '" + figure.title + "': PLplot device '" + device +
                       "' wrote no data for " + target.string());
  }
  files::replace(tmp, target);
}

}  // namespace

namespace {

// "0.02", "5000" within 1e-3..1e4; else "2×10⁻⁵" in PLplot's superscript syntax.
std::string tick_text(double v) {
  char buf[64];
  const double a = std::abs(v);
  if (a >= 1e-3 * (1 - 1e-9) && a < 1e4) {
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
  }
  int k = static_cast<int>(std::floor(std::log10(a) + 1e-9));
  double m = v / std::pow(10.0, k);
  std::snprintf(buf, sizeof buf, "%.3g", m);
  const std::string exp = "10#u" + std::to_string(k) + "#d";
  return std::abs(m - 1.0) < 1e-9 ? exp : std::string(buf) + "×" + exp;
}

// The smallest 1-2-5 x 10^j step at least `raw`.
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw * (1 - 1e-12)) return m * p;
  return 10.0 * p;
}

}  // namespace

std::vector<Tick> log_axis_ticks(double lo, double hi) {
  if (!(lo > 0) || !(hi > lo) || !std::isfinite(hi))
    throw InputError("log axis ticks: need 0 < lo < hi, got lo = " + std::to_string(lo) +
                     ", hi = " + std::to_string(hi));
  const double tol = 1e-9;  // a tick exactly on the range end counts
  const int k0 = static_cast<int>(std::floor(std::log10(lo))) - 1;
  const int k1 = static_cast<int>(std::ceil(std::log10(hi))) + 1;
  auto pick = [&](std::initializer_list<int> mantissas) {
    std::vector<Tick> t;
    for (int k = k0; k <= k1; ++k)
      for (int m : mantissas) {
        const double v = m * std::pow(10.0, k);
        if (v >= lo * (1 - tol) && v <= hi * (1 + tol)) t.push_back({v, tick_text(v)});
      }
    return t;
  };
  auto decades = pick({1});
  if (decades.size() >= 3) {
    // Many decades: keep every n-th so that at most 8 are labelled.
    const std::size_t every = (decades.size() + 7) / 8;
    std::vector<Tick> thinned;
    for (std::size_t i = 0; i < decades.size(); i += every) thinned.push_back(decades[i]);
    return thinned;
  }
  auto one_two_five = pick({1, 2, 5});
  if (one_two_five.size() >= 3) return one_two_five;
  auto all = pick({1, 2, 3, 4, 5, 6, 7, 8, 9});
  if (all.size() >= 3) return all;
  // Within a few integer mantissas (1.5-3.3 s has only "2" and "3"): linear
  // 1-2-5 steps, when they give more labels.
  const double step = nice_step((hi - lo) / 4.0);
  std::vector<Tick> t;
  for (double i = std::ceil(lo / step * (1 - tol)); i * step <= hi * (1 + tol); i += 1.0)
    t.push_back({i * step, tick_text(i * step)});
  return t.size() > all.size() ? t : all;
}

TitleLayout fit_title(const std::string& title, double width_chars) {
  // Length in glyphs (UTF-8 continuation bytes do not count).
  auto glyphs = [](const std::string& s) {
    double n = 0;
    for (unsigned char c : s) n += (c & 0xC0) != 0x80 ? 1.0 : 0.0;
    return n;
  };
  TitleLayout out;
  if (glyphs(title) <= width_chars || width_chars <= 0) {
    out.lines = {title};
    return out;
  }
  // Two lines, broken at the space nearest the middle.
  std::size_t best = std::string::npos;
  const double mid = static_cast<double>(title.size()) / 2.0;
  for (std::size_t i = 0; i < title.size(); ++i)
    if (title[i] == ' ' &&
        (best == std::string::npos || std::abs(static_cast<double>(i) - mid) < std::abs(static_cast<double>(best) - mid)))
      best = i;
  if (best != std::string::npos)
    out.lines = {title.substr(0, best), title.substr(best + 1)};
  else
    out.lines = {title};
  double longest = 0;
  for (const auto& l : out.lines) longest = std::max(longest, glyphs(l));
  constexpr double min_scale = 0.7;
  out.scale = std::min(1.0, std::max(min_scale, width_chars / longest));
  // Still too long at the smallest size: cut each line with "...".
  const auto room = static_cast<std::size_t>(std::floor(width_chars / out.scale));
  for (auto& l : out.lines)
    if (glyphs(l) > width_chars / out.scale) {
      std::string cut;
      double n = 0;
      for (std::size_t i = 0; i < l.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(l[i]);
        if ((c & 0xC0) != 0x80) {
          if (n + 1 > static_cast<double>(room) - 3) break;
          n += 1;
        }
        cut += l[i];
      }
      l = cut + "...";
    }
  return out;
}

std::string axis_title(const Axis& axis) {
  return axis.unit.empty() ? axis.label : axis.label + " [" + axis.unit + "]";
}

void write_png(const Figure& figure, const std::filesystem::path& target) {
  write_with(figure, "pngcairo", target);
}

void write_svg(const Figure& figure, const std::filesystem::path& target) {
  write_with(figure, "svgcairo", target);
}

void write_figure(const Figure& figure, const std::filesystem::path& target) {
  const auto ext = target.extension().string();
  if (ext == ".png") return write_png(figure, target);
  if (ext == ".svg") return write_svg(figure, target);
  throw InputError("plot file " + target.string() + ": extension must be .png or .svg");
}

}  // namespace stentsim::plots
