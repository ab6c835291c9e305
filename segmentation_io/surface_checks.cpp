// Checks and repairs of a segmented lumen or wall surface (issue 3).
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/self_intersection.hpp"
#include "segmentation_io/surface_input.hpp"

namespace stentsim::segmentation {

using Eigen::Vector3d;

namespace {

// A setting as the user writes it: a case key "input.surface.units: cm", a command-line
// option "--units cm".
std::string units_setting(const std::string& key, const std::string& value) {
  return key.rfind("--", 0) == 0 ? key + " " + value : key + ": " + value;
}


std::string at(const Vector3d& p) { return fmt::format("({:.3f}, {:.3f}, {:.3f}) mm", p.x(), p.y(), p.z()); }

Vector3d triangle_centroid(const TriSurface& s, const std::array<int, 3>& t) {
  return (s.points[t[0]] + s.points[t[1]] + s.points[t[2]]) / 3.0;
}

// Merges points closer than `tol` (grid hashing with neighbour cells).
int merge_points(TriSurface& s, double tol) {
  if (tol <= 0) return 0;
  struct Hash {
    std::size_t operator()(const std::array<long long, 3>& k) const {
      return std::size_t(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
    }
  };
  std::unordered_map<std::array<long long, 3>, std::vector<int>, Hash> grid;
  std::vector<int> map(s.points.size());
  std::vector<Vector3d> kept;
  auto cell = [&](const Vector3d& p) {
    return std::array<long long, 3>{(long long)std::floor(p.x() / tol), (long long)std::floor(p.y() / tol),
                                    (long long)std::floor(p.z() / tol)};
  };
  int merged = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    auto c = cell(s.points[i]);
    int found = -1;
    for (long long dx = -1; dx <= 1 && found < 0; ++dx)
      for (long long dy = -1; dy <= 1 && found < 0; ++dy)
        for (long long dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == grid.end()) continue;
          for (int j : it->second)
            if ((kept[j] - s.points[i]).norm() <= tol) {
              found = j;
              break;
            }
        }
    if (found >= 0) {
      map[i] = found;
      ++merged;
    } else {
      map[i] = int(kept.size());
      grid[c].push_back(int(kept.size()));
      kept.push_back(s.points[i]);
    }
  }
  for (auto& t : s.triangles)
    for (int& v : t) v = map[v];
  s.points = std::move(kept);
  return merged;
}

std::pair<int, int> edge_key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

}  // namespace

TriSurface check_and_repair(TriSurface s, const SurfaceCheckOptions& o, const std::string& what, SurfaceReport& rep) {
  auto fail = [&](const std::string& msg) { throw InputError(fmt::format("{}: {}", what, msg)); };
  auto repairable = [&](const std::string& msg) {
    if (!o.repair) fail(msg + " (" + o.repair_off_note + ")");
    rep.notes.push_back(msg);
    log::warn("{}: repaired: {}", what, msg);
  };

  // Units: scale to mm, then check the size is that of a coronary artery.
  const double scale = unit_length_in_mm(o.units);
  for (auto& p : s.points) p *= scale;
  const double diag = bounding_box_diagonal(s);
  if (diag < o.min_size || diag > o.max_size) {
    const std::string u = likely_units(diag, o.units, o.min_size, o.max_size);
    const std::string hint = u.empty() ? "" : fmt::format("; the file looks like it is in {}: set {}", unit_word(u), units_setting(o.units_key, u));
    fail(fmt::format("the surface spans {:.4g} mm (bounding-box diagonal) with units '{}', but a coronary segment spans "
                     "{:g} to {:g} mm{}", diag, o.units, o.min_size, o.max_size, hint));
  }

  // Duplicate points.
  rep.merged_points = merge_points(s, o.merge_tolerance * diag);
  if (rep.merged_points > 0) repairable(fmt::format("{} duplicate points merged", rep.merged_points));

  // Degenerate and duplicate triangles.
  {
    std::vector<std::array<int, 3>> keep;
    std::set<std::array<int, 3>> seen;
    const double min_area = 1e-12 * diag * diag;
    Vector3d first_degenerate, first_duplicate;
    for (const auto& t : s.triangles) {
      double area = 0.5 * (s.points[t[1]] - s.points[t[0]]).cross(s.points[t[2]] - s.points[t[0]]).norm();
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area <= min_area) {
        if (rep.degenerate_triangles++ == 0) first_degenerate = triangle_centroid(s, t);
        continue;
      }
      std::array<int, 3> sorted = t;
      std::sort(sorted.begin(), sorted.end());
      if (!seen.insert(sorted).second) {
        if (rep.duplicate_triangles++ == 0) first_duplicate = triangle_centroid(s, t);
        continue;
      }
      keep.push_back(t);
    }
    if (keep.empty())
      fail(fmt::format("all {} triangles are degenerate (zero area: repeated or collinear corners) or duplicates; nothing "
                       "of a surface is left — re-export it from the segmentation tool", s.triangles.size()));
    s.triangles = std::move(keep);
    if (rep.degenerate_triangles)
      repairable(fmt::format("{} degenerate (zero-area) triangles removed, the first at {}", rep.degenerate_triangles,
                             at(first_degenerate)));
    if (rep.duplicate_triangles)
      repairable(fmt::format("{} duplicated triangles removed, the first at {}", rep.duplicate_triangles,
                             at(first_duplicate)));
  }

  // Non-manifold edges: no repair (which sheet is the lumen is not ours to guess).
  std::map<std::pair<int, int>, std::vector<int>> edge_tris;
  auto build_edges = [&] {
    edge_tris.clear();
    for (std::size_t i = 0; i < s.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) edge_tris[edge_key(s.triangles[i][k], s.triangles[i][(k + 1) % 3])].push_back(int(i));
  };
  build_edges();
  {
    int count = 0;
    Vector3d first;
    for (const auto& [e, tris] : edge_tris)
      if (tris.size() > 2 && count++ == 0) first = 0.5 * (s.points[e.first] + s.points[e.second]);
    if (count > 0)
      fail(fmt::format("{} non-manifold edges (shared by more than two triangles), the first at {}; the surface must "
                       "be a single sheet — fix it in the segmentation tool", count, at(first)));
  }

  // Connected pieces (through shared edges).
  {
    const std::size_t n = s.triangles.size();
    std::vector<int> piece(n, -1);
    std::vector<double> area;
    std::vector<Vector3d> where;
    for (std::size_t seed = 0; seed < n; ++seed) {
      if (piece[seed] >= 0) continue;
      int id = int(area.size());
      area.push_back(0);
      where.push_back(triangle_centroid(s, s.triangles[seed]));
      std::vector<int> stack{int(seed)};
      piece[seed] = id;
      while (!stack.empty()) {
        int t = stack.back();
        stack.pop_back();
        const auto& tri = s.triangles[t];
        area[id] += 0.5 * (s.points[tri[1]] - s.points[tri[0]]).cross(s.points[tri[2]] - s.points[tri[0]]).norm();
        for (int k = 0; k < 3; ++k)
          for (int u : edge_tris[edge_key(tri[k], tri[(k + 1) % 3])])
            if (piece[u] < 0) piece[u] = id, stack.push_back(u);
      }
    }
    if (area.size() > 1) {
      int main = int(std::max_element(area.begin(), area.end()) - area.begin());
      double total = std::accumulate(area.begin(), area.end(), 0.0);
      std::string list;
      int large = 0;
      for (std::size_t i = 0; i < area.size(); ++i) {
        list += fmt::format("\n  piece {}: {:.3g} mm² near {}", i, area[i], at(where[i]));
        if (int(i) != main && area[i] >= o.small_piece_fraction * total) ++large;
      }
      if (large > 0)
        fail(fmt::format("the surface has {} disconnected pieces; one vessel segment was expected (join or remove "
                         "them in the segmentation tool):{}", area.size(), list));
      std::vector<std::array<int, 3>> keep;
      for (std::size_t i = 0; i < n; ++i)
        if (piece[i] == main) keep.push_back(s.triangles[i]);
      rep.pieces_dropped = int(area.size()) - 1;
      s.triangles = std::move(keep);
      repairable(fmt::format("{} small disconnected pieces (< {:g} % of the area) dropped:{}", rep.pieces_dropped,
                             100 * o.small_piece_fraction, list));
      build_edges();
    }
  }

  // Consistent orientation: flood from the first triangle, turning any
  // neighbour that runs a shared edge in the same direction.
  {
    const std::size_t n = s.triangles.size();
    std::vector<char> done(n, 0);
    std::vector<int> stack{0};
    done[0] = 1;
    auto has_directed = [](const std::array<int, 3>& t, int a, int b) {
      for (int k = 0; k < 3; ++k)
        if (t[k] == a && t[(k + 1) % 3] == b) return true;
      return false;
    };
    while (!stack.empty()) {
      int t = stack.back();
      stack.pop_back();
      const auto tri = s.triangles[t];
      for (int k = 0; k < 3; ++k) {
        int a = tri[k], b = tri[(k + 1) % 3];
        for (int u : edge_tris[edge_key(a, b)]) {
          if (u == t) continue;
          bool same = has_directed(s.triangles[u], a, b);
          if (done[u]) {
            if (same)
              fail(fmt::format("the surface cannot be oriented consistently (a Möbius-like twist near {})",
                               at(0.5 * (s.points[a] + s.points[b]))));
            continue;
          }
          if (same) {
            std::swap(s.triangles[u][1], s.triangles[u][2]);
            ++rep.orientation_flips;
          }
          done[u] = 1;
          stack.push_back(u);
        }
      }
    }
    if (rep.orientation_flips)
      repairable(fmt::format("{} triangles turned to agree with their neighbours' orientation", rep.orientation_flips));
  }

  // Open boundaries: the tube ends, and holes.
  auto loops = boundary_loops(s);
  if (int(loops.size()) < o.expected_open_ends) {
    fail(fmt::format("the surface has {} open ends but {} were expected: a lumen must be open at its proximal and distal "
                     "cuts (for a closed tree, extract a branch first)", loops.size(), o.expected_open_ends));
  }
  if (int(loops.size()) > o.expected_open_ends) {
    double end_perimeter = o.expected_open_ends > 0 ? loops[std::size_t(o.expected_open_ends) - 1].perimeter : 0;
    std::string list;
    bool all_small = true;
    for (std::size_t i = std::size_t(o.expected_open_ends); i < loops.size(); ++i) {
      list += fmt::format("\n  open boundary at {}, perimeter {:.3g} mm", at(loops[i].centroid), loops[i].perimeter);
      if (o.expected_open_ends > 0 && loops[i].perimeter >= o.small_hole_fraction * end_perimeter) all_small = false;
      if (o.expected_open_ends == 0) all_small = loops[i].perimeter < 0.1 * diag && all_small;
    }
    int holes = int(loops.size()) - o.expected_open_ends;
    if (!all_small || !o.repair)
      fail(fmt::format("the surface has {} open boundaries but {} open ends were expected; the extra ones are holes "
                       "or further branches{}:{}", loops.size(), o.expected_open_ends,
                       o.repair ? " too large to fill" : " (" + o.repair_off_note + ")", list));
    std::vector<BoundaryLoop> holes_only(loops.begin() + o.expected_open_ends, loops.end());
    s = capped(s, holes_only);
    rep.holes_filled = holes;
    repairable(fmt::format("{} holes filled:{}", holes, list));
    loops.resize(std::size_t(o.expected_open_ends));
  }
  rep.open_ends = int(loops.size());

  // Outward normals: the closed (capped) surface must enclose a positive volume.
  if (signed_volume(capped(s, loops)) < 0) {
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
    rep.normals_inverted = true;
    repairable("normals pointed inward; all triangles turned outward");
  }

  if (o.check_self_intersections) {
    auto pairs = self_intersecting_triangles(s.points, s.triangles, 20);
    if (!pairs.empty())
      fail(fmt::format("the surface intersects itself ({}{} pairs of triangles, the first near {}); fix it in the "
                       "segmentation tool (e.g. smooth or remesh the region)", pairs.size() >= 20 ? "at least " : "",
                       pairs.size(), at(triangle_centroid(s, s.triangles[std::size_t(pairs[0].first)]))));
  }

  // Drop points no triangle uses (left by merging, dropped pieces or the file).
  std::vector<int> index(s.points.size(), -1);
  std::vector<Vector3d> used;
  for (auto& t : s.triangles)
    for (int& v : t) {
      if (index[v] < 0) index[v] = int(used.size()), used.push_back(s.points[v]);
      v = index[v];
    }
  s.points = std::move(used);
  return s;
}

std::string unit_word(const std::string& u) {
  return u == "mm" ? "millimetres" : u == "cm" ? "centimetres" : u == "m" ? "metres" : u == "um" ? "micrometres" : u;
}

std::string likely_units(double value_mm, const std::string& declared, double lo_mm, double hi_mm) {
  const double in_file = value_mm / unit_length_in_mm(declared);
  for (const char* u : {"mm", "cm", "m", "um"}) {
    if (u == declared) continue;
    const double v = in_file * unit_length_in_mm(u);
    if (v >= lo_mm && v <= hi_mm) return u;
  }
  return "";
}

void check_reference_diameter_units(double d, const std::string& declared, const std::string& what,
                                    const std::string& units_key) {
  if (d >= kMinReferenceDiameter && d <= kMaxReferenceDiameter) return;
  const std::string u = likely_units(d, declared, kMinReferenceDiameter, kMaxReferenceDiameter);
  throw InputError(fmt::format(
      "{}: the lumen's reference diameter is {:.4g} mm with {}, but a coronary lumen's is about {:g} to {:g} mm{}",
      what, d, units_setting(units_key, declared), kMinReferenceDiameter, kMaxReferenceDiameter,
      u.empty() ? fmt::format("; check the file's units ({}) or the region of interest", units_key)
                : fmt::format("; the file looks like it is in {}: set {}", unit_word(u), units_setting(units_key, u))));
}

}  // namespace stentsim::segmentation
