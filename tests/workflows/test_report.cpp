// The report stage's library on a fixture work folder that follows the solve
// stage's contract (history.csv columns, summary.yaml QoIs, results.pvd, a
// manifest written by pipeline::Manifest): verdicts against the paper's
// numbers, figures drawn only from present data, clear errors for damaged
// inputs, a self-contained HTML, and what Chromium makes of it.
#include <gtest/gtest.h>
#include <zlib.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "common/error.hpp"
#include "common/summary.hpp"
#include "pipeline/manifest.hpp"
#include "workflows/report/paper_targets.hpp"
#include "workflows/report/report.hpp"
#include "workflows/report/report_inputs.hpp"
#include "workflows/report/report_writer.hpp"
#include "workflows/report/target_table.hpp"

namespace fs = std::filesystem;
using namespace stentsim;
using namespace stentsim::workflows::report;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("stentsim_test_report_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& f, const std::string& text) {
  fs::create_directories(f.parent_path());
  std::ofstream(f, std::ios::binary) << text;
}

std::string read(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct FixtureOptions {
  bool device_columns = true;  // pressure, diameters, dogboning, contact
  bool artery_columns = false;  // diastolic pressure, layer stresses
  bool balloon_profile = true;
};

// A free expansion to 1.01 MPa at t = 1 and back to 0 at t = 2 (40 steps), the
// stent's diameter following the pressure to 2.60 mm and recoiling to 2.50 mm.
std::string history_csv(const FixtureOptions& o) {
  std::string header = "step,time,dt,load_factor,newton_iterations,linear_iterations,step_cuts,wall_time_s,assembly_s,linear_solve_s";
  if (o.artery_columns) header += ",pressure_diastolic";
  if (o.device_columns) {
    header += ",pressure_inflation,stent_diameter";
    for (int k = 0; k < 4; ++k) header += fmt::format(",stent_ring_{}_diameter", k);
    header += ",stent_dogboning_percent,contact_stent_balloon_force,contact_stent_balloon_active_points";
  }
  if (o.artery_columns) header += ",max_principal_media_kpa,max_principal_adventitia_kpa,contact_stent_artery_force";
  header += ",some_future_column\n";
  std::string rows;
  const int n = 40;
  for (int i = 1; i <= n; ++i) {
    const double t = 2.0 * i / n;
    const double p = 1.01 * (t <= 1.0 ? t : 2.0 - t);
    const double d = t <= 1.0 ? 1.15 + 1.45 * t * t : 2.60 - 0.10 * (t - 1.0);
    rows += fmt::format("{},{},0.05,{},{},{},{},0.5,0.2,0.25", i, t, t, 3 + i % 3, 20 + i, i == 7 ? 1 : 0);
    if (o.artery_columns) rows += ",0.0113";
    if (o.device_columns) {
      rows += fmt::format(",{},{}", p, d);
      for (double factor : {1.05, 0.97, 0.98, 1.04}) rows += fmt::format(",{}", d * factor);
      rows += fmt::format(",{},{},{}", 20.0 * p, 0.8 * p, i);
    }
    if (o.artery_columns) rows += fmt::format(",{},{},{}", 40 + 300 * p, 10 + 40 * p, 0.5 * p);
    rows += ",nan\n";
  }
  return header + rows;
}

struct Fixture {
  fs::path dir, work, solve, report_dir, md, html, figures;
  ReportInput in;
};

Fixture make_fixture(const std::string& name, const FixtureOptions& o = {}) {
  Fixture f;
  f.dir = fresh_dir(name);
  f.work = f.dir / "case.work";
  f.solve = f.work / "solve";
  f.report_dir = f.work / "report";
  f.md = f.report_dir / "report.md";
  f.html = f.report_dir / "report.html";
  f.figures = f.report_dir / "figures";
  write(f.solve / "history.csv", history_csv(o));

  Summary s;
  s.set("stent_diameter_initial", 1.15, "mm");
  s.set("stent_diameter_max", 2.60, "mm");    // paper 2.59 +-3 %: pass
  s.set("stent_diameter_after", 2.50, "mm");  // paper 2.31 +-3 %: FAIL
  // recoil_percent left out: not computed
  s.set("dogboning_percent", 21.0, "%");  // paper 20.4 +-5 abs: pass
  s.set("dogboning_pressure", 0.84, "MPa");
  s.set("newton_iterations", 160, "");
  s.set("steps", 40, "");
  if (o.balloon_profile) {
    s.set("balloon_profile_z", std::vector<double>{-4, -2, 0, 2, 4}, "mm");
    s.set("balloon_profile_diameter_1.01MPa", std::vector<double>{2.0, 2.5, 2.45, 2.5, 2.0}, "mm");
    s.set("balloon_profile_diameter_0.5MPa", std::vector<double>{1.5, 1.9, 1.85, 1.9, 1.5}, "mm");
  }
  if (o.artery_columns) {
    s.set("max_principal_media_max_kpa", 8100, "kPa");
    s.set("max_principal_adventitia_max_kpa", 52, "kPa");    // paper 49.5 +-25 %: pass
    s.set("max_principal_adventitia_after_kpa", 30, "kPa");  // paper 13.7 +-25 %: FAIL
    s.set("max_principal_media_prestress_kpa", 15, "kPa");   // inconsistent in the paper
    s.set("artery_max_displacement_prestress", 0.15, "mm");  // paper 0.14 +-15 %, independent of the inflation pressure
  }
  s.set_text("contact_model", "penalty");
  s.set_run(120.0, 250.0);
  s.note("balloon", "orthotropic membrane-like hex8 layer");
  s.write(f.solve / "summary.yaml");

  write(f.solve / "results.pvd",
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n"
        "    <DataSet timestep=\"0\" group=\"\" part=\"0\" name=\"balloon\" file=\"results/balloon_00000.vtu\"/>\n"
        "    <DataSet timestep=\"0\" group=\"\" part=\"1\" name=\"stent\" file=\"results/stent_00000.vtu\"/>\n"
        "    <DataSet timestep=\"0.5\" group=\"\" part=\"0\" name=\"balloon\" file=\"results/balloon_00001.vtu\"/>\n"
        "    <DataSet timestep=\"0.5\" group=\"\" part=\"1\" name=\"stent\" file=\"results/stent_00001.vtu\"/>\n"
        "    <DataSet timestep=\"1\" group=\"\" part=\"0\" name=\"balloon\" file=\"results/balloon_00002.vtu\"/>\n"
        "    <DataSet timestep=\"1\" group=\"\" part=\"1\" name=\"stent\" file=\"results/stent_00002.vtu\"/>\n"
        "    <DataSet timestep=\"2\" group=\"\" part=\"0\" name=\"balloon\" file=\"results/balloon_00004.vtu\"/>\n"
        "    <DataSet timestep=\"2\" group=\"\" part=\"1\" name=\"stent\" file=\"results/stent_00004.vtu\"/>\n"
        "  </Collection>\n</VTKFile>\n");

  Summary balloon;
  balloon.set("balloon_elements", 1276);
  balloon.set("balloon_nodes", 2552);
  balloon.set("balloon_dofs", 7656);
  balloon.set("balloon_length", 9.4, "mm");
  balloon.write(f.work / "balloon" / "summary.yaml");

  pipeline::Manifest m;
  m.tool_version = "test";
  auto record = [](double seconds, double mb) {
    pipeline::StageRecord r;
    r.status = "ok";
    r.finished = "2025-01-01T00:00:00Z";
    r.duration_s = seconds;
    r.peak_memory_mb = mb;
    return r;
  };
  m.set("placement", record(0.4, 50));
  m.set("balloon", record(0.2, 40));
  m.set("stent", record(0.3, 45));
  m.set("solve", record(125.0, 260));
  m.set("report", record(0, 0));  // a previous report: not listed
  m.save(f.work / "manifest.yaml");

  f.in.case_name = "free-expansion-straight";
  f.in.scene = "free-expansion";
  f.in.case_file = f.dir / "free-expansion.yaml";
  f.in.work_dir = f.work;
  f.in.solve_dir = f.solve;
  f.in.targets_key = "free_expansion_straight";
  f.in.pressure_max = 1.01;
  f.in.stages = {"balloon", "stent", "solve", "report"};
  return f;
}

// Keeps the folder of a failed test for a look (or every test's, with
// STENTSIM_KEEP_TEST_OUTPUT set), removes it otherwise.
void cleanup(const Fixture& f) {
  if (!::testing::Test::HasFailure() && !std::getenv("STENTSIM_KEEP_TEST_OUTPUT")) fs::remove_all(f.dir);
}

// The cells of the Markdown table row whose first cell starts with `first`.
std::vector<std::string> md_row(const std::string& md, const std::string& first) {
  std::istringstream in(md);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| " + first, 0) != 0) continue;
    std::vector<std::string> cells;
    std::size_t start = 1;
    while (true) {
      const auto bar = line.find(" |", start);
      if (bar == std::string::npos) break;
      std::string c = line.substr(start, bar - start);
      cells.push_back(c.substr(c.find_first_not_of(' ') == std::string::npos ? c.size() : c.find_first_not_of(' ')));
      start = bar + 2;
    }
    return cells;
  }
  return {};
}

std::string verdict_of(const std::string& md, const std::string& quantity) {
  const auto cells = md_row(md, quantity);
  return cells.size() == 6 ? cells[5] : "<no row '" + quantity + "'>";
}

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

double qoi(const Summary& s, const std::string& name) {
  auto it = s.qois().find(name);
  if (it == s.qois().end()) return -1;
  return std::get<double>(it->second.value);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "<no InputError>";
}

std::vector<unsigned char> base64_decode(const std::string& in) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  unsigned buf = 0;
  int bits = 0;
  for (char c : in) {
    if (c == '=') break;
    const int v = val(c);
    if (v < 0) return {};  // not base64
    buf = (buf << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buf >> bits) & 0xFF));
    }
  }
  return out;
}

bool is_png(const std::vector<unsigned char>& b) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  return b.size() > 8 && std::equal(sig, sig + 8, b.begin());
}

// A minimal PNG reader (8-bit RGB/RGBA, not interlaced: what Chromium writes)
// so the screenshot's pixels can be looked at without an image library.
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;  // 3 bytes a pixel
};

std::optional<Image> decode_png(const std::string& file) {
  const std::string s = read(file);
  const std::vector<unsigned char> b(s.begin(), s.end());
  if (!is_png(b)) return std::nullopt;
  auto u32 = [&](std::size_t p) { return (unsigned(b[p]) << 24) | (unsigned(b[p + 1]) << 16) | (unsigned(b[p + 2]) << 8) | unsigned(b[p + 3]); };
  Image img;
  int colour_type = -1, depth = 0, interlace = 0;
  std::vector<unsigned char> idat;
  for (std::size_t p = 8; p + 8 <= b.size();) {
    const unsigned len = u32(p);
    const std::string type(b.begin() + p + 4, b.begin() + p + 8);
    if (p + 12 + len > b.size()) return std::nullopt;
    if (type == "IHDR") {
      img.width = static_cast<int>(u32(p + 8));
      img.height = static_cast<int>(u32(p + 12));
      depth = b[p + 16];
      colour_type = b[p + 17];
      interlace = b[p + 20];
    } else if (type == "IDAT") {
      idat.insert(idat.end(), b.begin() + p + 8, b.begin() + p + 8 + len);
    }
    p += 12 + len;
  }
  if (depth != 8 || (colour_type != 2 && colour_type != 6) || interlace != 0) return std::nullopt;
  const int bpp = colour_type == 6 ? 4 : 3;
  const std::size_t stride = static_cast<std::size_t>(img.width) * bpp;
  std::vector<unsigned char> raw((stride + 1) * img.height);
  uLongf raw_len = raw.size();
  if (uncompress(raw.data(), &raw_len, idat.data(), idat.size()) != Z_OK || raw_len != raw.size()) return std::nullopt;
  std::vector<unsigned char> prev(stride, 0), cur(stride);
  img.rgb.reserve(static_cast<std::size_t>(img.width) * img.height * 3);
  for (int y = 0; y < img.height; ++y) {
    const unsigned char* row = raw.data() + y * (stride + 1);
    const int filter = row[0];
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= static_cast<std::size_t>(bpp) ? cur[i - bpp] : 0, up = prev[i];
      const int c = i >= static_cast<std::size_t>(bpp) ? prev[i - bpp] : 0;
      int pred = 0;
      switch (filter) {
        case 0: pred = 0; break;
        case 1: pred = a; break;
        case 2: pred = up; break;
        case 3: pred = (a + up) / 2; break;
        case 4: {
          const int pa = std::abs(up - c), pb = std::abs(a - c), pc = std::abs(a + up - 2 * c);
          pred = pa <= pb && pa <= pc ? a : (pb <= pc ? up : c);
          break;
        }
        default: return std::nullopt;
      }
      cur[i] = static_cast<unsigned char>(row[1 + i] + pred);
    }
    for (int x = 0; x < img.width; ++x)
      for (int k = 0; k < 3; ++k) img.rgb.push_back(cur[x * bpp + k]);
    std::swap(prev, cur);
  }
  return img;
}

// ---------------------------------------------------------------------------

TEST(ReportTargets, EveryEmbeddedEntryHasAMappingAndTheSetupIsRead) {
  for (const auto& key : paper_case_keys(paper_targets_text(), "embedded")) {
    const PaperCase c = paper_case(key);
    for (const auto& r : c.results) EXPECT_NE(find_mapping(key, r.name), nullptr) << key << "." << r.name;
    ASSERT_TRUE(c.pressure_max) << key;
    EXPECT_DOUBLE_EQ(*c.pressure_max, 1.01) << key;
    EXPECT_TRUE(c.run_time_s) << key;
  }
  const PaperCase s = paper_case("free_expansion_straight");
  EXPECT_NEAR(*s.run_time_s, 14.7 * 60, 1e-9);
  EXPECT_EQ(s.run_processes, 2);
  EXPECT_NE(s.pressure_comment.find("13 atm"), std::string::npos) << s.pressure_comment;
  const PaperCase g = paper_case("generic_artery_case1");
  EXPECT_NEAR(*g.run_time_s, 6.8 * 3600, 1e-9);
  bool saw_comment = false;
  for (const auto& r : g.results)
    if (r.name == "prestress_max_principal_media_kPa") {
      EXPECT_TRUE(r.inconsistent);
      saw_comment = r.comment.find("hoop equilibrium") != std::string::npos;
    }
  EXPECT_TRUE(saw_comment) << "the comment above the entry should come with it";
  // The embedded copy keeps the shared file's comments.
  EXPECT_NE(paper_targets_text().find("# Reference numbers from the paper"), std::string::npos);
  EXPECT_NE(error_of([] { paper_case("no_such_case"); }).find("free_expansion_straight"), std::string::npos);
}

TEST(ReportTargets, VerdictRules) {
  PaperCase c;
  c.key = "free_expansion_straight";
  c.pressure_max = 1.01;
  PaperResult relative, absolute;
  relative.name = "diameter_at_max_pressure";
  relative.value = 2.59;
  relative.tolerance = 0.03;
  absolute.name = "elastic_recoil_percent";
  absolute.value = 10.8;
  absolute.tolerance_abs = 2.0;
  c.results = {relative, absolute};
  Summary s;
  s.set("stent_diameter_max", 2.59 * 1.029, "mm");  // just inside 3 %
  s.set("recoil_percent", 12.9, "%");               // 2.1 points off: outside
  TargetTable t = judge_targets(c, s, 1.01);
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0].verdict, Verdict::pass);
  EXPECT_EQ(t.rows[1].verdict, Verdict::fail);
  s.set("stent_diameter_max", 2.59 * 1.031, "mm");  // just outside
  s.set("recoil_percent", 12.7, "%");
  t = judge_targets(c, s, 1.01);
  EXPECT_EQ(t.rows[0].verdict, Verdict::fail);
  EXPECT_EQ(t.rows[1].verdict, Verdict::pass);
  EXPECT_EQ(t.judged, 2);
  // 13 atm is not the paper's 1.01 MPa: shown, not judged.
  t = judge_targets(c, s, 13 * 0.101325);
  EXPECT_EQ(t.rows[0].verdict, Verdict::different_pressure);
  EXPECT_EQ(t.judged, 0);
  EXPECT_FALSE(t.pressure.matches);
  // Units convert (kPa in the summary, MPa in the paper).
  EXPECT_NEAR(*convert_unit(7990, "kPa", "MPa"), 7.99, 1e-12);
  EXPECT_NEAR(*convert_unit(0.62, "N*mm", "N mm"), 0.62, 1e-12);
  EXPECT_FALSE(convert_unit(1, "mm", "MPa"));
}

TEST(ReportInputs, InflationRowsAndPressureColumn) {
  EXPECT_EQ(inflation_end({0, 0.5, 1.0, 1.0, 0.5, 0}), 4u);
  EXPECT_EQ(inflation_end({0.2, 0.6, 1.0, 0.4}), 3u);
  EXPECT_EQ(inflation_end({0, 0, 0}), 0u);
  History h;
  h.columns = {"pressure_diastolic", "pressure_balloon"};
  h.values["pressure_diastolic"];
  h.values["pressure_balloon"];
  EXPECT_EQ(inflation_pressure_column(h).value_or(""), "pressure_balloon");
  h.columns.push_back("pressure_inflation");
  h.values["pressure_inflation"];
  EXPECT_EQ(inflation_pressure_column(h).value_or(""), "pressure_inflation");
}

TEST(Report, WritesBothFilesWithVerdictsFiguresAndFrames) {
  Fixture f = make_fixture("main");
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  ASSERT_TRUE(fs::exists(f.md));
  ASSERT_TRUE(fs::exists(f.html));
  const std::string md = read(f.md), html = read(f.html);

  EXPECT_TRUE(starts_with(verdict_of(md, "diameter_at_max_pressure"), "pass")) << md;
  EXPECT_TRUE(starts_with(verdict_of(md, "diameter_after_deflation"), "FAIL"));
  EXPECT_TRUE(starts_with(verdict_of(md, "dogboning_ratio_percent_at_10_4_atm"), "pass"));
  EXPECT_TRUE(starts_with(verdict_of(md, "elastic_recoil_percent"), "not computed"));
  EXPECT_TRUE(starts_with(verdict_of(md, "manufacturer_diameter_at_13_atm"), "report only"));
  const auto row = md_row(md, "diameter_at_max_pressure");
  ASSERT_EQ(row.size(), 6u);
  EXPECT_EQ(row[1], "2.59 mm");
  EXPECT_EQ(row[2], "±3 % (relative)");
  EXPECT_EQ(row[3], "2.6 mm");
  EXPECT_EQ(qoi(out, "targets_passed"), 2);
  EXPECT_EQ(qoi(out, "targets_failed"), 1);
  EXPECT_EQ(qoi(out, "targets_judged"), 3);
  EXPECT_EQ(qoi(out, "targets_not_computed"), 1);
  EXPECT_EQ(qoi(out, "pressure_matches_paper"), 1);

  // The same verdicts in the HTML, coloured.
  EXPECT_NE(html.find("<td class=\"pass\">pass"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"fail\">FAIL"), std::string::npos);

  // The run: stages from the manifest (not the report itself), mesh counts, solve costs, the paper's run time.
  EXPECT_EQ(md_row(md, "solve").at(1), "ok");
  EXPECT_TRUE(md_row(md, "report").empty());
  EXPECT_NE(md.find("| balloon | balloon_dofs | 7656 |"), std::string::npos);
  EXPECT_EQ(md.find("balloon_length"), std::string::npos);  // not a count: not in the mesh table
  EXPECT_NE(md.find("converged steps: 40"), std::string::npos);
  EXPECT_NE(md.find("Newton iterations: 160 in all"), std::string::npos);
  EXPECT_NE(md.find("assembly 8 s (40 %), linear solve 10 s (50 %)"), std::string::npos) << md;
  EXPECT_NE(md.find("the paper's 14.7 min on 2 processes"), std::string::npos);

  // Results: known QoIs with units, others listed, notes shown.
  EXPECT_EQ(md_row(md, "stent_diameter_max").at(1), "2.6");
  EXPECT_EQ(md_row(md, "stent_diameter_max").at(2), "mm");
  EXPECT_NE(md.find("| contact_model | penalty |"), std::string::npos);
  EXPECT_NE(md.find("orthotropic membrane-like hex8 layer"), std::string::npos);

  // Figures: drawn from present columns, PNG and SVG; the layer stresses are absent.
  for (const char* name : {"stent_diameter_vs_pressure", "stent_diameter_over_time", "dogboning_over_time", "contact_forces_over_time",
                           "pressures_over_time", "newton_iterations", "balloon_profile"}) {
    EXPECT_TRUE(fs::exists(f.figures / (std::string(name) + ".png"))) << name;
    EXPECT_TRUE(fs::exists(f.figures / (std::string(name) + ".svg"))) << name;
    EXPECT_NE(md.find(fmt::format("](figures/{}.png)", name)), std::string::npos) << name;
  }
  EXPECT_FALSE(fs::exists(f.figures / "layer_stresses_over_time.png"));
  EXPECT_NE(md.find("Maximum principal stress per layer over the run: history.csv has no max_principal_<layer>_kpa"), std::string::npos);
  EXPECT_EQ(qoi(out, "report_figures"), 7);
  EXPECT_EQ(qoi(out, "report_figures_omitted"), 1);

  // 3-D frames: initial, the end of the inflation (t = 1) and after, per body.
  EXPECT_NE(md.find("| max (end of inflation) | 1 | stent | solve/results/stent_00002.vtu |"), std::string::npos) << md;
  EXPECT_NE(md.find("| after (last frame) | 2 | balloon | solve/results/balloon_00004.vtu |"), std::string::npos);
  EXPECT_NE(md.find("solve/results.pvd"), std::string::npos);
  cleanup(f);
}

TEST(Report, AnotherPressureIsShownNotJudged) {
  Fixture f = make_fixture("pressure");
  f.in.pressure_max = 13 * 0.101325;
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const std::string md = read(f.md);
  EXPECT_TRUE(starts_with(verdict_of(md, "diameter_at_max_pressure"), "different pressure")) << md;
  EXPECT_TRUE(starts_with(verdict_of(md, "diameter_after_deflation"), "different pressure"));
  EXPECT_TRUE(starts_with(verdict_of(md, "elastic_recoil_percent"), "not computed"));
  EXPECT_NE(md.find("not to the pressure of the paper's numbers (1.01 MPa"), std::string::npos);
  EXPECT_EQ(qoi(out, "targets_judged"), 0);
  EXPECT_EQ(qoi(out, "pressure_matches_paper"), 0);
  cleanup(f);
}

TEST(Report, GenericArteryConvertsUnitsAndKeepsInconsistentRowsUnjudged) {
  FixtureOptions o;
  o.artery_columns = true;
  Fixture f = make_fixture("artery", o);
  f.in.scene = "generic-artery";
  f.in.targets_key = "generic_artery_case1";
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const std::string md = read(f.md);
  const auto peak = md_row(md, "peak_max_principal_at_max_pressure_MPa");
  ASSERT_EQ(peak.size(), 6u) << md;
  EXPECT_EQ(peak[3], "8.1 MPa");
  EXPECT_TRUE(starts_with(peak[5], "report only"));
  EXPECT_TRUE(starts_with(verdict_of(md, "prestress_max_principal_media_kPa"), "inconsistent in paper"));
  EXPECT_TRUE(starts_with(verdict_of(md, "adventitia_max_principal_at_max_pressure_kPa"), "pass"));
  EXPECT_TRUE(starts_with(verdict_of(md, "adventitia_max_principal_after_kPa"), "FAIL"));
  EXPECT_TRUE(starts_with(verdict_of(md, "prestress_max_displacement"), "pass"));
  EXPECT_TRUE(starts_with(verdict_of(md, "media_max_principal_after_kPa"), "not computed"));
  // Why a row is not judged is said.
  EXPECT_NE(md.find("hoop equilibrium"), std::string::npos);
  EXPECT_NE(md.find("never a pass criterion"), std::string::npos);
  // With an artery the layer stresses are drawn, and the inflation column is not the diastolic one.
  EXPECT_TRUE(fs::exists(f.figures / "layer_stresses_over_time.png"));
  EXPECT_NE(md.find("x: pressure_inflation"), std::string::npos);
  // Passed: adventitia at max, prestress displacement; failed: both diameters (Case 1's are smaller), adventitia after.
  EXPECT_EQ(qoi(out, "targets_passed"), 2);
  EXPECT_EQ(qoi(out, "targets_failed"), 3);
  cleanup(f);
}

TEST(Report, PatientNumbersAreShownForScaleOnly) {
  FixtureOptions o;
  o.artery_columns = true;
  Fixture f = make_fixture("patient", o);
  f.in.scene = "patient";
  f.in.targets_key = "patient_case2";
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const std::string md = read(f.md);
  const auto media = md_row(md, "media_at_max_kPa");
  ASSERT_EQ(media.size(), 6u) << md;
  EXPECT_EQ(media[1], "78.3 kPa");
  EXPECT_EQ(media[3], "8100 kPa");
  EXPECT_TRUE(starts_with(media[5], "report only"));
  EXPECT_TRUE(starts_with(verdict_of(md, "stent_bending_moment_max_Nmm"), "not computed"));
  EXPECT_NE(md.find("another geometry"), std::string::npos);
  EXPECT_NE(md.find("the paper's 23.4 h on 20 processes"), std::string::npos) << md;
  EXPECT_EQ(qoi(out, "targets_judged"), 0);
  cleanup(f);
}

TEST(Report, FiguresWithoutDataAreOmittedAndSaidSo) {
  FixtureOptions o;
  o.device_columns = false;
  o.balloon_profile = false;
  Fixture f = make_fixture("bare", o);
  f.in.targets_key = "";  // no paper numbers
  write(f.figures / "contact_forces_over_time.png", "from an earlier run");
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const std::string md = read(f.md);
  EXPECT_TRUE(fs::exists(f.figures / "newton_iterations.png"));
  for (const char* name : {"stent_diameter_vs_pressure", "stent_diameter_over_time", "dogboning_over_time", "contact_forces_over_time",
                           "layer_stresses_over_time", "pressures_over_time", "balloon_profile"})
    EXPECT_FALSE(fs::exists(f.figures / (std::string(name) + ".png"))) << name;
  EXPECT_NE(md.find("Stent diameter against inflation pressure: history.csv has no inflation pressure column"), std::string::npos) << md;
  EXPECT_NE(md.find("Contact forces over the run: history.csv has no contact_<pair>_force values"), std::string::npos);
  EXPECT_NE(md.find("Balloon profile: solve/summary.yaml has no balloon_profile_z list"), std::string::npos);
  EXPECT_NE(md.find("The frame at max pressure is not known"), std::string::npos);
  EXPECT_NE(md.find("This case has no paper numbers"), std::string::npos);
  EXPECT_EQ(out.qois().count("targets_judged"), 0u);
  EXPECT_EQ(qoi(out, "report_figures"), 1);
  EXPECT_EQ(qoi(out, "report_figures_omitted"), 7);
  cleanup(f);
}

TEST(Report, DamagedInputsAreInputErrorsNamingTheFileAndLine) {
  Fixture f = make_fixture("errors");
  const fs::path history = f.solve / "history.csv";
  const std::string good = read(history);
  Summary out;
  auto run = [&] { write_report(f.in, f.md, f.html, f.figures, out); };

  // Line 3 (the second step) gets a word in its time column.
  std::string bad = good;
  auto line3 = bad.find('\n', bad.find('\n') + 1) + 1;
  auto comma = bad.find(',', line3);
  bad.replace(comma + 1, bad.find(',', comma + 1) - comma - 1, "fast");
  write(history, bad);
  std::string e = error_of(run);
  EXPECT_NE(e.find(history.string() + ":3:"), std::string::npos) << e;
  EXPECT_NE(e.find("'time'"), std::string::npos) << e;
  EXPECT_NE(e.find("'fast'"), std::string::npos) << e;
  EXPECT_NE(e.find("not a number"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(f.md)) << "nothing is written from a damaged input";

  // Line 4 loses its last cell.
  bad = good;
  auto line4 = bad.find('\n', line3) + 1;
  auto eol = bad.find('\n', line4);
  bad.erase(bad.rfind(',', eol), eol - bad.rfind(',', eol));
  write(history, bad);
  e = error_of(run);
  EXPECT_NE(e.find(history.string() + ":4:"), std::string::npos) << e;
  EXPECT_NE(e.find("values, but the header has"), std::string::npos) << e;

  // A required column missing from the header.
  write(history, "step,time\n1,0.1\n");
  e = error_of(run);
  EXPECT_NE(e.find(history.string() + ":1:"), std::string::npos) << e;
  EXPECT_NE(e.find("newton_iterations"), std::string::npos) << e;

  fs::remove(history);
  e = error_of(run);
  EXPECT_NE(e.find(history.string()), std::string::npos) << e;
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
  write(history, good);

  // The solve's summary.yaml missing, then damaged.
  const fs::path summary = f.solve / "summary.yaml";
  const std::string summary_text = read(summary);
  fs::remove(summary);
  e = error_of(run);
  EXPECT_NE(e.find(summary.string()), std::string::npos) << e;
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
  write(summary, "qoi: {a: [1, 2\n");
  e = error_of(run);
  EXPECT_NE(e.find(summary.string()), std::string::npos) << e;
  write(summary, summary_text);

  // A results.pvd frame without a number for its time.
  write(f.solve / "results.pvd", "<VTKFile><Collection><DataSet timestep=\"soon\" file=\"a.vtu\"/></Collection></VTKFile>");
  e = error_of(run);
  EXPECT_NE(e.find((f.solve / "results.pvd").string()), std::string::npos) << e;
  EXPECT_NE(e.find("'soon'"), std::string::npos) << e;

  // No manifest.
  fs::remove(f.work / "manifest.yaml");
  e = error_of(run);
  EXPECT_NE(e.find((f.work / "manifest.yaml").string()), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(f.md));
  cleanup(f);
}

TEST(Report, HtmlIsSelfContainedAndEscaped) {
  Fixture f = make_fixture("html");
  f.in.case_name = "rca <seed 1> & \"friends\"";
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const std::string html = read(f.html);
  EXPECT_NE(html.find("rca &lt;seed 1&gt; &amp; &quot;friends&quot;"), std::string::npos);
  EXPECT_EQ(html.find("<seed 1>"), std::string::npos);
  // Nothing loaded from elsewhere: no scripts, style sheets, frames or remote URLs.
  for (const char* bad : {"<script", "<link", "<iframe", "http://", "https://", "url("}) EXPECT_EQ(html.find(bad), std::string::npos) << bad;
  // Every image is an inline PNG.
  // (std::regex recurses per character and overflows the stack on a base64 payload.)
  int images = 0;
  for (std::size_t pos = html.find("<img"); pos != std::string::npos; pos = html.find("<img", pos + 1)) {
    const auto tag_end = html.find('>', pos);
    const auto src_at = html.find("src=\"", pos);
    ASSERT_TRUE(src_at != std::string::npos && src_at < tag_end) << "an <img> without src";
    const auto src_end = html.find('"', src_at + 5);
    const std::string src = html.substr(src_at + 5, src_end - src_at - 5);
    ASSERT_TRUE(starts_with(src, "data:image/png;base64,")) << src.substr(0, 80);
    EXPECT_TRUE(is_png(base64_decode(src.substr(22)))) << "image " << images << " does not decode to a PNG";
    ++images;
  }
  EXPECT_EQ(images, 7);
  // base64 itself round-trips (all three padding cases).
  for (const std::string& s : std::vector<std::string>{"a", "ab", "abc", "abcd", std::string("\x89PNG\r\n\x1a\n", 8)}) {
    const auto d = base64_decode(base64(s));
    EXPECT_EQ(std::string(d.begin(), d.end()), s);
  }
  cleanup(f);
}

TEST(Report, ChromiumRendersTheHtml) {
  const char* chromium = "/usr/bin/chromium";
  if (!fs::exists(chromium)) GTEST_SKIP() << "Debian's chromium is not installed (apt-get install chromium; scripts/install-deps.sh lists it)";
  Fixture f = make_fixture("chromium");
  Summary out;
  write_report(f.in, f.md, f.html, f.figures, out);
  const fs::path shot = f.dir / "report.png";
  const std::string cmd = fmt::format(
      "timeout 60 {} --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir={} --screenshot={} "
      "--window-size=1200,1600 file://{} > {} 2>&1",
      chromium, (f.dir / "chromium-profile").string(), shot.string(), f.html.string(), (f.dir / "chromium.log").string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read(f.dir / "chromium.log");
  ASSERT_TRUE(fs::exists(shot)) << read(f.dir / "chromium.log");
  const auto img = decode_png(shot.string());
  ASSERT_TRUE(img) << shot << " is not an 8-bit RGB(A) PNG";
  EXPECT_EQ(img->width, 1200);
  EXPECT_EQ(img->height, 1600);
  // Not blank: text and table rules cover a share of the page, and dark text is there.
  std::size_t inked = 0, dark = 0;
  const std::size_t pixels = img->rgb.size() / 3;
  for (std::size_t i = 0; i < pixels; ++i) {
    const int r = img->rgb[3 * i], g = img->rgb[3 * i + 1], b = img->rgb[3 * i + 2];
    if (r < 235 || g < 235 || b < 235) ++inked;
    if (r + g + b < 200) ++dark;
  }
  EXPECT_GT(static_cast<double>(inked) / pixels, 0.03) << "the screenshot " << shot << " looks blank";
  EXPECT_GT(static_cast<double>(dark) / pixels, 0.003) << "no text in the screenshot " << shot;
  std::cout << "screenshot: " << shot << "\n";
  cleanup(f);
}

}  // namespace

// The embedded copy of the paper's numbers is the shared validation file, word for word.
TEST(ReportTargets, EmbeddedCopyMatchesTheSharedValidationFile) {
  const char* shared = std::getenv("STENTSIM_SHARED_DIR");
  if (!shared) GTEST_SKIP() << "no shared folder (../shared or /work/shared): nothing to compare with";
  auto text = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  const std::string ours = text(fs::path(STENTSIM_TEST_SOURCE_DIR) / "workflows/report/paper_targets.yaml");
  ASSERT_FALSE(ours.empty());
  EXPECT_EQ(ours, text(fs::path(shared) / "validation/targets.yaml"))
      << "workflows/report/paper_targets.yaml differs from the shared validation/targets.yaml: copy it again";
}
