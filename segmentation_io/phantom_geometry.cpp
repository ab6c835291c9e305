// Phantom geometry: vessel axis, canal-surface lumen, outer wall, true centerline.
// See phantom.hpp for why the lumen is a canal surface.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "common/error.hpp"
#include "common/log.hpp"
#include "segmentation_io/phantom.hpp"
#include "segmentation_io/polyline_frames.hpp"

namespace stentsim::segmentation {
namespace {

using Eigen::Vector3d;

// Portable uniform [0,1) from mt19937 (std distributions differ between libraries).
double uniform01(std::mt19937& g) { return double(g()) / 4294967296.0; }

// The base curve, parametrized by its arc length u.
Vector3d base_curve(const PhantomSpec& s, double u) {
  switch (s.curve) {
    case PhantomCurve::straight:
      return {0, 0, u};
    case PhantomCurve::arc: {
      double R = s.radius_of_curvature;
      return {R * (1 - std::cos(u / R)), 0, R * std::sin(u / R)};
    }
    case PhantomCurve::helix: {
      // Curvature a/(a²+b²) = 1/Rc with b = pitch/2π; the wider of the two
      // helices (larger a) keeps the turns apart.
      double Rc = s.radius_of_curvature, b = s.helix_pitch / (2 * M_PI);
      double a = 0.5 * (Rc + std::sqrt(std::max(0.0, Rc * Rc - 4 * b * b)));
      double phi = u / std::sqrt(a * a + b * b);
      return {a * std::cos(phi) - a, a * std::sin(phi), b * phi};
    }
  }
  return {0, 0, u};
}

// Cosine bump: 1 at the throat, 0 outside the narrowing, C¹ everywhere.
double bump(const PhantomSpec& s, double u) {
  if (s.stenosis_severity <= 0) return 0;
  double x = (u - s.stenosis_position * s.length) / s.stenosis_length;
  if (std::abs(x) >= 0.5) return 0;
  return 0.5 * (1 + std::cos(2 * M_PI * x));
}

}  // namespace

PhantomGeometry build_phantom(const PhantomSpec& s) {
  validate(s);
  std::mt19937 rng(s.seed);
  const double psi = s.plaque_angle >= 0 ? s.plaque_angle : 2 * M_PI * uniform01(rng);
  const double ph1 = 2 * M_PI * uniform01(rng), ph2 = 2 * M_PI * uniform01(rng);
  const double lam1 = s.length * (0.6 + 0.3 * uniform01(rng)), lam2 = s.length * (0.8 + 0.4 * uniform01(rng));

  // Fine samples of the axis parameter (0.005 mm): derivatives by central
  // differences are then exact to ~1e-8 mm for these smooth curves.
  const int M = std::max(200, int(std::ceil(s.length / 0.005)));
  const double du = s.length / M;
  std::vector<Vector3d> base(M + 1);
  for (int i = 0; i <= M; ++i) base[i] = base_curve(s, i * du);
  Frames bf = parallel_transport_frames(base);
  std::vector<Vector3d> axis(M + 1);
  for (int i = 0; i <= M; ++i) {
    double u = i * du;
    double w1 = s.waviness * (std::sin(2 * M_PI * u / lam1 + ph1) - std::sin(ph1));
    double w2 = s.waviness * (std::sin(2 * M_PI * u / lam2 + ph2) - std::sin(ph2));
    axis[i] = base[i] + w1 * bf.normal[i] + w2 * bf.binormal[i];
  }
  Frames af = parallel_transport_frames(axis);

  // Lumen spine γ = c − δ n and radius r.
  const double R0 = s.reference_radius, S = s.stenosis_severity / 100.0;
  std::vector<Vector3d> spine(M + 1);
  std::vector<double> r(M + 1), rout(M + 1);
  std::vector<Vector3d> plaque(M + 1);
  for (int i = 0; i <= M; ++i) {
    double u = i * du, b = bump(s, u);
    r[i] = R0 * (1 - S * b);
    plaque[i] = std::cos(psi) * af.normal[i] + std::sin(psi) * af.binormal[i];
    spine[i] = axis[i] - s.eccentricity * (R0 - r[i]) * plaque[i];
    double t = s.wall_thickness_proximal + (s.wall_thickness_distal - s.wall_thickness_proximal) * u / s.length;
    rout[i] = R0 + t + s.remodeling * b;
  }
  Frames sf = parallel_transport_frames(spine);
  std::vector<double> speed(M + 1), drds(M + 1);
  for (int i = 0; i <= M; ++i) {
    int a = std::max(0, i - 1), b = std::min(M, i + 1);
    speed[i] = (spine[b] - spine[a]).norm() / ((b - a) * du);
    drds[i] = (r[b] - r[a]) / ((b - a) * du) / speed[i];
  }
  std::vector<double> sigma = cumulative_length(spine);

  PhantomGeometry g;
  const int N = s.circumferential_points;
  const double h = s.axial_spacing > 0 ? s.axial_spacing : 2 * M_PI * R0 / N;
  // Ring stations: fine-grid indices closest to equal spacing along the spine.
  const int rings = std::max(2, int(std::round(sigma.back() / h)) + 1);
  std::vector<int> station(rings);
  {
    int j = 0;
    for (int k = 0; k < rings; ++k) {
      double target = sigma.back() * k / (rings - 1);
      while (j < M && sigma[j + 1] <= target) ++j;
      station[k] = (j < M && target - sigma[j] > sigma[j + 1] - target) ? j + 1 : j;
    }
  }

  auto tube = [&](MeshData& m, auto&& ring_point) {
    m.points.reserve(std::size_t(rings) * N);
    for (int k = 0; k < rings; ++k)
      for (int j = 0; j < N; ++j) m.points.push_back(ring_point(station[k], 2 * M_PI * j / N));
    // Quads split along alternating diagonals; (k,j),(k,j+1),(k+1,j) has
    // normal θ̂ × T = radial: outward (see phantom.hpp).
    for (int k = 0; k + 1 < rings; ++k)
      for (int j = 0; j < N; ++j) {
        std::int64_t a = k * N + j, b = k * N + (j + 1) % N, c = (k + 1) * N + j, d = (k + 1) * N + (j + 1) % N;
        if ((j + k) % 2 == 0) {
          m.add_cell(CellType::triangle, {a, b, d});
          m.add_cell(CellType::triangle, {a, d, c});
        } else {
          m.add_cell(CellType::triangle, {a, b, c});
          m.add_cell(CellType::triangle, {b, d, c});
        }
      }
    m.field_text["units"] = "mm";
    m.field_text["phantom_preset"] = s.preset;
    m.field_text["phantom_seed"] = std::to_string(s.seed);
  };
  // Characteristic circle of the sphere (γ, r): centre γ − r ρ T, radius r√(1−ρ²).
  tube(g.lumen, [&](int i, double th) -> Vector3d {
    double rho = drds[i];
    return spine[i] - r[i] * rho * sf.tangent[i] +
           r[i] * std::sqrt(1 - rho * rho) * (std::cos(th) * sf.normal[i] + std::sin(th) * sf.binormal[i]);
  });
  tube(g.wall, [&](int i, double th) -> Vector3d {
    return axis[i] + rout[i] * (std::cos(th) * af.normal[i] + std::sin(th) * af.binormal[i]);
  });

  // True centerline every 10 fine samples (0.05 mm).
  auto& cl = g.true_centerline;
  DataArray rad, absc, normals{3, {}};
  std::vector<std::int64_t> ids;
  std::vector<int> samples;
  for (int i = 0; i < M; i += 10) samples.push_back(i);
  samples.push_back(M);
  for (int i : samples) {
    ids.push_back(std::int64_t(cl.points.size()));
    cl.points.push_back(spine[i]);
    rad.values.push_back(r[i]);
    absc.values.push_back(sigma[i]);
    for (int c = 0; c < 3; ++c) normals.values.push_back(sf.normal[i][c]);
  }
  cl.add_cell(CellType::polyline, ids);
  cl.point_data["MaximumInscribedSphereRadius"] = rad;
  cl.point_data["Abscissas"] = absc;
  cl.point_data["ParallelTransportNormals"] = normals;
  cl.field_text["units"] = "mm";
  cl.field_text["phantom_preset"] = s.preset;
  cl.field_text["phantom_seed"] = std::to_string(s.seed);

  int imin = int(std::min_element(r.begin(), r.end()) - r.begin());
  if (S > 0) imin = int(std::round(s.stenosis_position * s.length / du));
  g.min_radius = r[imin];
  g.stenosis_abscissa = sigma[imin];
  g.stenosis_point = spine[imin];

  // Wall thickness along rays from the axis in its normal planes.
  g.wall_thickness_min = 1e300;
  g.wall_thickness_max = 0;
  for (int k = 0; k < rings; ++k) {
    int i = station[k];
    double delta = s.eccentricity * (R0 - r[i]);
    for (int j = 0; j < 72; ++j) {
      double th = 2 * M_PI * j / 72;
      Vector3d u = std::cos(th) * af.normal[i] + std::sin(th) * af.binormal[i];
      double un = u.dot(plaque[i]);
      double t_lumen = delta * un + std::sqrt(r[i] * r[i] - delta * delta * (1 - un * un));
      double t = rout[i] - t_lumen;
      g.wall_thickness_min = std::min(g.wall_thickness_min, t);
      g.wall_thickness_max = std::max(g.wall_thickness_max, t);
    }
  }
  return g;
}

void write_phantom(const PhantomSpec& spec, const std::filesystem::path& lumen_vtp,
                   const std::filesystem::path& wall_vtp, const std::filesystem::path& centerline_true_vtp,
                   Summary& summary) {
  PhantomGeometry g = build_phantom(spec);
  write_vtp(lumen_vtp.string(), g.lumen);
  write_vtp(wall_vtp.string(), g.wall);
  write_vtp(centerline_true_vtp.string(), g.true_centerline);
  summary.set_text("phantom_preset", spec.preset);
  summary.set("phantom_seed", double(spec.seed));
  summary.set("reference_radius", spec.reference_radius, "mm");
  summary.set("true_min_radius", g.min_radius, "mm");
  summary.set("true_stenosis_percent_diameter", 100 * (1 - g.min_radius / spec.reference_radius), "%");
  summary.set("true_stenosis_abscissa", g.stenosis_abscissa, "mm");
  summary.set("true_centerline_length", g.true_centerline.point_data.at("Abscissas").values.back(), "mm");
  summary.set("wall_thickness_min", g.wall_thickness_min, "mm");
  summary.set("wall_thickness_max", g.wall_thickness_max, "mm");
  summary.set("lumen_triangles", double(g.lumen.num_cells()));
  summary.set("wall_triangles", double(g.wall.num_cells()));
  summary.note("phantom_lumen", "canal surface around the true centerline: the true inscribed radius is exact");
  log::info("phantom {} (seed {}): throat radius {:.4f} mm at {:.3f} mm, wall {:.2f}-{:.2f} mm, {} lumen triangles",
            spec.preset, spec.seed, g.min_radius, g.stenosis_abscissa, g.wall_thickness_min, g.wall_thickness_max,
            g.lumen.num_cells());
}

void write_phantom(const PhantomSpec& spec, const std::filesystem::path& out_dir, Summary& summary) {
  std::filesystem::create_directories(out_dir);
  write_phantom(spec, out_dir / "lumen.vtp", out_dir / "wall.vtp", out_dir / "centerline_true.vtp", summary);
}

}  // namespace stentsim::segmentation
