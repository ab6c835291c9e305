#include "workflows/cohort/cohort_plots.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include "common/files.hpp"
#include "common/markdown.hpp"
#include "workflows/plots/figure.hpp"

namespace fs = std::filesystem;

namespace stentsim::workflows {
namespace {

// Fixed and input columns are not QoIs: no plot, no statistics.
bool is_fixed(const std::string& col) {
  const auto& fixed = cohort_fixed_columns();
  return std::find(fixed.begin(), fixed.end(), col) != fixed.end() || col.rfind("override.", 0) == 0;
}

std::optional<double> number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string cell(const std::map<std::string, std::string>& row, const std::string& col) {
  auto it = row.find(col);
  return it == row.end() ? "" : it->second;
}

// "mesh.artery_elements [mm]" -> label "artery_elements", stage "mesh", unit "mm".
struct QoiName {
  std::string stage, name, unit;
};
QoiName split_column(const std::string& col) {
  QoiName q;
  std::string base = col;
  if (auto lb = col.rfind(" ["); lb != std::string::npos && col.back() == ']') {
    q.unit = col.substr(lb + 2, col.size() - lb - 3);
    base = col.substr(0, lb);
  }
  const auto dot = base.find('.');
  q.stage = dot == std::string::npos ? "" : base.substr(0, dot);
  q.name = dot == std::string::npos ? base : base.substr(dot + 1);
  return q;
}

// A file name from the column: letters, digits, '.', '-', '_' only.
std::string plot_file_name(const std::string& col) {
  const QoiName q = split_column(col);
  std::string stem = "plot_" + (q.stage.empty() ? "" : q.stage + ".") + q.name;
  for (char& ch : stem)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-' && ch != '_') ch = '_';
  return stem + ".png";
}


}  // namespace

std::vector<std::string> numeric_qoi_columns(const CohortTable& t) {
  std::vector<std::string> out;
  for (const auto& col : t.columns) {
    if (is_fixed(col)) continue;
    bool any = false, all = true;
    for (const auto& row : t.rows) {
      const auto v = cell(row, col);
      if (v.empty()) continue;
      if (number(v)) any = true;
      else all = false;
    }
    if (any && all) out.push_back(col);
  }
  return out;
}

std::vector<fs::path> write_cohort_plots(const CohortConfig& c, const CohortTable& t) {
  std::vector<fs::path> written;
  std::vector<std::string> ids;
  for (const auto& row : t.rows) ids.push_back(cell(row, "case"));
  if (ids.empty()) return written;
  for (const auto& col : numeric_qoi_columns(t)) {
    const QoiName q = split_column(col);
    plots::Figure f;
    f.title = fmt::format("{}: {} ({} stage)", c.name, q.name, q.stage);
    f.x.label = "case";
    f.x.tick_labels = ids;
    f.y.label = q.name;
    f.y.unit = q.unit;
    f.width_px = std::max(700, 200 + 45 * static_cast<int>(ids.size()));
    plots::Series ok{"done", {}, {}, plots::Style::markers, plots::Marker::circle};
    plots::Highlight failed{"failed / unexpected", {}, {}, plots::Marker::cross, false, true};
    plots::Highlight expected{"failed as expected", {}, {}, plots::Marker::cross, false, false};
    std::vector<std::size_t> missing_failed, missing_expected;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < t.rows.size(); ++i) {
      const auto v = number(cell(t.rows[i], col));
      const std::string status = cell(t.rows[i], "status");
      const bool is_ok = status == "done";
      const bool is_expected = status == "failed as expected";
      if (v) {
        lo = std::min(lo, *v);
        hi = std::max(hi, *v);
      }
      const double x = static_cast<double>(i);
      if (is_ok) {
        ok.x.push_back(x);
        ok.y.push_back(v ? *v : std::numeric_limits<double>::quiet_NaN());
      } else if (v) {  // a failed case that still produced this QoI (an earlier stage)
        auto& h = is_expected ? expected : failed;
        h.x.push_back(x);
        h.y.push_back(*v);
      } else {
        (is_expected ? missing_expected : missing_failed).push_back(i);
      }
    }
    // Fix the y range so that cases without a value sit on the bottom axis.
    if (!(lo <= hi)) lo = hi = 0.0;
    const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(0.1 * std::abs(lo), 1.0);
    f.y.min = lo - pad;
    f.y.max = hi + pad;
    for (auto i : missing_failed) {
      failed.x.push_back(static_cast<double>(i));
      failed.y.push_back(*f.y.min);
    }
    for (auto i : missing_expected) {
      expected.x.push_back(static_cast<double>(i));
      expected.y.push_back(*f.y.min);
    }
    if (!missing_failed.empty() || !missing_expected.empty())
      f.title += "  (x on the axis: no value)";
    if (!ok.x.empty()) f.series.push_back(ok);
    if (!failed.x.empty()) f.highlights.push_back(failed);
    if (!expected.x.empty()) f.highlights.push_back(expected);
    const fs::path file = c.work_dir / plot_file_name(col);
    plots::write_png(f, file);
    written.push_back(file);
  }
  return written;
}

void write_cohort_markdown(const CohortConfig& c, const CohortTable& t) {
  const auto qois = numeric_qoi_columns(t);
  std::string md = fmt::format("# Cohort {}\n\n{} cases; source: `{}`.\n\n", c.name, t.rows.size(), c.file.string());
  int n_ok = 0, n_expected = 0, n_failed = 0;
  for (const auto& row : t.rows) {
    const auto s = cell(row, "status");
    if (s == "done") ++n_ok;
    else if (s == "failed as expected") ++n_expected;
    else ++n_failed;
  }
  md += fmt::format("Done: {}, failed as expected: {}, other (failed, interrupted, succeeded unexpectedly): {}.\n\n",
                    n_ok, n_expected, n_failed);

  md += "## Cases\n\n| case | status | failed stage | wall time [s] |";
  for (const auto& col : qois) md += " " + markdown_cell(col) + " |";
  md += "\n|---|---|---|---:|";
  for (std::size_t i = 0; i < qois.size(); ++i) md += "---:|";
  md += "\n";
  for (const auto& row : t.rows) {
    md += fmt::format("| {} | {} | {} | {} |", markdown_cell(cell(row, "case")), markdown_cell(cell(row, "status")),
                      markdown_cell(cell(row, "failed_stage")), cell(row, "wall_time_s"));
    for (const auto& col : qois) {
      const auto v = number(cell(row, col));
      md += v ? fmt::format(" {:.4g} |", *v) : std::string(" – |");
    }
    md += "\n";
  }

  md += "\n## QoIs over the cases that have them\n\n| QoI | unit | n | min | median | max | plot |\n|---|---|---:|---:|---:|---:|---|\n";
  for (const auto& col : qois) {
    std::vector<double> v;
    for (const auto& row : t.rows)
      if (auto x = number(cell(row, col))) v.push_back(*x);
    std::sort(v.begin(), v.end());
    const double median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    const QoiName q = split_column(col);
    const auto png = plot_file_name(col);
    md += fmt::format("| {}.{} | {} | {} | {:.4g} | {:.4g} | {:.4g} | [{}]({}) |\n", markdown_cell(q.stage), markdown_cell(q.name),
                      markdown_cell(q.unit), v.size(), v.front(), median, v.back(), png, png);
  }

  bool any_failure = false;
  for (const auto& row : t.rows)
    if (!cell(row, "message").empty()) {
      if (!any_failure) md += "\n## Failures (last log lines)\n\n";
      any_failure = true;
      const std::string kind = cell(row, "error_kind");
      md += fmt::format("- **{}** ({}{}{}): {}\n", markdown_cell(cell(row, "case")), cell(row, "status"),
                        cell(row, "failed_stage").empty() ? "" : " at " + cell(row, "failed_stage"),
                        kind.empty() ? "" : kind == "input" ? ", bad input" : ", " + markdown_cell(kind),
                        markdown_cell(cell(row, "message")));
    }
  files::write_atomic(c.work_dir / "cohort_summary.md", md);
}

}  // namespace stentsim::workflows
