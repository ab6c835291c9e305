#include "device_gen/placement_file.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::device_gen {
namespace {

void emit_list(YAML::Emitter& e, const std::vector<double>& v) {
  e << YAML::Flow << YAML::BeginSeq;
  for (double d : v) e << d;
  e << YAML::EndSeq;
}

void emit_point(YAML::Emitter& e, const Eigen::Vector3d& p) { emit_list(e, {p.x(), p.y(), p.z()}); }

struct Reader {
  std::filesystem::path file;
  YAML::Node root;
  YAML::Node at(const std::string& dotted) const {
    YAML::Node n = YAML::Clone(root);
    std::size_t start = 0;
    while (true) {
      const std::size_t dot = dotted.find('.', start);
      const std::string key = dotted.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (!n.IsMap() || !n[key]) throw InputError(fmt::format("{}: key '{}' is missing (not a stentsim placement file?)", file.string(), dotted));
      n = n[key];
      if (dot == std::string::npos) return n;
      start = dot + 1;
    }
  }
  double number(const std::string& k) const {
    try {
      return at(k).as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(fmt::format("{}: '{}' must be a number", file.string(), k));
    }
  }
  std::string text(const std::string& k) const { return at(k).as<std::string>(); }
  std::vector<double> list(const std::string& k) const {
    try {
      return at(k).as<std::vector<double>>();
    } catch (const YAML::Exception&) {
      throw InputError(fmt::format("{}: '{}' must be a list of numbers", file.string(), k));
    }
  }
  Eigen::Vector3d point(const std::string& k) const {
    const auto v = list(k);
    if (v.size() != 3) throw InputError(fmt::format("{}: '{}' must have 3 components", file.string(), k));
    return {v[0], v[1], v[2]};
  }
};

}  // namespace

void write_placement_yaml(const Placement& P, const std::filesystem::path& file) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << "stentsim-placement-1";
  e << YAML::Key << "units" << YAML::Value << "mm";
  e << YAML::Key << "centerline" << YAML::Value << P.centerline_file;
  e << YAML::Key << "site" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "chosen_by" << YAML::Value << P.site_chosen_by;
  e << YAML::Key << "abscissa" << YAML::Value << P.site_abscissa;
  e << YAML::Key << "point" << YAML::Value;
  emit_point(e, P.site_point);
  e << YAML::Key << "inscribed_radius" << YAML::Value << P.site_radius;
  e << YAML::Key << "smoothed_inscribed_radius" << YAML::Value << P.site_smoothed_radius;
  e << YAML::Key << "lumen_diameter" << YAML::Value << 2.0 * P.site_smoothed_radius;
  e << YAML::Key << "reference_radius" << YAML::Value << P.site_reference_radius;  // taper line; 0: not fitted
  e << YAML::Key << "reference_taper" << YAML::Value << P.reference_taper;
  e << YAML::Key << "percent_diameter_stenosis" << YAML::Value << P.percent_diameter_stenosis();
  e << YAML::EndMap;
  e << YAML::Key << "balloon" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "length" << YAML::Value << P.balloon_length;
  e << YAML::Key << "outer_diameter" << YAML::Value << P.balloon_outer_diameter;
  e << YAML::Key << "proximal_abscissa" << YAML::Value << P.proximal_abscissa;
  e << YAML::Key << "distal_abscissa" << YAML::Value << P.distal_abscissa;
  e << YAML::EndMap;
  e << YAML::Key << "stent" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "length" << YAML::Value << P.stent_length;
  e << YAML::Key << "envelope_diameter" << YAML::Value << P.stent_envelope_diameter;
  e << YAML::EndMap;
  e << YAML::Key << "fit" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "method" << YAML::Value
    << "FITPACK curfit (Dierckx), cubic, scipy UnivariateSpline semantics, per coordinate against abscissa";
  e << YAML::Key << "smoothing" << YAML::Value << P.smoothing;
  e << YAML::Key << "tolerance" << YAML::Value << P.smoothing_tolerance;
  e << YAML::Key << "spacing_requested" << YAML::Value << P.spacing_requested;
  e << YAML::Key << "spacing" << YAML::Value << P.spacing;
  e << YAML::Key << "abscissa_offset" << YAML::Value << P.proximal_abscissa;
  e << YAML::Key << "weight_iterations" << YAML::Value << P.weight_iterations;
  e << YAML::Key << "abscissae" << YAML::Value;
  emit_list(e, P.x);
  e << YAML::Key << "weights" << YAML::Value;
  emit_list(e, P.weights);
  e << YAML::Key << "points" << YAML::Value << YAML::BeginMap;
  for (int k = 0; k < 3; ++k) {
    e << YAML::Key << std::string(1, "xyz"[k]) << YAML::Value;
    emit_list(e, P.y[static_cast<std::size_t>(k)]);
  }
  e << YAML::EndMap;
  e << YAML::Key << "splines" << YAML::Value << YAML::BeginMap;
  for (int k = 0; k < 3; ++k) {
    const auto& f = P.fits[static_cast<std::size_t>(k)];
    e << YAML::Key << std::string(1, "xyz"[k]) << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "degree" << YAML::Value << f.spline.degree;
    e << YAML::Key << "knots" << YAML::Value;
    emit_list(e, f.spline.knots);
    e << YAML::Key << "coefficients" << YAML::Value;
    emit_list(e, f.spline.coefficients);
    e << YAML::Key << "residual" << YAML::Value << f.residual;
    e << YAML::Key << "ier" << YAML::Value << f.ier;
    e << YAML::Key << "condition_met" << YAML::Value << f.condition_met();
    e << YAML::Key << "note" << YAML::Value << fitpack::describe_ier(f.ier);
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  e << YAML::EndMap;
  e << YAML::Key << "clearance" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "method" << YAML::Value << P.clearance_method;
  e << YAML::Key << "min" << YAML::Value << P.clearance_min;
  e << YAML::Key << "at_abscissa" << YAML::Value << P.proximal_abscissa + P.clearance_at;
  e << YAML::Key << "margin" << YAML::Value << P.clearance_margin;
  e << YAML::EndMap;
  e << YAML::Key << "frame" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "initial_normal" << YAML::Value;
  emit_point(e, P.initial_normal);
  e << YAML::EndMap;
  e << YAML::EndMap;
  files::write_atomic(file, std::string(e.c_str()) + "\n");
}

Placement read_placement_yaml(const std::filesystem::path& file) {
  Reader r{file, {}};
  try {
    r.root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& ex) {
    throw InputError(fmt::format("{}: not a readable YAML file ({})", file.string(), ex.what()));
  }
  if (r.text("format") != "stentsim-placement-1")
    throw InputError(fmt::format("{}: format '{}' is not stentsim-placement-1", file.string(), r.text("format")));
  Placement P;
  P.centerline_file = r.text("centerline");
  P.site_chosen_by = r.text("site.chosen_by");
  P.site_abscissa = r.number("site.abscissa");
  P.site_point = r.point("site.point");
  P.site_radius = r.number("site.inscribed_radius");
  P.site_smoothed_radius = r.number("site.smoothed_inscribed_radius");
  // The taper reference came later: files written before it lack the keys.
  if (r.root["site"] && r.root["site"]["reference_radius"]) {
    P.site_reference_radius = r.number("site.reference_radius");
    P.reference_taper = r.number("site.reference_taper");
  }
  P.balloon_length = r.number("balloon.length");
  P.balloon_outer_diameter = r.number("balloon.outer_diameter");
  P.proximal_abscissa = r.number("balloon.proximal_abscissa");
  P.distal_abscissa = r.number("balloon.distal_abscissa");
  P.stent_length = r.number("stent.length");
  P.stent_envelope_diameter = r.number("stent.envelope_diameter");
  P.smoothing = r.number("fit.smoothing");
  P.smoothing_tolerance = r.number("fit.tolerance");
  P.spacing_requested = r.number("fit.spacing_requested");
  P.spacing = r.number("fit.spacing");
  P.weight_iterations = static_cast<int>(r.number("fit.weight_iterations"));
  P.x = r.list("fit.abscissae");
  P.weights = r.list("fit.weights");
  for (int k = 0; k < 3; ++k) {
    const std::string c(1, "xyz"[k]);
    P.y[static_cast<std::size_t>(k)] = r.list("fit.points." + c);
    auto& f = P.fits[static_cast<std::size_t>(k)];
    f.spline.degree = static_cast<int>(r.number("fit.splines." + c + ".degree"));
    f.spline.knots = r.list("fit.splines." + c + ".knots");
    f.spline.coefficients = r.list("fit.splines." + c + ".coefficients");
    f.residual = r.number("fit.splines." + c + ".residual");
    f.ier = static_cast<int>(r.number("fit.splines." + c + ".ier"));
    f.smoothing = P.smoothing;
    f.tolerance = P.smoothing_tolerance;
    const std::size_t n = f.spline.knots.size();
    if (f.spline.degree != 3 || n < 8 || f.spline.coefficients.size() != n - 4)
      throw InputError(fmt::format("{}: fit.splines.{} must be a cubic with n >= 8 knots and n - 4 coefficients", file.string(), c));
  }
  P.clearance_method = r.text("clearance.method");
  P.clearance_min = r.number("clearance.min");
  P.clearance_at = r.number("clearance.at_abscissa") - P.proximal_abscissa;
  P.clearance_margin = r.number("clearance.margin");
  P.initial_normal = r.point("frame.initial_normal");
  if (!(P.balloon_length > 0)) throw InputError(fmt::format("{}: balloon.length must be positive", file.string()));
  return P;
}

DeviceAxis axis_from_placement(const Placement& P) {
  return DeviceAxis::along(P.curve(), 0.5 * P.balloon_length, P.balloon_length, P.initial_normal);
}

MeshData axis_polyline(const DeviceAxis& axis, double step) {
  MeshData m;
  const int n = std::max(2, static_cast<int>(std::ceil(axis.length() / step)));
  DataArray s{1, {}}, t{3, {}}, nrm{3, {}}, k{1, {}};
  std::vector<std::int64_t> ids;
  for (int i = 0; i <= n; ++i) {
    const double sigma = axis.length() * i / n;
    const AxisFrame f = axis.frame(sigma);
    m.points.push_back(f.position);
    s.values.push_back(sigma);
    t.values.insert(t.values.end(), {f.tangent.x(), f.tangent.y(), f.tangent.z()});
    nrm.values.insert(nrm.values.end(), {f.normal.x(), f.normal.y(), f.normal.z()});
    k.values.push_back(f.curvature.norm());
    ids.push_back(i);
  }
  m.add_cell(CellType::polyline, ids);
  m.point_data["Abscissas"] = std::move(s);
  m.point_data["Tangents"] = std::move(t);
  m.point_data["ParallelTransportNormals"] = std::move(nrm);
  m.point_data["Curvature"] = std::move(k);
  m.field_text["units"] = "mm";
  m.field_text["description"] = "stentsim balloon centerline: device axis by arc length from the balloon's proximal end";
  return m;
}

}  // namespace stentsim::device_gen
