// Benchmark of the patient wall meshing (not a test): sections, OCC lofts,
// fragment and gmsh tet meshing of one segmentation (lumen.vtp, wall.vtp,
// centerline.vtp in a folder, e.g. `stentsim phantom --preset case2-rca` +
// `stentsim centerline`), median wall time of several runs, element and node
// counts, mean edge length and quality. Paper (Case 2, 21 mm RCA segment,
// mean size 0.25 mm): 156,590 tet10 elements, 238,123 nodes.
// Every run prints the mesh fingerprint (hash of nodes, connectivity, tags):
// repeated runs on the same input must print the same one. CPU time is the
// process's user + system time of the run (the machine may be shared).
// Usage: bench_patient_mesh DIR [element=tet10] [size=0.25] [runs=3] [out.vtu|-] [algorithm_3d=delaunay] [KEY=VALUE...]
// with KEY one of min_intima, station_spacing, points_per_section, min_size_ratio, min_elements_per_layer
// (PatientMeshOptions; defaults otherwise).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/resource.h>
#include <vector>

#include "common/mesh_data.hpp"
#include "common/mesh_tags.hpp"
#include "meshing/patient_mesh.hpp"

using namespace stentsim;
namespace fs = std::filesystem;

static double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_patient_mesh DIR [element=tet10] [size=0.25] [runs=3] [out.vtu|-] [algorithm_3d=delaunay]\n");
    return 2;
  }
  const fs::path dir = argv[1];
  meshing::PatientMeshOptions o;
  o.element = argc > 2 ? argv[2] : "tet10";
  o.size = argc > 3 ? std::atof(argv[3]) : 0.25;
  const int runs = argc > 4 ? std::atoi(argv[4]) : 3;
  if (argc > 6) o.algorithm_3d = argv[6];
  for (int a = 7; a < argc; ++a) {
    const std::string kv = argv[a];
    const auto eq = kv.find('=');
    const std::string k = kv.substr(0, eq);
    const double v = eq == std::string::npos ? 0.0 : std::atof(kv.c_str() + eq + 1);
    if (k == "min_intima") o.min_intima = v;
    else if (k == "station_spacing") o.station_spacing = v;
    else if (k == "points_per_section") o.points_per_section = int(v);
    else if (k == "min_size_ratio") o.min_size_ratio = v;
    else if (k == "min_elements_per_layer") o.min_elements_per_layer = int(v);
    else {
      std::fprintf(stderr, "bench_patient_mesh: unknown option %s\n", kv.c_str());
      return 2;
    }
  }
  const MeshData lumen = read_vtp((dir / "lumen.vtp").string()), wall = read_vtp((dir / "wall.vtp").string()),
                 cl = read_vtp((dir / "centerline.vtp").string());
  const fs::path msh = fs::temp_directory_path() / "bench_patient_mesh.msh";
  std::vector<double> times, cpu;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    const auto w = meshing::wall_sections(lumen, wall, cl, o);
    const MeshData m = meshing::mesh_wall_sections(w, o, msh);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(cpu_seconds() - c0);
    const auto q = meshing::mesh_quality(m);
    std::size_t tets = 0;
    for (auto n : q.elements_per_layer) tets += n;
    std::printf("run %d: %.2f s (CPU %.2f s), %zu %s, %zu nodes (intima %zu, media %zu, adventitia %zu), %zu sections (smallest gap %.3f of the spacing, thinned rays %.3f), "
                "mean edge %.4f mm, min scaled Jacobian %.3f (%s, at %.2f %.2f %.2f), min Jacobian ratio %.3f, "
                "max aspect ratio %.2f (%s, at %.2f %.2f %.2f), fingerprint %s\n",
                r + 1, times.back(), cpu.back(), tets, o.element.c_str(), m.points.size(), q.elements_per_layer[tags::intima],
                q.elements_per_layer[tags::media], q.elements_per_layer[tags::adventitia], w.origin.size(),
                w.min_gap_ratio, w.clamped_fraction, q.mean_edge_length, q.min_scaled_jacobian, tags::layer_name(q.worst_sj_layer), q.worst_sj_position.x(),
                q.worst_sj_position.y(), q.worst_sj_position.z(), q.min_jacobian_ratio, q.max_aspect_ratio,
                tags::layer_name(q.worst_ar_layer), q.worst_ar_position.x(), q.worst_ar_position.y(), q.worst_ar_position.z(),
                meshing::mesh_fingerprint(m).c_str());
    if (r + 1 == runs && argc > 5 && std::string(argv[5]) != "-") write_vtu(argv[5], m);
  }
  fs::remove(msh);
  std::sort(times.begin(), times.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf("%s: %s size %.3f mm, min_intima %.3f mm, %s: median meshing time %.2f s over %d runs (min %.2f, max %.2f), median CPU %.2f s\n",
              dir.string().c_str(), o.element.c_str(), o.size, o.min_intima, o.algorithm_3d.c_str(), times[times.size() / 2], runs,
              times.front(), times.back(), cpu[cpu.size() / 2]);
  return 0;
}
