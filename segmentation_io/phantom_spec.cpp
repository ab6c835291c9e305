// Phantom presets and the `phantom:` config section.
#include <fmt/format.h>

#include <cmath>

#include "common/error.hpp"
#include "segmentation_io/phantom.hpp"

namespace stentsim::segmentation {

const char* to_string(PhantomCurve c) {
  switch (c) {
    case PhantomCurve::straight: return "straight";
    case PhantomCurve::arc: return "arc";
    case PhantomCurve::helix: return "helix";
  }
  return "?";
}

const std::vector<std::string>& phantom_preset_names() {
  static const std::vector<std::string> names = {"straight-healthy", "case2-rca", "severe-70", "tortuous"};
  return names;
}

PhantomSpec phantom_preset(const std::string& name, unsigned seed) {
  PhantomSpec s;
  s.preset = name;
  s.seed = seed;
  if (name == "straight-healthy") {
    // A healthy 2.5 mm coronary segment, wall 0.5 mm.
    s.curve = PhantomCurve::straight;
    s.length = 20.0;
    s.reference_radius = 1.25;
    s.stenosis_severity = 0.0;
    s.wall_thickness_proximal = s.wall_thickness_distal = 0.5;
  } else if (name == "case2-rca") {
    // Paper Case 2 (Sec. 4.2) as settled in DESIGN.md §8: ~21 mm proximal RCA,
    // 1.9 mm reference lumen, ~20 % obstruction (1.52 mm throat), curved with a
    // radius of curvature of ~10 mm, eccentric plaque with positive remodeling,
    // total wall 0.7–1.8 mm.
    s.curve = PhantomCurve::arc;
    s.length = 21.0;
    s.radius_of_curvature = 10.0;
    s.waviness = 0.1;
    s.reference_radius = 0.95;
    s.stenosis_severity = 20.0;
    s.stenosis_length = 9.0;
    s.stenosis_position = 0.5;
    s.eccentricity = 0.7;
    s.wall_thickness_proximal = 0.7;
    s.wall_thickness_distal = 0.9;
    s.remodeling = 0.7;
  } else if (name == "severe-70") {
    // 70 % diameter stenosis; deliberately narrower (0.75 mm) than the crimped
    // device's 1.27 mm envelope (DESIGN.md §8: exercises the placement error).
    s.curve = PhantomCurve::arc;
    s.length = 24.0;
    s.radius_of_curvature = 25.0;
    s.reference_radius = 1.25;
    s.stenosis_severity = 70.0;
    s.stenosis_length = 8.0;
    s.stenosis_position = 0.5;
    s.eccentricity = 0.3;
    s.wall_thickness_proximal = s.wall_thickness_distal = 0.5;
    s.remodeling = 0.3;
  } else if (name == "tortuous") {
    // A helical segment whose radius of curvature is 5 mm everywhere.
    s.curve = PhantomCurve::helix;
    s.length = 30.0;
    s.radius_of_curvature = 5.0;
    s.helix_pitch = 12.0;
    s.reference_radius = 0.9;
    s.stenosis_severity = 40.0;
    s.stenosis_length = 6.0;
    s.stenosis_position = 0.45;
    s.eccentricity = 0.4;
    s.wall_thickness_proximal = s.wall_thickness_distal = 0.5;
    s.remodeling = 0.2;
  } else {
    std::string list;
    for (const auto& n : phantom_preset_names()) list += (list.empty() ? "" : ", ") + n;
    throw InputError(fmt::format("unknown phantom preset '{}'; expected one of: {}", name, list));
  }
  return s;
}

void validate(const PhantomSpec& s) {
  auto bad = [&](const std::string& field, const std::string& why) {
    throw InputError(fmt::format("phantom '{}': {} {}", s.preset, field, why));
  };
  if (!(s.length > 0)) bad("length", "must be positive");
  if (!(s.reference_radius > 0)) bad("reference_radius", "must be positive");
  if (s.stenosis_severity < 0 || s.stenosis_severity >= 95) bad("stenosis_severity", "must be in [0, 95) % diameter");
  if (s.stenosis_severity > 0) {
    if (!(s.stenosis_length > 0)) bad("stenosis_length", "must be positive");
    double a = s.stenosis_position * s.length - 0.5 * s.stenosis_length;
    double b = s.stenosis_position * s.length + 0.5 * s.stenosis_length;
    if (a < 0 || b > s.length)
      bad("stenosis_position", fmt::format("puts the narrowing ({:.3g}..{:.3g} mm) outside the segment (0..{:.3g} mm)",
                                           a, b, s.length));
    // The canal surface needs |dr/ds| < 1 (spheres must not swallow each other).
    double slope = 0.5 * s.stenosis_severity / 100 * s.reference_radius * 2 * M_PI / s.stenosis_length;
    if (slope > 0.8) bad("stenosis_length", fmt::format("is too short for this severity (lumen slope {:.2f} > 0.8)", slope));
  }
  if (s.eccentricity < 0 || s.eccentricity >= 1) bad("eccentricity", "must be in [0, 1)");
  if (s.wall_thickness_proximal <= 0 || s.wall_thickness_distal <= 0) bad("wall_thickness", "must be positive");
  if (s.remodeling < 0) bad("remodeling", "must be non-negative");
  if (s.circumferential_points < 8 || s.circumferential_points > 4096) bad("circumferential_points", "must be in [8, 4096]");
  if (s.axial_spacing < 0) bad("axial_spacing", "must be non-negative");
  if (s.waviness < 0) bad("waviness", "must be non-negative");
  double outer = s.reference_radius + std::max(s.wall_thickness_proximal, s.wall_thickness_distal) + s.remodeling;
  if (s.curve != PhantomCurve::straight) {
    if (!(s.radius_of_curvature > 0)) bad("radius_of_curvature", "must be positive");
    if (outer >= 0.9 * s.radius_of_curvature)
      bad("radius_of_curvature", fmt::format("({} mm) must exceed the outer wall radius ({:.3g} mm) by 10 % or the wall "
                                             "folds through itself", s.radius_of_curvature, outer));
  }
  if (s.curve == PhantomCurve::helix) {
    double b = s.helix_pitch / (2 * M_PI);
    if (!(s.helix_pitch > 0) || s.radius_of_curvature < 2 * b)
      bad("helix_pitch", fmt::format("must be in (0, π·radius_of_curvature = {:.3g} mm] for a helix of that curvature",
                                     M_PI * s.radius_of_curvature));
    if (s.helix_pitch < 2.2 * outer)
      bad("helix_pitch", fmt::format("({} mm) lets neighbouring turns of the wall ({:.3g} mm outer radius) touch",
                                     s.helix_pitch, outer));
  }
}

PhantomSpec parse_phantom(ConfigMap& section) {
  std::string preset = section.choice("preset", phantom_preset_names(), std::string("case2-rca"));
  int seed = section.integer("seed", 1, Range::non_negative());
  PhantomSpec s = phantom_preset(preset, static_cast<unsigned>(seed));
  using units::kLength;
  auto len = [&](const char* key, double& v, Range r = Range::positive()) {
    if (section.has(key)) v = section.quantity(key, kLength, std::nullopt, r);
  };
  auto num = [&](const char* key, double& v, Range r) {
    if (section.has(key)) v = section.number(key, std::nullopt, r);
  };
  if (section.has("curve")) {
    auto c = section.choice("curve", {"straight", "arc", "helix"});
    s.curve = c == "straight" ? PhantomCurve::straight : c == "arc" ? PhantomCurve::arc : PhantomCurve::helix;
  }
  len("length", s.length);
  len("radius_of_curvature", s.radius_of_curvature);
  len("helix_pitch", s.helix_pitch);
  len("waviness", s.waviness, Range::non_negative());
  len("reference_radius", s.reference_radius);
  num("stenosis_severity", s.stenosis_severity, {0.0, 95.0, true, false});
  len("stenosis_length", s.stenosis_length);
  num("stenosis_position", s.stenosis_position, Range::between(0, 1));
  num("eccentricity", s.eccentricity, {0.0, 1.0, true, false});
  if (section.has("plaque_angle")) s.plaque_angle = section.quantity("plaque_angle", units::kAngle, std::nullopt, Range::between(0, 2 * M_PI));
  len("wall_thickness_proximal", s.wall_thickness_proximal);
  len("wall_thickness_distal", s.wall_thickness_distal);
  len("remodeling", s.remodeling, Range::non_negative());
  if (section.has("circumferential_points"))
    s.circumferential_points = section.integer("circumferential_points", std::nullopt, Range::between(8, 4096));
  len("axial_spacing", s.axial_spacing);
  section.finish();
  try {
    validate(s);
  } catch (const InputError& e) {
    section.fail("", e.what());
  }
  return s;
}

}  // namespace stentsim::segmentation
