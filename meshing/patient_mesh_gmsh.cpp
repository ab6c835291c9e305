// gmsh adapter of the patient wall mesh: OCC loft of every interface through
// the cross-sections, fragment into conforming layer volumes, tet meshing.
// The only file of meshing/ that includes gmsh.h.
#include <fmt/format.h>
#include <gmsh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "common/error.hpp"
#include "common/log.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"

namespace stentsim::meshing {

using Eigen::Vector3d;

namespace {

struct GmshSession {
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    // One thread everywhere (1D, 2D and 3D meshing in parallel over
    // entities would make the result depend on the schedule).
    gmsh::option::setNumber("General.NumThreads", 1);
    for (const char* k : {"Mesh.MaxNumThreads1D", "Mesh.MaxNumThreads2D", "Mesh.MaxNumThreads3D"}) gmsh::option::setNumber(k, 1);
  }
  // gmsh::finalize may throw (a std::string in gmsh 4.8); from a destructor
  // during unwinding that would terminate the process.
  ~GmshSession() {
    try {
      gmsh::finalize();
    } catch (...) {
    }
  }
};

/// Nearest station and ray of a point: the local layer radii there.
struct SectionLookup {
  const WallSections& w;
  std::pair<std::size_t, std::size_t> nearest(const Vector3d& x) const {
    std::size_t best = 0;
    double bd = 1e300;
    for (std::size_t s = 0; s < w.origin.size(); ++s) {
      const Vector3d d = x - w.origin[s];
      const double a = d.dot(w.tangent[s]);
      const double dd = a * a + 0.01 * (d - a * w.tangent[s]).squaredNorm();  // favour the plane the point lies in
      if (dd < bd) bd = dd, best = s;
    }
    const Vector3d d = x - w.origin[best];
    double th = std::atan2(d.dot(w.binormal[best]), d.dot(w.normal[best]));
    if (th < 0) th += 2 * std::numbers::pi;
    const std::size_t n = w.radius[best][0].size();
    return {best, std::size_t(std::lround(th / (2 * std::numbers::pi) * double(n))) % n};
  }
  double radial(const Vector3d& x, std::size_t s) const {
    const Vector3d d = x - w.origin[s];
    return (d - d.dot(w.tangent[s]) * w.tangent[s]).norm();
  }
};

}  // namespace

namespace {

MeshData loft_and_mesh(const WallSections& w, const PatientMeshOptions& o, const std::filesystem::path& msh);

/// gmsh 4.8 reports some failures (OCC lofts and booleans, tetgen's boundary
/// recovery) by throwing a std::string or other non-std objects: each becomes
/// a ComputeError with gmsh's last message, read while the session is open.
MeshData mesh_with_gmsh(const WallSections& w, const PatientMeshOptions& o, const std::filesystem::path& msh) {
  GmshSession session;
  auto failed = [](const std::string& what) {
    std::string last;
    try {
      gmsh::logger::getLastError(last);
    } catch (...) {
    }
    return ComputeError(fmt::format("mesh: gmsh failed to loft or mesh the wall ({}{}{})", what,
                                    last.empty() || last == what ? "" : ": ", last == what ? "" : last));
  };
  try {
    return loft_and_mesh(w, o, msh);
  } catch (const std::exception&) {
    throw;
  } catch (const std::string& e) {
    throw failed(e);
  } catch (const char* e) {
    throw failed(e);
  } catch (...) {
    throw failed("no message");
  }
}

MeshData loft_and_mesh(const WallSections& w, const PatientMeshOptions& o, const std::filesystem::path& msh) {
  namespace occ = gmsh::model::occ;
  gmsh::model::add("artery");
  const std::size_t ns = w.origin.size(), nk = w.radius[0].size(), nr = w.radius[0][0].size();
  // One closed interpolating spline per station and surface; a solid loft per
  // surface (lumen, interfaces, outer wall). The rays start at the same
  // parallel-transported normal in every section, so the lofts do not twist.
  // Every other surface's splines start half a turn round (the same ray in
  // all its sections). With a common start the nested lofts share their
  // seam and parametrization, gmsh's 2D mesher gives them nearly the same
  // triangulation, edges of neighbouring interfaces lie radially over one
  // another, and the 3D Delaunay leaves flat tets (two nodes on each
  // interface, antiparallel edges) that its optimizer does not swap out:
  // case2-rca, tet10 0.25 mm, min_intima 0.05 mm: scaled Jacobian 0.054,
  // aspect ratio 21 in the media; a 0.05 mm intima on a straight tube:
  // 0.052 / 22 (test_meshing_patient_thin_intima).
  const std::size_t seam_step = nr / 2;
  std::vector<int> solids;
  for (std::size_t k = 0; k < nk; ++k) {
    std::vector<int> wires;
    const std::size_t seam = (k % 2) * seam_step;
    for (std::size_t s = 0; s < ns; ++s) {
      std::vector<int> pts;
      for (std::size_t i = 0; i < nr; ++i) {
        const Vector3d x = w.point(s, k, (i + seam) % nr);
        pts.push_back(occ::addPoint(x.x(), x.y(), x.z()));
      }
      pts.push_back(pts.front());
      wires.push_back(occ::addWire({occ::addSpline(pts)}));
    }
    gmsh::vectorpair out;
    occ::addThruSections(wires, out, -1, true, false);
    int vol = -1;
    for (auto& [d, t] : out)
      if (d == 3) vol = t;
    if (vol < 0) throw ComputeError(fmt::format("mesh: the OCC loft of surface {} gave no solid", k));
    solids.push_back(vol);
  }
  // Fragment: nested solids become the lumen core and one shell per layer with
  // shared interface faces (a conforming mesh).
  gmsh::vectorpair obj = {{3, solids[0]}}, tools, out;
  for (std::size_t k = 1; k < nk; ++k) tools.push_back({3, solids[k]});
  std::vector<gmsh::vectorpair> outMap;
  occ::fragment(obj, tools, out, outMap);
  std::map<int, int> count;  // fragment volume -> number of input solids containing it
  for (const auto& children : outMap)
    for (auto& [d, t] : children)
      if (d == 3) ++count[t];
  std::map<int, std::vector<int>> layer_volumes;
  gmsh::vectorpair lumen_core;
  for (auto& [t, c] : count) {
    const int inner = int(nk) - c;  // innermost surface enclosing it
    if (inner == 0) lumen_core.push_back({3, t});
    else layer_volumes[w.layers[std::size_t(inner - 1)]].push_back(t);
  }
  if (layer_volumes.size() != w.layers.size())
    throw ComputeError(fmt::format("mesh: fragmenting the lofts gave {} layers instead of {} (interfaces crossing?)",
                                   layer_volumes.size(), w.layers.size()));
  occ::remove(lumen_core, true);
  occ::synchronize();

  for (auto& [L, vols] : layer_volumes) {
    gmsh::model::addPhysicalGroup(3, vols, L);
    gmsh::model::setPhysicalName(3, L, tags::layer_name(L));
  }
  // Exterior faces: proximal/distal caps lie in the first/last section plane;
  // the others are the endothelium or the outer wall by their radius.
  gmsh::vectorpair all, bnd;
  for (auto& [L, vols] : layer_volumes)
    for (int v : vols) all.push_back({3, v});
  gmsh::model::getBoundary(all, bnd, true, false, false);
  std::map<int, std::vector<int>> groups;
  const SectionLookup look{w};
  const double D = 2 * w.radius[0][nk - 1][0];
  for (auto& [d, t] : bnd) {
    std::vector<double> lo, hi, x;
    gmsh::model::getParametrizationBounds(2, std::abs(t), lo, hi);
    gmsh::model::getValue(2, std::abs(t), {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])}, x);
    const Vector3d p(x[0], x[1], x[2]);
    int g;
    if (std::abs((p - w.origin.front()).dot(w.tangent.front())) < 1e-4 * D) g = tags::proximal_cut;
    else if (std::abs((p - w.origin.back()).dot(w.tangent.back())) < 1e-4 * D) g = tags::distal_cut;
    else {
      auto [s, i] = look.nearest(p);
      const double r = look.radial(p, s);
      g = std::abs(r - w.radius[s][0][i]) < std::abs(r - w.radius[s][nk - 1][i]) ? tags::endothelium : tags::outer_wall;
    }
    groups[g].push_back(std::abs(t));
  }
  for (int g : {tags::endothelium, tags::outer_wall, tags::proximal_cut, tags::distal_cut}) {
    if (!groups.count(g)) throw ComputeError(fmt::format("mesh: no {} surface found on the lofted wall", tags::face_group_name(g)));
    gmsh::model::addPhysicalGroup(2, groups[g], g);
    gmsh::model::setPhysicalName(2, g, tags::face_group_name(g));
  }

  // Local size, through the thickness: in each layer the target, but at most
  // that layer's local thickness / min_elements_per_layer, not below
  // min_size_ratio * size. For n >= 2 check_layer_sizing has rejected the
  // settings where the floor would bite, so the clamp never drops the count;
  // for n = 1 it is a floor only (one element through holds anyway). Sizing every layer by the thinnest one at the ray
  // (the first version) refined the whole case2-rca wall to the thin intima's
  // size: 307,840 tet10 at 0.25 mm against the paper's 156,590. A point on an
  // interface (within a quarter of the smallest size) takes the finer of the
  // two layers, so the shared faces are sized for both.
  const double hmin = o.min_size_ratio * o.size;
  gmsh::model::mesh::setSizeCallback([&](int, int, double x, double y, double z) {
    const Vector3d p(x, y, z);
    auto [s, i] = look.nearest(p);
    const double r = look.radial(p, s), tol = 0.25 * hmin;
    double h = o.size;
    for (std::size_t k = 0; k + 1 < nk; ++k) {
      const double lo = w.radius[s][k][i], hi = w.radius[s][k + 1][i];
      const bool inside = r >= lo - tol && r <= hi + tol;
      const bool innermost_below = k == 0 && r < lo, outermost_above = k + 2 == nk && r > hi;
      if (inside || innermost_below || outermost_above) h = std::min(h, (hi - lo) / o.min_elements_per_layer);
    }
    return std::clamp(h, hmin, o.size);  // a no-op for n >= 2 (check_layer_sizing; same section radii)
  });
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  // The classic Delaunay by default: it is reproducible (gmsh orders its
  // nodes by number and seeds its random perturbation). gmsh 4.8's HXT
  // adapter collects the surface nodes in a std::set<MVertex*> ordered by
  // address (gmsh issue 2255, fixed in 4.12), so its meshes change with the
  // heap layout: case2-rca tet10 at 0.25 mm gave 118,614 and 118,557 tets in
  // two runs of one process. HXT gave better shapes there (max aspect ratio
  // 3.6 instead of 15, min scaled Jacobian 0.092 instead of 0.076; raising
  // Mesh.OptimizeThreshold to 0.6 did not help the classic one).
  gmsh::option::setNumber("Mesh.Algorithm3D", o.algorithm_3d == "hxt" ? 10 : 1);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  // Three of gmsh's Laplacian smoothing passes (default 1) on the 2D meshes:
  // with 1 pass the coarse moderate-bend test (test_meshing_patient_checks)
  // kept a tet at scaled Jacobian 0.028, with 3 passes 0.144.
  gmsh::option::setNumber("Mesh.Smoothing", 3);
  gmsh::option::setNumber("Mesh.ElementOrder", o.element == "tet10" ? 2 : 1);
  gmsh::option::setNumber("Mesh.SecondOrderLinear", 1);  // midside nodes on straight edges: projecting them onto the lofted B-spline faces took > 10 min on case2-rca
  // gmsh's API default (AbortOnError 2) throws a std::string from Msg::Error;
  // thrown inside the mesher's OpenMP regions it cannot be caught and
  // terminates the process (seen on a real vessel). 1: an error aborts the
  // meshing, the call returns, and the error is read from the logger.
  gmsh::option::setNumber("General.AbortOnError", 1);
  gmsh::logger::start();
  try {
    gmsh::model::mesh::generate(3);
    std::string last;
    gmsh::logger::getLastError(last);
    if (!last.empty()) throw ComputeError(fmt::format("mesh: gmsh failed to mesh the layers ({})", last));
  } catch (const ComputeError&) {
    throw;
  } catch (const std::exception& e) {
    throw ComputeError(fmt::format("mesh: gmsh failed: {}", e.what()));
  } catch (...) {
    // gmsh 4.8 throws non-std exceptions (e.g. tetgen's boundary recovery on
    // overlapping facets where two lofted interfaces come too close).
    std::string last;
    gmsh::logger::getLastError(last);
    throw ComputeError(fmt::format("mesh: gmsh failed to mesh the layers ({}); try a smaller mesh.size or a larger "
                                   "mesh.min_intima", last.empty() ? "no message" : last));
  }
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.SaveAll", 0);
  gmsh::write(msh.string());

  // Export: compact node numbering over the physical volumes' nodes.
  MeshData m;
  std::map<std::size_t, std::int64_t> node_index;
  std::vector<std::size_t> ntags;
  std::vector<double> coord, par;
  gmsh::model::mesh::getNodes(ntags, coord, par, -1, -1, false, false);
  std::map<std::size_t, Vector3d> xyz;
  for (std::size_t i = 0; i < ntags.size(); ++i) xyz[ntags[i]] = Vector3d(coord[3 * i], coord[3 * i + 1], coord[3 * i + 2]);
  auto idx = [&](std::size_t tag) {
    auto [it, fresh] = node_index.try_emplace(tag, std::int64_t(m.points.size()));
    if (fresh) m.points.push_back(xyz.at(tag));
    return it->second;
  };
  const bool quad = o.element == "tet10";
  const int tet_type = quad ? 11 : 4, tri_type = quad ? 9 : 2;
  const int tet_n = quad ? 10 : 4, tri_n = quad ? 6 : 3;
  std::vector<double> layer, face;
  // Face key (sorted corners) -> the centroid of its tet, to orient faces outward.
  std::map<std::array<std::int64_t, 3>, Vector3d> tet_of_face;
  for (auto& [L, vols] : layer_volumes)
    for (int v : vols) {
      std::vector<std::size_t> et, en;
      gmsh::model::mesh::getElementsByType(tet_type, et, en, v);
      for (std::size_t e = 0; e < et.size(); ++e) {
        std::vector<std::int64_t> c(static_cast<std::size_t>(tet_n));
        for (int j = 0; j < tet_n; ++j) c[std::size_t(j)] = idx(en[e * std::size_t(tet_n) + std::size_t(j)]);
        if (quad) std::swap(c[8], c[9]);  // gmsh edge 8 is (2,3) and 9 is (1,3); VTK the reverse
        const Vector3d ctr = (m.points[std::size_t(c[0])] + m.points[std::size_t(c[1])] + m.points[std::size_t(c[2])] +
                              m.points[std::size_t(c[3])]) / 4;
        static const int fv[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
        for (auto& f : fv) {
          std::array<std::int64_t, 3> k = {c[std::size_t(f[0])], c[std::size_t(f[1])], c[std::size_t(f[2])]};
          std::sort(k.begin(), k.end());
          tet_of_face[k] = ctr;
        }
        m.add_cell(quad ? CellType::quadratic_tetra : CellType::tetra, c);
        layer.push_back(L);
        face.push_back(tags::no_face);
      }
    }
  for (auto& [g, surfs] : groups)
    for (int sf : surfs) {
      std::vector<std::size_t> et, en;
      gmsh::model::mesh::getElementsByType(tri_type, et, en, sf);
      for (std::size_t e = 0; e < et.size(); ++e) {
        std::vector<std::int64_t> c(static_cast<std::size_t>(tri_n));
        for (int j = 0; j < tri_n; ++j) c[std::size_t(j)] = idx(en[e * std::size_t(tri_n) + std::size_t(j)]);
        std::array<std::int64_t, 3> k = {c[0], c[1], c[2]};
        std::sort(k.begin(), k.end());
        auto it = tet_of_face.find(k);
        if (it == tet_of_face.end()) throw ComputeError(fmt::format("mesh: a {} triangle has no tetrahedron", tags::face_group_name(g)));
        const Vector3d a = m.points[std::size_t(c[0])], b = m.points[std::size_t(c[1])], cc = m.points[std::size_t(c[2])];
        if ((b - a).cross(cc - a).dot((a + b + cc) / 3 - it->second) < 0) {  // wind so the normal leaves the tet
          std::swap(c[1], c[2]);
          if (quad) std::swap(c[3], c[5]);
        }
        m.add_cell(quad ? CellType::quadratic_triangle : CellType::triangle, c);
        layer.push_back(tags::no_layer);
        face.push_back(g);
      }
    }
  gmsh::model::mesh::removeSizeCallback();
  m.cell_data[tags::kLayer] = {1, std::move(layer)};
  m.cell_data[tags::kFaceGroup] = {1, std::move(face)};
  m.field_text["units"] = "mm";
  m.field_text["description"] = fmt::format("patient artery wall: {} layers, {} (gmsh OCC loft of {} sections)",
                                            w.layers.size(), o.element, ns);
  return m;
}

}  // namespace

MeshData mesh_wall_sections(const WallSections& w, const PatientMeshOptions& o, const std::filesystem::path& msh) {
  validate(o);
  check_wall_sections(w, o.min_section_gap_ratio);
  check_layer_sizing(w, o);
  log::info("mesh: lofting {} sections of {} surfaces and meshing them with gmsh ({}, size {} mm)", w.origin.size(),
            w.radius.empty() ? 0 : w.radius[0].size(), o.element, o.size);
  return mesh_with_gmsh(w, o, msh);
}

}  // namespace stentsim::meshing
