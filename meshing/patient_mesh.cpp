#include "meshing/patient_mesh.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/log.hpp"
#include "common/mesh_tags.hpp"
#include "common/plane_section.hpp"

namespace stentsim::meshing {

using Eigen::Vector2d;
using Eigen::Vector3d;

void validate(const PatientMeshOptions& o) {
  auto need = [](bool ok, const char* field, const std::string& what) {
    if (!ok) throw InputError(fmt::format("mesh.{}: {}", field, what));
  };
  need(o.element == "tet10" || o.element == "tet4", "element", "must be tet10 or tet4");
  need(o.size > 0, "size", "must be positive");
  need(o.min_size_ratio > 0 && o.min_size_ratio <= 1, "min_size_ratio", "must be in (0, 1]");
  need(o.min_elements_per_layer >= 1, "min_elements_per_layer", "must be at least 1");
  need(o.media_ratio >= 0 && o.adventitia_ratio >= 0 && o.media_ratio + o.adventitia_ratio < 0.5, "media_ratio",
       "media_ratio and adventitia_ratio must be non-negative with a sum below 0.5");
  need(o.intima || o.media_ratio > 0 || o.adventitia_ratio > 0, "intima", "at least one layer is needed");
  need(o.min_intima >= 0, "min_intima", "must be non-negative");
  need(o.station_spacing > 0, "station_spacing", "must be positive");
  need(o.points_per_section >= 8, "points_per_section", "must be at least 8");
  need(o.end_trim >= 0, "end_trim", "must be non-negative");
  need(o.min_section_gap_ratio >= 0 && o.min_section_gap_ratio < 1, "min_section_gap_ratio", "must be in [0, 1)");
  need(o.algorithm_3d == "delaunay" || o.algorithm_3d == "hxt", "algorithm_3d", "must be delaunay or hxt");
  need(o.max_elements >= 1, "max_elements", "must be at least 1");
}

// The per-layer element count is a requirement, the floor min_size_ratio *
// size a guard against runaway refinement: when a layer's thickness / n
// falls below the floor the two settings conflict, and the user decides
// (the first version clamped the size up to the floor without a word, so
// min_elements_per_layer = 2 gave one element through the 0.1 mm intima).
// One element through a layer needs no size cap: every layer is its own
// meshed volume of the conforming mesh, so every path across it crosses at
// least one of its tets. With n = 1 the floor stays a floor (a 0.1 mm intima
// at size 0.25 gets 0.125 mm tets; letting it go to 0.1 mm cost quality:
// min scaled Jacobian 0.015 instead of > 0.05 on the moderate-bend test).
void check_layer_sizing(const WallSections& w, const PatientMeshOptions& o) {
  if (o.min_elements_per_layer <= 1) return;
  const double hmin = o.min_size_ratio * o.size;
  const std::size_t nk = w.radius.empty() ? 0 : w.radius[0].size();
  double worst = std::numeric_limits<double>::infinity();
  std::size_t ws = 0, wk = 0, wi = 0;
  for (std::size_t s = 0; s < w.radius.size(); ++s)
    for (std::size_t k = 0; k + 1 < nk; ++k)
      for (std::size_t i = 0; i < w.radius[s][k].size(); ++i) {
        const double t = w.radius[s][k + 1][i] - w.radius[s][k][i];
        if (t < worst) worst = t, ws = s, wk = k, wi = i;
      }
  if (worst / o.min_elements_per_layer >= hmin) return;
  const Vector3d p = 0.5 * (w.point(ws, wk, wi) + w.point(ws, wk + 1, wi));
  throw InputError(fmt::format(
      "mesh: the {} is {:.4g} mm thick at s = {:.2f} mm ({:.3f}, {:.3f}, {:.3f}); mesh.min_elements_per_layer = {} "
      "needs a size of {:.4g} mm there, below mesh.min_size_ratio * mesh.size = {:.3g} * {:.3g} = {:.4g} mm; lower "
      "mesh.min_size_ratio (to {:.3g} or less) or mesh.min_elements_per_layer",
      tags::layer_name(w.layers[wk]), worst, w.abscissa[ws], p.x(), p.y(), p.z(), o.min_elements_per_layer,
      worst / o.min_elements_per_layer, o.min_size_ratio, o.size, hmin,
      std::floor(1000 * worst / o.min_elements_per_layer / o.size) / 1000));
}


// Local size as mesh_wall_sections's size callback gives it inside a layer of
// thickness t: the target, at most t / n, not below the floor.
static double local_size(double t, const PatientMeshOptions& o) {
  return std::clamp(std::min(o.size, t / o.min_elements_per_layer), o.min_size_ratio * o.size, o.size);
}

// Tets per unit volume at edge length h in gmsh's Delaunay meshes of these walls:
// c / h^3 with c calibrated on the phantoms (a regular tet would give 8.5; gmsh's
// tets are smaller than the target near the thin layers' faces).
static constexpr double kTetsPerCubedSize = 11.0;

std::vector<double> estimate_elements(const WallSections& w, const PatientMeshOptions& o) {
  std::vector<double> count(4, 0.0);
  const std::size_t ns = w.radius.size(), nk = ns ? w.radius[0].size() : 0;
  for (std::size_t s = 0; s + 1 < ns; ++s) {
    const double ds = std::abs(w.abscissa[s + 1] - w.abscissa[s]);
    for (std::size_t k = 0; k + 1 < nk; ++k) {
      const std::size_t nr = w.radius[s][k].size();
      const double dth = 2 * std::numbers::pi / double(nr);
      for (std::size_t i = 0; i < nr; ++i)
        for (std::size_t q : {s, s + 1}) {
          const double lo = w.radius[q][k][i], hi = w.radius[q][k + 1][i];
          if (!(hi > lo)) continue;
          const double volume = 0.5 * (hi * hi - lo * lo) * dth * 0.5 * ds;  // half the interval per end section
          const double h = local_size(hi - lo, o);
          count[static_cast<std::size_t>(w.layers[k])] += kTetsPerCubedSize * volume / (h * h * h);
        }
    }
  }
  return count;
}

double check_element_budget(const WallSections& w, const PatientMeshOptions& o) {
  double thickest = 0;
  for (const auto& section : w.radius)
    for (std::size_t i = 0; !section.empty() && i < section[0].size(); ++i)
      thickest = std::max(thickest, section.back()[i] - section.front()[i]);
  if (o.size > 2 * thickest)
    throw InputError(fmt::format("mesh.size = {:g} mm is more than twice the thickest wall ({:.3g} mm): no layer can be "
                                 "meshed at that size (the paper meshes at 0.25 mm); set mesh.size to {:.2g} mm or less",
                                 o.size, thickest, thickest));
  const std::vector<double> n = estimate_elements(w, o);
  double total = 0;
  std::string per_layer;
  for (int L : w.layers) {
    total += n[static_cast<std::size_t>(L)];
    per_layer += fmt::format("{}{} {:.3g}", per_layer.empty() ? "" : ", ", tags::layer_name(L), n[static_cast<std::size_t>(L)]);
  }
  if (total > o.max_elements)
    throw InputError(fmt::format("mesh: about {:.3g} tets are expected at mesh.size = {:g} mm ({}), more than "
                                 "mesh.max_elements = {:.3g}; raise mesh.size (the count goes with 1/size^3) or "
                                 "mesh.max_elements", total, o.size, per_layer, o.max_elements));
  return total;
}

Vector3d WallSections::point(std::size_t s, std::size_t k, std::size_t i) const {
  const double th = 2 * std::numbers::pi * double(i) / double(radius[s][k].size());
  return origin[s] + radius[s][k][i] * (std::cos(th) * normal[s] + std::sin(th) * binormal[s]);
}


WallSections wall_sections(const MeshData& lumen, const MeshData& wall, const MeshData& centerline,
                           const PatientMeshOptions& o) {
  validate(o);
  const auto& cp = centerline.points;
  if (cp.size() < 3) throw InputError("centerline: needs at least 3 points");
  auto ptn_it = centerline.point_data.find("ParallelTransportNormals");
  if (ptn_it == centerline.point_data.end() || ptn_it->second.components != 3 || ptn_it->second.tuples() != cp.size())
    throw InputError("centerline: point array ParallelTransportNormals (3 components per point) is missing");
  std::vector<double> s(cp.size(), 0.0);
  for (std::size_t i = 1; i < cp.size(); ++i) s[i] = s[i - 1] + (cp[i] - cp[i - 1]).norm();
  WallSections w;
  auto at_abscissa = [&](double sv) {
    const auto it = std::upper_bound(s.begin(), s.end(), sv);
    const std::size_t j = std::clamp<std::size_t>(std::size_t(it - s.begin()), 1, cp.size() - 1);
    const double f = std::clamp((sv - s[j - 1]) / std::max(1e-12, s[j] - s[j - 1]), 0.0, 1.0);
    return Vector3d((1 - f) * cp[j - 1] + f * cp[j]);
  };
  // Ends cut obliquely to this centerline (a region of interest clipped
  // normal to the tree path's centerline, a label image's slab): a section
  // at end_trim may leave the lumen's open end on some rays. The trim at that
  // end then grows in 0.1 mm steps until the section encloses the centerline
  // in both surfaces, up to one reference diameter (twice the end's largest
  // inscribed radius within it); the summary and log give the trims used.
  const auto radius_it = centerline.point_data.find("MaximumInscribedSphereRadius");
  auto encloses = [&](double sa) {
    const Vector3d x = at_abscissa(sa);
    const Vector3d t = (at_abscissa(std::min(s.back(), sa + 0.5 * o.station_spacing)) -
                        at_abscissa(std::max(s.front(), sa - 0.5 * o.station_spacing))).normalized();
    Vector3d n = t.unitOrthogonal(), b = t.cross(n);
    const auto lc = plane_cut(lumen, x, t, n, b), wc = plane_cut(wall, x, t, n, b);
    for (int i = 0; i < o.points_per_section; ++i) {
      const double th = 2 * std::numbers::pi * i / o.points_per_section;
      const Vector2d dir(std::cos(th), std::sin(th));
      const double rl = ray_hit(lc, dir), rw = ray_hit(wc, dir);
      if (std::isnan(rl) || std::isnan(rw) || rw <= rl) return false;
    }
    return true;
  };
  auto trim_at = [&](bool proximal) {
    double limit = o.end_trim;
    if (radius_it != centerline.point_data.end() && radius_it->second.tuples() == cp.size()) {
      double rmax = 0;  // the end's reference radius: the largest inscribed radius within 5 mm of it
      for (std::size_t i = 0; i < cp.size(); ++i)
        if ((proximal ? s[i] - s.front() : s.back() - s[i]) <= 5.0) rmax = std::max(rmax, radius_it->second.values[i]);
      limit = std::max(limit, 2 * rmax);
    }
    for (double trim = o.end_trim; trim <= limit + 1e-9; trim += 0.1)
      if (encloses(proximal ? s.front() + trim : s.back() - trim)) return trim;
    return o.end_trim;  // the section loop below reports where and why
  };
  w.end_trim_proximal = trim_at(true);
  w.end_trim_distal = trim_at(false);
  const double L = s.back() - s.front() - w.end_trim_proximal - w.end_trim_distal;
  if (L < 2 * o.station_spacing)
    throw InputError(fmt::format("centerline: {:.3g} mm long after end_trim, too short to mesh", L));
  const int ns = std::max(3, int(std::round(L / o.station_spacing)) + 1);
  const int nk = 2 + (o.intima && (o.media_ratio > 0 || o.adventitia_ratio > 0) ? 1 : 0) +
                 ((o.media_ratio > 0 && o.adventitia_ratio > 0) ? 1 : 0);
  if (o.intima) w.layers.push_back(tags::intima);
  if (o.media_ratio > 0) w.layers.push_back(tags::media);
  if (o.adventitia_ratio > 0) w.layers.push_back(tags::adventitia);
  if (int(w.layers.size()) != nk - 1) throw InputError("mesh: inconsistent layer set");
  std::size_t seg = 0, clamped = 0, rays = 0;
  for (int st = 0; st < ns; ++st) {
    const double sa = s.front() + w.end_trim_proximal + L * st / (ns - 1);
    while (seg + 2 < cp.size() && s[seg + 1] < sa) ++seg;
    const double a = std::clamp((sa - s[seg]) / std::max(1e-12, s[seg + 1] - s[seg]), 0.0, 1.0);
    const Vector3d x = (1 - a) * cp[seg] + a * cp[seg + 1];
    // Tangent: the chord over one spacing centred on the station (points
    // interpolated on the polyline, so the window is symmetric and on a
    // circular arc the chord is the exact tangent), so the cut planes turn
    // smoothly. Clamped at the centerline's ends.
    const Vector3d t = (at_abscissa(std::min(s.back(), sa + 0.5 * o.station_spacing)) -
                        at_abscissa(std::max(s.front(), sa - 0.5 * o.station_spacing))).normalized();
    Vector3d n0((1 - a) * ptn_it->second.at(seg, 0) + a * ptn_it->second.at(seg + 1, 0),
                (1 - a) * ptn_it->second.at(seg, 1) + a * ptn_it->second.at(seg + 1, 1),
                (1 - a) * ptn_it->second.at(seg, 2) + a * ptn_it->second.at(seg + 1, 2));
    n0 -= n0.dot(t) * t;
    if (n0.norm() < 1e-9) throw InputError(fmt::format("centerline: ParallelTransportNormals parallel to the tangent at s = {:.3f} mm", sa));
    const Vector3d n = n0.normalized(), b = t.cross(n);
    const auto lc = plane_cut(lumen, x, t, n, b), wc = plane_cut(wall, x, t, n, b);
    std::vector<std::vector<double>> r(std::size_t(nk), std::vector<double>(std::size_t(o.points_per_section)));
    for (int i = 0; i < o.points_per_section; ++i) {
      const double th = 2 * std::numbers::pi * i / o.points_per_section;
      const Vector2d dir(std::cos(th), std::sin(th));
      const double rl = ray_hit(lc, dir), rw = ray_hit(wc, dir);
      const Vector3d where = x + (std::isnan(rl) ? 0.0 : rl) * (std::cos(th) * n + std::sin(th) * b);
      if (std::isnan(rl))
        throw InputError(fmt::format("lumen: the cross-section at s = {:.2f} mm (point {:.3f} {:.3f} {:.3f}) does not enclose "
                                     "the centerline{}",
                                     sa, x.x(), x.y(), x.z(),
                                     st == 0 || st == ns - 1 ? " (an end cut obliquely: raise mesh.end_trim)" : ""));
      if (std::isnan(rw))
        throw InputError(fmt::format("wall: the cross-section at s = {:.2f} mm (point {:.3f} {:.3f} {:.3f}) does not enclose the centerline", sa, x.x(), x.y(), x.z()));
      if (rw <= rl + 1e-6)
        throw InputError(fmt::format("wall: inside the lumen at s = {:.2f} mm, near ({:.3f}, {:.3f}, {:.3f})", sa,
                                     where.x(), where.y(), where.z()));
      r[0][std::size_t(i)] = rl;
      r[std::size_t(nk - 1)][std::size_t(i)] = rw;
    }
    // Local outer diameter: twice the mean outer radius of the section (paper 4.2).
    double D = 0;
    for (double v : r[std::size_t(nk - 1)]) D += 2 * v / o.points_per_section;
    for (int i = 0; i < o.points_per_section; ++i) {
      const double rl = r[0][std::size_t(i)], rw = r[std::size_t(nk - 1)][std::size_t(i)], T = rw - rl;
      double tm = o.media_ratio * D, ta = o.adventitia_ratio * D;
      const double keep = o.intima ? o.min_intima : 0.0;
      ++rays;
      if (o.intima && tm + ta + keep > T) {
        // Wall thinner than the rule allows: media and adventitia shrink in
        // proportion so the intima keeps min_intima (our choice; reported).
        if (T <= keep * 1.5)
          throw InputError(fmt::format("wall: {:.3f} mm thick at s = {:.2f} mm, below 1.5 min_intima", T, sa));
        const double f = (T - keep) / (tm + ta);
        tm *= f;
        ta *= f;
        ++clamped;
      } else if (!o.intima) {
        const double f = T / (tm + ta);  // media + adventitia fill the wall in their ratio
        tm *= f;
        ta *= f;
      }
      std::size_t k = 1;
      if (o.intima && nk > 2) r[k++][std::size_t(i)] = rw - ta - tm;
      if (o.media_ratio > 0 && o.adventitia_ratio > 0) r[k++][std::size_t(i)] = rw - ta;
    }
    w.origin.push_back(x);
    w.tangent.push_back(t);
    w.normal.push_back(n);
    w.binormal.push_back(b);
    w.abscissa.push_back(sa);
    w.radius.push_back(std::move(r));
  }
  w.clamped_fraction = rays ? double(clamped) / double(rays) : 0.0;
  w.min_gap_ratio = check_wall_sections(w, o.min_section_gap_ratio);
  return w;
}

namespace {

/// Columns dx/dxi_k of the tet10 map at reference point (xi, eta, zeta); VTK
/// node order (corners 0-3, midside nodes of edges 01, 12, 02, 03, 13, 23).
/// Shape functions in barycentrics L: corners L_i (2 L_i - 1), edges 4 L_i L_j.
Eigen::Matrix3d tet10_jacobian(const std::array<Vector3d, 10>& x, const std::array<double, 3>& xi) {
  const double L[4] = {1 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]};
  static const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    auto dL = [k](int i) { return i == 0 ? -1.0 : (i == k + 1 ? 1.0 : 0.0); };
    for (int i = 0; i < 4; ++i) j.col(k) += (4 * L[i] - 1) * dL(i) * x[std::size_t(i)];
    for (int e = 0; e < 6; ++e) {
      const int a = edge[e][0], b = edge[e][1];
      j.col(k) += 4 * (L[a] * dL(b) + L[b] * dL(a)) * x[std::size_t(4 + e)];
    }
  }
  return j;
}

}  // namespace

MeshQuality mesh_quality(const MeshData& m) {
  MeshQuality q;
  const auto& layer = m.cell_data.at(tags::kLayer);
  double edge_sum = 0;
  std::size_t edge_count = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    if (m.cell_types[c] != CellType::tetra && m.cell_types[c] != CellType::quadratic_tetra) continue;
    const auto nd = m.cell(c);
    const Vector3d x[4] = {m.points[std::size_t(nd[0])], m.points[std::size_t(nd[1])], m.points[std::size_t(nd[2])],
                           m.points[std::size_t(nd[3])]};
    // Corner scaled Jacobian: det of the three edges at a corner over their
    // length product, times sqrt 2 so the regular tet scores 1.
    static const int corner[4][3] = {{1, 2, 3}, {2, 0, 3}, {0, 1, 3}, {1, 0, 2}};
    double sj = 1e300;
    for (int v = 0; v < 4; ++v) {
      const Vector3d e1 = x[corner[v][0]] - x[v], e2 = x[corner[v][1]] - x[v], e3 = x[corner[v][2]] - x[v];
      sj = std::min(sj, std::sqrt(2.0) * e1.dot(e2.cross(e3)) / (e1.norm() * e2.norm() * e3.norm()));
    }
    const double vol = (x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0])) / 6;
    if (m.cell_types[c] == CellType::quadratic_tetra) {
      // The quadratic map at the corners and the 4-point rule's points
      // (a = 0.1381966, b = 0.5854102): the scaled Jacobian of its columns
      // (sqrt 2 det J / |J1||J2||J3|, the corner formula at corner 0 for a
      // straight tet) and det J against the straight tet's 6 V.
      std::array<Vector3d, 10> xq;
      for (std::size_t a = 0; a < 10; ++a) xq[a] = m.points[std::size_t(nd[a])];
      const double qa = 0.1381966011250105, qb = 0.5854101966249685;
      const std::array<std::array<double, 3>, 8> at = {
          {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {qa, qa, qa}, {qb, qa, qa}, {qa, qb, qa}, {qa, qa, qb}}};
      for (const auto& xi : at) {
        const Eigen::Matrix3d j = tet10_jacobian(xq, xi);
        const double d = j.determinant();
        sj = std::min(sj, std::sqrt(2.0) * d / (j.col(0).norm() * j.col(1).norm() * j.col(2).norm()));
        q.min_jacobian_ratio = std::min(q.min_jacobian_ratio, d / (6 * vol));
      }
    }
    double area = 0, hmax = 0;
    static const int f[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (auto& ff : f) area += 0.5 * (x[ff[1]] - x[ff[0]]).cross(x[ff[2]] - x[ff[0]]).norm();
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const double h = (x[i] - x[j]).norm();
        hmax = std::max(hmax, h);
        edge_sum += h;
        ++edge_count;
      }
    const double rin = 3 * std::abs(vol) / area;
    const double ar = hmax / (2 * std::sqrt(6.0) * rin);
    const int L = int(layer.at(c));
    if (L >= 0 && L < 4) ++q.elements_per_layer[std::size_t(L)];
    if (ar > q.max_aspect_ratio) {
      q.max_aspect_ratio = ar;
      q.worst_ar_position = (x[0] + x[1] + x[2] + x[3]) / 4;
      q.worst_ar_layer = L;
      q.worst_ar_cell = c;
    }
    if (sj < q.min_scaled_jacobian) {
      q.min_scaled_jacobian = sj;
      q.worst_sj_position = (x[0] + x[1] + x[2] + x[3]) / 4;
      q.worst_sj_layer = L;
      q.worst_sj_cell = c;
    }
  }
  q.mean_edge_length = edge_count ? edge_sum / double(edge_count) : 0.0;
  return q;
}

std::string mesh_fingerprint(const MeshData& m) {
  // Raw bytes: equal hashes need bitwise equal coordinates, which is what a
  // reproducible mesher gives (no tolerance hides a moved node).
  std::string bytes;
  auto put = [&bytes](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
  for (const auto& x : m.points) put(x.data(), 3 * sizeof(double));
  for (auto t : m.cell_types) {
    const int v = int(t);
    put(&v, sizeof v);
  }
  put(m.connectivity.data(), m.connectivity.size() * sizeof(std::int64_t));
  for (const char* key : {tags::kLayer, tags::kFaceGroup}) {
    auto it = m.cell_data.find(key);
    if (it != m.cell_data.end()) put(it->second.values.data(), it->second.values.size() * sizeof(double));
  }
  return files::text_hash(bytes);
}

void run_patient_mesh(const std::filesystem::path& lumen_vtp, const std::filesystem::path& wall_vtp,
                      const std::filesystem::path& centerline_vtp, const PatientMeshOptions& o,
                      const std::filesystem::path& artery_vtu, const std::filesystem::path& artery_msh,
                      Summary& summary) {
  const auto t0 = std::chrono::steady_clock::now();
  const MeshData lumen = read_vtp(lumen_vtp.string()), wall = read_vtp(wall_vtp.string()),
                 cl = read_vtp(centerline_vtp.string());
  WallSections w;
  try {
    w = wall_sections(lumen, wall, cl, o);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{} / {} / {}: {}", lumen_vtp.string(), wall_vtp.string(), centerline_vtp.string(), e.what()));
  }
  if (w.clamped_fraction > 0)
    log::warn("mesh: on {:.1f} % of the rays the wall is thinner than media + adventitia + min_intima; media and adventitia shrink there",
              100 * w.clamped_fraction);
  // gmsh picks the format from the extension: the temporary keeps ".msh".
  const double estimated = check_element_budget(w, o);
  log::info("mesh: about {:.3g} tets expected; meshing with gmsh", estimated);
  const auto msh_tmp = artery_msh.parent_path() / (".tmp-" + artery_msh.filename().string());
  MeshData m = mesh_wall_sections(w, o, msh_tmp);
  const MeshQuality q = mesh_quality(m);
  std::size_t tets = 0;
  for (auto n : q.elements_per_layer) tets += n;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.set("artery_nodes", double(m.points.size()));
  summary.set("artery_dofs", 3.0 * double(m.points.size()));
  summary.set("artery_elements", double(tets));
  summary.set("artery_elements_estimate", estimated);
  for (int L : w.layers) summary.set(fmt::format("{}_elements", tags::layer_name(L)), double(q.elements_per_layer[std::size_t(L)]));
  summary.set("min_scaled_jacobian", q.min_scaled_jacobian);
  summary.set("max_aspect_ratio", q.max_aspect_ratio);
  if (o.element == "tet10") summary.set("min_jacobian_ratio", q.min_jacobian_ratio);
  summary.set("mean_edge_length", q.mean_edge_length, "mm");
  summary.set("sections", double(w.origin.size()));
  summary.set("end_trim_proximal", w.end_trim_proximal, "mm");
  summary.set("end_trim_distal", w.end_trim_distal, "mm");
  if (w.end_trim_proximal > o.end_trim + 1e-9 || w.end_trim_distal > o.end_trim + 1e-9)
    log::info("mesh: ends cut obliquely: trimmed {:.1f} mm (proximal) and {:.1f} mm (distal) instead of mesh.end_trim = {} mm",
              w.end_trim_proximal, w.end_trim_distal, o.end_trim);
  summary.set("thinned_layer_ray_fraction", w.clamped_fraction);
  summary.set("min_section_gap_ratio", w.min_gap_ratio);
  summary.set("meshing_time", secs, "s");
  summary.note("element", o.element);
  summary.note("algorithm_3d", o.algorithm_3d);
  summary.note("mesh_fingerprint", mesh_fingerprint(m));
  summary.note("mesh_size_mm", fmt::format("{}", o.size));
  log::info("mesh: {} {} elements, {} nodes, mean edge {:.3f} mm, min scaled Jacobian {:.3f}, max aspect ratio {:.2f}, {:.1f} s",
            tets, o.element, m.points.size(), q.mean_edge_length, q.min_scaled_jacobian, q.max_aspect_ratio, secs);
  if (q.min_scaled_jacobian < o.min_scaled_jacobian || q.max_aspect_ratio > o.max_aspect_ratio) std::filesystem::remove(msh_tmp);
  if (q.min_scaled_jacobian < o.min_scaled_jacobian)
    throw ComputeError(fmt::format(
        "mesh: scaled Jacobian {:.3g} below mesh.min_scaled_jacobian {:.3g} in the {} at ({:.3f}, {:.3f}, {:.3f}); "
        "refine mesh.size or raise min_intima",
        q.min_scaled_jacobian, o.min_scaled_jacobian, tags::layer_name(q.worst_sj_layer), q.worst_sj_position.x(),
        q.worst_sj_position.y(), q.worst_sj_position.z()));
  if (q.max_aspect_ratio > o.max_aspect_ratio)
    throw ComputeError(fmt::format("mesh: aspect ratio {:.3g} above mesh.max_aspect_ratio {:.3g} in the {} at ({:.3f}, "
                                   "{:.3f}, {:.3f}); refine mesh.size or raise min_intima",
                                   q.max_aspect_ratio, o.max_aspect_ratio, tags::layer_name(q.worst_ar_layer),
                                   q.worst_ar_position.x(), q.worst_ar_position.y(), q.worst_ar_position.z()));
  write_vtu(artery_vtu.string(), m);
  std::filesystem::rename(msh_tmp, artery_msh);
}

}  // namespace stentsim::meshing
