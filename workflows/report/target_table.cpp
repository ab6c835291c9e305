#include "workflows/report/target_table.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "common/units.hpp"

namespace stentsim::workflows::report {
namespace {

constexpr const char* kPatient = "another geometry (the paper's patient is not public): for scale only";
constexpr const char* kSingular =
    "the lumen layer's Gauss-point peak sits under a strut's line load: singular, moves with the mesh and the penalty "
    "(DESIGN.md §8), so it is never a pass criterion";

std::string num(double v) { return fmt::format("{:.4g}", v); }

std::string with_unit(const std::string& value, const std::string& unit) {
  return unit.empty() ? value : value + (unit == "%" ? "" : " ") + unit;
}

std::string normalised_unit(std::string u) {
  std::string out;
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (u[i] == ' ' || u[i] == '*') continue;
    if (u.compare(i, 2, "\xC2\xB7") == 0) {  // the middle dot of "N·mm"
      ++i;
      continue;
    }
    out += u[i];
  }
  return out;
}

}  // namespace

const std::vector<TargetMapping>& target_mappings() {
  // clang-format off
  static const std::vector<TargetMapping> table = {
    {"free_expansion_straight", "diameter_at_max_pressure", {"stent_diameter_max"}, "mm", false, true, ""},
    {"free_expansion_straight", "diameter_after_deflation", {"stent_diameter_after"}, "mm", false, true, ""},
    {"free_expansion_straight", "elastic_recoil_percent", {"recoil_percent"}, "%", false, true, ""},
    {"free_expansion_straight", "dogboning_ratio_percent_at_10_4_atm", {"dogboning_percent"}, "%", false, true,
     "ours: the maximum over the inflation, at dogboning_pressure (results table)"},
    {"free_expansion_straight", "manufacturer_diameter_at_13_atm", {"stent_diameter_max"}, "mm", true, true,
     "the manufacturer's compliance chart at 13 atm (1.317 MPa), not a simulation: for orientation"},

    {"free_expansion_curved", "straightening",
     {"stent_centroid_curvature_initial", "stent_centroid_curvature_max", "stent_centroid_curvature_after"}, "1/mm", true, true,
     "a statement, not a number: the centerline straightens when the curvature at max and after is below the initial one"},
    {"free_expansion_curved", "diameters", {"stent_diameter_max", "stent_diameter_after"}, "mm", true, true,
     "a statement, not a number: compare with the straight device (paper 2.59 mm at max, 2.31 mm after)"},
    {"free_expansion_curved", "load_steps", {"steps"}, "", true, false, "a setting of the paper's run, not a result"},

    {"generic_artery_case1", "prestress_max_displacement", {"artery_max_displacement_prestress"}, "mm", false, false, ""},
    {"generic_artery_case1", "prestress_max_principal_media_kPa", {"max_principal_media_prestress_kpa"}, "kPa", false, false, ""},
    {"generic_artery_case1", "prestress_max_principal_adventitia_kPa", {"max_principal_adventitia_prestress_kpa"}, "kPa", false, false,
     "the paper's prestress stresses violate hoop equilibrium (85 mmHg on this tube needs a mean hoop stress of about 15 kPa)"},
    {"generic_artery_case1", "stent_diameter_at_max_pressure", {"stent_diameter_max"}, "mm", false, true, ""},
    {"generic_artery_case1", "stent_diameter_after_deflation", {"stent_diameter_after"}, "mm", false, true, ""},
    {"generic_artery_case1", "elastic_recoil_percent", {"recoil_percent"}, "%", false, true, ""},
    {"generic_artery_case1", "peak_max_principal_at_max_pressure_MPa", {"max_principal_media_max_kpa"}, "MPa", true, true, ""},
    {"generic_artery_case1", "adventitia_max_principal_at_max_pressure_kPa", {"max_principal_adventitia_max_kpa"}, "kPa", false, true, ""},
    {"generic_artery_case1", "media_max_principal_after_kPa", {"max_principal_media_after_kpa"}, "kPa", true, true, kSingular},
    {"generic_artery_case1", "adventitia_max_principal_after_kPa", {"max_principal_adventitia_after_kpa"}, "kPa", false, true, ""},

    {"patient_case2", "endothelium_peak_at_max_pressure_kPa", {"max_principal_endothelium_max_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "endothelium_prestressed_kPa", {"max_principal_endothelium_prestress_kpa"}, "kPa", true, false, kPatient},
    {"patient_case2", "endothelium_after_kPa", {"max_principal_endothelium_after_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "media_at_max_kPa", {"max_principal_media_max_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "adventitia_at_max_kPa", {"max_principal_adventitia_max_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "media_after_kPa", {"max_principal_media_after_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "adventitia_after_kPa", {"max_principal_adventitia_after_kpa"}, "kPa", true, true, kPatient},
    {"patient_case2", "stent_bending_moment_max_Nmm", {"stent_bending_moment_max_max"}, "N mm", true, true, kPatient},
    {"patient_case2", "stent_bending_moment_after_max_Nmm", {"stent_bending_moment_max_after"}, "N mm", true, true, kPatient},
    {"patient_case2", "contact_line_load_max_N_per_mm", {"contact_line_load_max_stent_artery_max"}, "N/mm", true, true, kPatient},
    {"patient_case2", "contact_line_load_after_max_N_per_mm", {"contact_line_load_max_stent_artery_after"}, "N/mm", true, true, kPatient},
  };
  // clang-format on
  return table;
}

const TargetMapping* find_mapping(const std::string& example, const std::string& target) {
  for (const auto& m : target_mappings())
    if (m.example == example && m.target == target) return &m;
  return nullptr;
}

std::string verdict_text(Verdict v) {
  switch (v) {
    case Verdict::pass: return "pass";
    case Verdict::fail: return "FAIL";
    case Verdict::report_only: return "report only";
    case Verdict::inconsistent: return "inconsistent in paper";
    case Verdict::not_computed: return "not computed";
    case Verdict::different_pressure: return "different pressure";
  }
  return "?";
}

std::optional<double> convert_unit(double value, const std::string& from, const std::string& to) {
  const std::string f = normalised_unit(from), t = normalised_unit(to);
  if (f.empty() || f == t) return value;
  try {
    const auto uf = units::parse_unit(f), ut = units::parse_unit(t);
    if (!(uf.dim == ut.dim)) return std::nullopt;
    return value * uf.factor / ut.factor;
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

PressureCheck check_pressure(const PaperCase& paper, double p) {
  PressureCheck c;
  const std::string ours = fmt::format("{:.4g} MPa ({:.3g} atm)", p, p / units::kAtmInMPa);
  if (!paper.pressure_max) {
    c.statement = p > 0 ? fmt::format("The targets give no inflation pressure for {}; the case inflates to {}.", paper.key, ours)
                        : fmt::format("The targets give no inflation pressure for {}, and the case's is not known.", paper.key);
    c.matches = p > 0;  // nothing to differ from: judge
    return c;
  }
  c.known = true;
  const double pp = *paper.pressure_max;
  std::string source = fmt::format("`{}`", paper.pressure_source);
  if (paper.pressure_shared) source += ", the pressure of every example in the paper";
  // The targets file notes that the paper calls 1.01 MPa "13 atm" as well, which is 1.317 MPa: say so.
  std::string aside;
  if (paper.pressure_comment.find("13 atm") != std::string::npos)
    aside = fmt::format(" The paper also writes this pressure as 13 atm, which is {:.4g} MPa; the numbers are compared at {:.4g} MPa.",
                        13 * units::kAtmInMPa, pp);
  if (p <= 0) {
    c.statement = fmt::format("The paper's numbers are at {:.4g} MPa ({}); the case's inflation pressure is not known, so the rows "
                              "that depend on it are not judged.{}",
                              pp, source, aside);
    return c;
  }
  // The paper's 1.01 MPa has three significant digits.
  c.matches = std::abs(p - pp) <= 0.005 * pp;
  if (c.matches)
    c.statement = fmt::format("The case inflates to {}, the pressure of the paper's numbers ({:.4g} MPa, {}): the rows are judged.{}",
                              ours, pp, source, aside);
  else
    c.statement = fmt::format("The case inflates to {}, not to the pressure of the paper's numbers ({:.4g} MPa, {}): rows that depend on "
                              "the inflation pressure are shown but judged \"different pressure\", not pass or fail.{}",
                              ours, pp, source, aside);
  return c;
}

TargetTable judge_targets(const PaperCase& paper, const Summary& ours, double case_pressure_max) {
  TargetTable t;
  t.pressure = check_pressure(paper, case_pressure_max);
  const auto& qois = ours.qois();
  for (const auto& r : paper.results) {
    TargetRow row;
    const TargetMapping* m = find_mapping(paper.key, r.name);
    const std::string unit = m ? m->paper_unit : "";
    row.quantity = m ? fmt::format("{} ({})", r.name, fmt::join(m->summary_keys, ", ")) : r.name;
    row.paper = r.value ? with_unit(fmt::format("{:g}", *r.value), unit) : "\"" + r.text + "\"";
    if (r.tolerance) row.tolerance = fmt::format("±{:g} % (relative)", *r.tolerance * 100);
    else if (r.tolerance_abs) row.tolerance = fmt::format("±{} (absolute)", with_unit(fmt::format("{:g}", *r.tolerance_abs), unit));
    // Why a row is judged so: the verdict's own reason first, then the mapping's note, then the targets file's comment.
    std::string why;
    auto add_why = [&](const std::string& s) { why = why.empty() ? s : why + "; " + s; };

    if (!m) {
      row.verdict = Verdict::not_computed;
      add_why("no summary quantity is mapped to this entry (workflows/report/target_table.cpp)");
    } else if (!r.value) {
      // A statement: list what we have for the reader to weigh.
      std::vector<std::string> parts;
      for (const auto& k : m->summary_keys) {
        auto it = qois.find(k);
        if (it == qois.end()) continue;
        if (auto d = std::get_if<double>(&it->second.value)) parts.push_back(fmt::format("{} = {}", k, with_unit(num(*d), it->second.unit)));
      }
      row.ours = fmt::format("{}", fmt::join(parts, "; "));
      row.verdict = parts.empty() ? Verdict::not_computed : Verdict::report_only;
      if (parts.empty()) add_why(fmt::format("the run did not compute {}", fmt::join(m->summary_keys, ", ")));
    } else {
      const std::string& key = m->summary_keys.front();
      auto it = qois.find(key);
      std::optional<double> value;
      if (it == qois.end()) {
        add_why(fmt::format("the run did not compute {}", key));
      } else if (auto d = std::get_if<double>(&it->second.value); !d) {
        add_why(fmt::format("{} in the summary is not a single number", key));
      } else if (!std::isfinite(*d)) {
        add_why(fmt::format("{} is {} (the run could not measure it)", key, *d));
      } else if (auto c = convert_unit(*d, it->second.unit, unit); !c) {
        add_why(fmt::format("{} is in '{}', which does not convert to the paper's '{}'", key, it->second.unit, unit));
      } else {
        value = c;
      }
      if (!value) {
        row.verdict = Verdict::not_computed;
      } else {
        const double diff = *value - *r.value;
        row.ours = with_unit(num(*value), unit);
        row.difference = with_unit(fmt::format("{:+.3g}", diff), unit);
        if (*r.value != 0) {
          const double rel = 100.0 * diff / std::abs(*r.value);
          row.difference += std::abs(rel) < 100 ? fmt::format(" ({:+.1f} % rel.)", rel) : fmt::format(" ({:+.0f} % rel.)", rel);
        }
        if (r.inconsistent) {
          row.verdict = Verdict::inconsistent;
          if (m->why.empty() && r.comment.empty()) add_why("the targets file marks the paper's number as inconsistent");
        } else if (r.report_only || m->report_only) {
          row.verdict = Verdict::report_only;
          if (m->why.empty() && r.comment.empty()) add_why("the targets file reports it, it does not judge it");
        } else if (!r.tolerance && !r.tolerance_abs) {
          row.verdict = Verdict::report_only;
          add_why("the targets file gives no tolerance");
        } else if (m->depends_on_pressure && !t.pressure.matches) {
          row.verdict = Verdict::different_pressure;
          add_why(case_pressure_max > 0 ? fmt::format("the case inflates to {:.4g} MPa", case_pressure_max)
                                        : std::string("the case's inflation pressure is not known"));
        } else {
          const double allowed = r.tolerance ? *r.tolerance * std::abs(*r.value) : *r.tolerance_abs;
          row.verdict = std::abs(diff) <= allowed ? Verdict::pass : Verdict::fail;
        }
      }
    }
    if (m && !m->why.empty()) add_why(m->why);
    if (!r.comment.empty()) add_why("paper_targets.yaml: " + r.comment);
    row.why = why;
    switch (row.verdict) {
      case Verdict::pass: ++t.passed; break;
      case Verdict::fail: ++t.failed; break;
      case Verdict::not_computed: ++t.not_computed; break;
      default: ++t.not_judged; break;
    }
    t.rows.push_back(std::move(row));
  }
  t.judged = t.passed + t.failed;
  return t;
}

}  // namespace stentsim::workflows::report
