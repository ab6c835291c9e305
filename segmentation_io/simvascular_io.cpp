// SimVascular `.pth` / `.ctgr` reading (pugixml) and the contour loft.
// Element and attribute names follow SimVascular's sv4gui path and contour
// group writers (format version 1.0).
#include "segmentation_io/simvascular_io.hpp"

#include <fmt/format.h>
#include <pugixml.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

namespace {

struct XmlFile {
  pugi::xml_document doc;
  std::string name;
};

void load_xml(XmlFile& x, const std::filesystem::path& file) {
  x.name = file.string();
  files::require_regular_file(file, "SimVascular file");
  pugi::xml_parse_result r = x.doc.load_file(file.c_str());
  if (!r)
    throw InputError(fmt::format("{}: not valid XML ({} at byte {})", x.name, r.description(), r.offset));
}

// "<a>/<b id=3>" style location of an element, for error messages.
std::string where(const pugi::xml_node& n) {
  std::string s;
  for (pugi::xml_node p = n; p && p.type() == pugi::node_element; p = p.parent()) {
    std::string e = std::string("<") + p.name();
    if (auto id = p.attribute("id")) e += std::string(" id=") + id.value();
    e += ">";
    s = s.empty() ? e : e + "/" + s;
  }
  return s;
}

pugi::xml_node child(const XmlFile& f, const pugi::xml_node& n, const char* name) {
  pugi::xml_node c = n.child(name);
  if (!c) throw InputError(fmt::format("{}: element {} has no <{}> child", f.name, where(n), name));
  return c;
}

double attribute_number(const XmlFile& f, const pugi::xml_node& n, const char* name) {
  pugi::xml_attribute a = n.attribute(name);
  if (!a) throw InputError(fmt::format("{}: element {} lacks the attribute `{}`", f.name, where(n), name));
  const char* s = a.value();
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(s, &end);
  while (end && *end == ' ') ++end;
  if (end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw InputError(fmt::format("{}: element {} attribute `{}` = \"{}\" is not a finite number", f.name, where(n),
                                 name, s));
  return v;
}

Vector3d xyz(const XmlFile& f, const pugi::xml_node& n) {
  return {attribute_number(f, n, "x"), attribute_number(f, n, "y"), attribute_number(f, n, "z")};
}

Vector3d unit(const XmlFile& f, const pugi::xml_node& n) {
  Vector3d v = xyz(f, n);
  if (v.norm() < 1e-12) throw InputError(fmt::format("{}: element {} is a zero vector", f.name, where(n)));
  return v.normalized();
}

}  // namespace

SvPath read_simvascular_path(const std::filesystem::path& file) {
  XmlFile f;
  load_xml(f, file);
  pugi::xml_node path = f.doc.child("path");
  if (!path) throw InputError(fmt::format("{}: no <path> element (is this a SimVascular .pth file?)", f.name));
  pugi::xml_node element = child(f, child(f, path, "timestep"), "path_element");
  pugi::xml_node pps = child(f, element, "path_points");
  SvPath out;
  for (pugi::xml_node pp : pps.children("path_point")) {
    out.points.push_back(xyz(f, child(f, pp, "pos")));
    out.tangents.push_back(unit(f, child(f, pp, "tangent")));
  }
  if (out.points.size() < 2)
    throw InputError(fmt::format("{}: element {} holds {} <path_point>; a path needs at least two", f.name,
                                 where(pps), out.points.size()));
  return out;
}

std::vector<SvContour> read_simvascular_contours(const std::filesystem::path& file) {
  XmlFile f;
  load_xml(f, file);
  pugi::xml_node group = f.doc.child("contourgroup");
  if (!group)
    throw InputError(fmt::format("{}: no <contourgroup> element (is this a SimVascular .ctgr file?)", f.name));
  pugi::xml_node ts = child(f, group, "timestep");
  std::vector<SvContour> out;
  for (pugi::xml_node c : ts.children("contour")) {
    SvContour k;
    k.id = c.attribute("id").as_int(int(out.size()));
    k.type = c.attribute("type").as_string();
    if (std::string(c.attribute("closed").as_string("true")) == "false")
      throw InputError(fmt::format("{}: element {} is an open contour (closed=\"false\"); a lumen cross-section "
                                   "must be closed", f.name, where(c)));
    pugi::xml_node pp = child(f, c, "path_point");
    k.path_position = xyz(f, child(f, pp, "pos"));
    k.path_tangent = unit(f, child(f, pp, "tangent"));
    pugi::xml_node cps = child(f, c, "contour_points");
    for (pugi::xml_node p : cps.children("point")) k.points.push_back(xyz(f, p));
    if (k.points.size() < 3)
      throw InputError(fmt::format("{}: element {} holds {} <point>; a contour needs at least three", f.name,
                                   where(cps), k.points.size()));
    out.push_back(std::move(k));
  }
  if (out.empty()) throw InputError(fmt::format("{}: element {} holds no <contour>", f.name, where(ts)));
  return out;
}

namespace {

Vector3d centroid(const std::vector<Vector3d>& p) {
  Vector3d c = Vector3d::Zero();
  for (const auto& x : p) c += x;
  return c / double(p.size());
}

// Newell's normal of a closed polygon (area-weighted, sign = orientation).
Vector3d newell_normal(const std::vector<Vector3d>& p) {
  Vector3d n = Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) n += p[i].cross(p[(i + 1) % p.size()]);
  return n;
}

// `n` points at equal arc length along the closed curve, starting at p[0].
std::vector<Vector3d> resample_closed(const std::vector<Vector3d>& p, int n) {
  std::vector<double> s(p.size() + 1, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) s[i + 1] = s[i] + (p[(i + 1) % p.size()] - p[i]).norm();
  const double L = s.back();
  std::vector<Vector3d> out;
  out.reserve(std::size_t(n));
  std::size_t seg = 0;
  for (int k = 0; k < n; ++k) {
    double t = L * k / n;
    while (seg + 1 < p.size() && s[seg + 1] < t) ++seg;
    double len = s[seg + 1] - s[seg];
    double a = len > 0 ? (t - s[seg]) / len : 0.0;
    out.push_back((1 - a) * p[seg] + a * p[(seg + 1) % p.size()]);
  }
  return out;
}

Vector3d catmull_rom(const Vector3d& p0, const Vector3d& p1, const Vector3d& p2, const Vector3d& p3, double t) {
  // Uniform Catmull-Rom segment between p1 and p2.
  double t2 = t * t, t3 = t2 * t;
  return 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2 + (-p0 + 3 * p1 - 3 * p2 + p3) * t3);
}

}  // namespace

TriSurface loft_contours(const SvPath& path, std::vector<SvContour> contours, const LoftOptions& o,
                         const std::string& what) {
  if (contours.size() < 2)
    throw InputError(fmt::format("{}: {} contour(s); lofting a vessel needs at least two", what, contours.size()));
  const int N = o.points_per_contour;
  if (N < 8) throw InputError(fmt::format("{}: points_per_contour = {} (at least 8)", what, N));
  // Order along the path: the index of the path point nearest to each centroid.
  struct Ring {
    double station;
    Vector3d tangent;
    std::vector<Vector3d> pts;
  };
  std::vector<Ring> rings;
  for (auto& c : contours) {
    Vector3d cc = centroid(c.points);
    std::size_t best = 0;
    double bd = std::numeric_limits<double>::max();
    for (std::size_t i = 0; i < path.points.size(); ++i) {
      double d = (path.points[i] - cc).squaredNorm();
      if (d < bd) bd = d, best = i;
    }
    Vector3d t = path.points.empty() ? c.path_tangent : path.tangents[best];
    // Fractional station: nearest point plus its offset along the tangent, so
    // contours between two path points still order correctly.
    double station = double(best);
    if (!path.points.empty()) {
      double h = best + 1 < path.points.size() ? (path.points[best + 1] - path.points[best]).norm()
                                               : (path.points[best] - path.points[best - 1]).norm();
      if (h > 0) station += (cc - path.points[best]).dot(t) / h;
    }
    std::vector<Vector3d> p = c.points;
    if (newell_normal(p).dot(t) < 0) std::reverse(p.begin(), p.end());
    rings.push_back({station, t, resample_closed(p, N)});
  }
  std::stable_sort(rings.begin(), rings.end(), [](const Ring& a, const Ring& b) { return a.station < b.station; });
  for (std::size_t i = 1; i < rings.size(); ++i)
    if (std::abs(rings[i].station - rings[i - 1].station) < 1e-9)
      throw InputError(fmt::format("{}: two contours sit at the same place along the path", what));
  // Align each ring's start with the previous ring (relative to centroids).
  for (std::size_t r = 1; r < rings.size(); ++r) {
    const auto& prev = rings[r - 1].pts;
    auto& cur = rings[r].pts;
    Vector3d cp = centroid(prev), cc = centroid(cur);
    int best = 0;
    double bd = std::numeric_limits<double>::max();
    for (int k = 0; k < N; ++k) {
      double d = 0;
      for (int j = 0; j < N; ++j) d += ((cur[std::size_t((j + k) % N)] - cc) - (prev[std::size_t(j)] - cp)).squaredNorm();
      if (d < bd) bd = d, best = k;
    }
    std::rotate(cur.begin(), cur.begin() + best, cur.end());
  }
  // Interpolated rings between consecutive contours.
  double circ = 0;
  for (int j = 0; j < N; ++j) circ += (rings[0].pts[std::size_t((j + 1) % N)] - rings[0].pts[std::size_t(j)]).norm();
  const double h = o.axial_spacing > 0 ? o.axial_spacing : circ / N;
  const std::size_t m = rings.size();
  auto P = [&](long r, int j) -> const Vector3d& {
    return rings[std::size_t(std::clamp<long>(r, 0, long(m) - 1))].pts[std::size_t(j)];
  };
  // The ring count is bounded before anything is allocated: one contour point far off
  // (a damaged coordinate) would otherwise ask for billions of rings.
  constexpr double kMaxRings = 100000;
  double rings_needed = 0;
  for (std::size_t r = 0; r + 1 < m; ++r)
    rings_needed += std::max(1.0, std::ceil((centroid(rings[r + 1].pts) - centroid(rings[r].pts)).norm() / h));
  if (!(rings_needed <= kMaxRings))
    throw InputError(fmt::format("{}: lofting the contours at {:.3g} mm between rings needs {:.3g} rings (at most {:.0f}): the "
                                 "contours span {:.3g} mm; is a coordinate far off or a contour degenerate?",
                                 what, h, rings_needed, kMaxRings, (centroid(rings.back().pts) - centroid(rings.front().pts)).norm()));
  std::vector<std::vector<Vector3d>> all;
  for (std::size_t r = 0; r + 1 < m; ++r) {
    double gap = (centroid(rings[r + 1].pts) - centroid(rings[r].pts)).norm();
    int sub = std::max(1, int(std::ceil(gap / h)));
    for (int s = 0; s < sub; ++s) {
      double t = double(s) / sub;
      std::vector<Vector3d> ring(static_cast<std::size_t>(N));
      for (int j = 0; j < N; ++j) {
        long i = long(r);
        // Ends: reflect the neighbour so the end segment has a natural tangent.
        Vector3d p0 = i > 0 ? P(i - 1, j) : Vector3d(2 * P(i, j) - P(i + 1, j));
        Vector3d p3 = i + 2 < long(m) ? P(i + 2, j) : Vector3d(2 * P(i + 1, j) - P(i, j));
        ring[std::size_t(j)] = catmull_rom(p0, P(i, j), P(i + 1, j), p3, t);
      }
      all.push_back(std::move(ring));
    }
  }
  all.push_back(rings.back().pts);
  TriSurface s;
  for (const auto& ring : all) s.points.insert(s.points.end(), ring.begin(), ring.end());
  for (std::size_t k = 0; k + 1 < all.size(); ++k)
    for (int j = 0; j < N; ++j) {
      int a = int(k) * N + j, b = int(k) * N + (j + 1) % N, c = int(k + 1) * N + (j + 1) % N, d = int(k + 1) * N + j;
      s.triangles.push_back({a, b, c});
      s.triangles.push_back({a, c, d});
    }
  return s;
}

}  // namespace stentsim::segmentation
