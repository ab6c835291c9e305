// `stentsim mesh`: the patient wall mesh stage as a tool of its own.
#include <cstdio>

#include "common/summary.hpp"
#include "meshing/patient_mesh.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "workflows/cli/commands.hpp"

namespace stentsim::cli {

void register_mesh(CLI::App& app) {
  struct Args {
    std::string lumen, wall, centerline, out;
    meshing::PatientMeshOptions o;
  };
  auto a = std::make_shared<Args>();
  auto* c = app.add_subcommand("mesh", "Layered tet mesh of a patient wall: artery.vtu and artery.msh (gmsh 4.1)");
  c->add_option("--lumen", a->lumen, "lumen.vtp")->required();
  c->add_option("--wall", a->wall, "wall.vtp")->required();
  c->add_option("--centerline", a->centerline, "centerline.vtp (ParallelTransportNormals)")->required();
  c->add_option("--out", a->out, "Output folder")->required();
  c->add_option("--element", a->o.element, "tet10 or tet4")->check(CLI::IsMember({"tet10", "tet4"}));
  c->add_option("--size", a->o.size, "Target element size in mm")->check(CLI::PositiveNumber);
  c->add_option("--min-elements-per-layer", a->o.min_elements_per_layer, "Elements through each layer");
  c->add_option("--media-ratio", a->o.media_ratio, "Media thickness / local outer diameter (0: no media)");
  c->add_option("--adventitia-ratio", a->o.adventitia_ratio, "Adventitia thickness / local outer diameter (0: none)");
  c->add_option("--min-intima", a->o.min_intima, "Thinnest intima in mm");
  c->add_option("--min-size-ratio", a->o.min_size_ratio,
                "Smallest local element size as a fraction of --size (the floor --min-elements-per-layer may not undercut)")
      ->check(CLI::Range(1e-3, 1.0));
  c->add_flag("!--no-intima", a->o.intima, "Media reaches the lumen (no intima)");
  c->add_option("--station-spacing", a->o.station_spacing, "Distance of the lofted cross-sections in mm");
  c->add_option("--min-scaled-jacobian", a->o.min_scaled_jacobian, "Quality bound");
  c->add_option("--min-section-gap-ratio", a->o.min_section_gap_ratio,
                "Smallest gap between consecutive sections at the outer wall, as a fraction of their spacing");
  c->add_option("--max-elements", a->o.max_elements, "Refuse a mesh estimated above this many tets (before gmsh runs)")
      ->check(CLI::Range(1.0, 1e9));
  c->add_option("--algorithm-3d", a->o.algorithm_3d, "gmsh 3D mesher: delaunay (reproducible) or hxt (gmsh 4.8: not reproducible)")
      ->check(CLI::IsMember({"delaunay", "hxt"}));
  on(c, [a] {
    Summary summary;
    const std::filesystem::path out(a->out);
    // The case path's surface checks (there its segmentation stage runs them):
    // a damaged or mis-scaled surface fails here, naming its file, before gmsh sees it.
    const auto lumen = segmentation::load_stage_lumen(a->lumen, "stentsim mesh");
    const auto wall = segmentation::load_stage_surface(a->wall, "stentsim mesh");
    segmentation::check_stage_wall(lumen, wall, a->lumen, a->wall, "stentsim mesh");
    std::filesystem::create_directories(out);
    meshing::run_patient_mesh(a->lumen, a->wall, a->centerline, a->o, out / "artery.vtu", out / "artery.msh", summary);
    summary.write(out / "summary.yaml");
    std::printf("wrote %s/artery.vtu and artery.msh\n", a->out.c_str());
    return 0;
  });
}

}  // namespace stentsim::cli
