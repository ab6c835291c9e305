// `stentsim fibers`: the patient fiber stage as a tool of its own — harmonic
// lifting on a wall mesh (artery.vtu with Layer and FaceGroup) along its
// lumen centerline, written as fibers.vtu (+ summary.yaml beside it).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/mesh_tags.hpp"
#include "common/summary.hpp"
#include "fibers/harmonic_fibers.hpp"
#include "workflows/cli/commands.hpp"

namespace fs = std::filesystem;

namespace stentsim::cli {

void register_fibers(CLI::App& app) {
  struct Args {
    std::string mesh, centerline, out, solver = solver::linear_solver_name(fibers::HarmonicFiberOptions{}.linear_solver);
    double intima = 0, media = 0, adventitia = 40, weight = 0.5;  // deg from circumferential (paper 4.2)
    bool quadratic = false;
  };
  auto a = std::make_shared<Args>();
  auto* sub = app.add_subcommand("fibers", "Fiber field of a wall mesh by harmonic lifting: fibers.vtu");
  sub->add_option("--mesh", a->mesh, "artery.vtu (cell arrays Layer, FaceGroup)")->required()->check(CLI::ExistingFile);
  sub->add_option("--centerline", a->centerline, "centerline.vtp (lumen centerline polyline)")->required()->check(CLI::ExistingFile);
  sub->add_option("--out", a->out, "Output fibers.vtu")->required();
  sub->add_option("--intima-angle", a->intima, "Intima fiber angle from circumferential, deg")->capture_default_str();
  sub->add_option("--media-angle", a->media, "Media fiber angle from circumferential, deg")->capture_default_str();
  sub->add_option("--adventitia-angle", a->adventitia, "Adventitia fiber angle (+/-) from circumferential, deg")->capture_default_str();
  sub->add_option("--centerline-weight", a->weight, "Weight of the centerline tangent vs grad of the longitudinal coordinate (0..1)")
      ->capture_default_str();
  sub->add_option("--linear-solver", a->solver, "Linear solver of the Laplace problems")
      ->check(CLI::IsMember(solver::linear_solver_names()))
      ->capture_default_str();
  sub->add_flag("--quadratic-laplace", a->quadratic,
                "tet10: solve the longitudinal Laplace problem on all 10 nodes too (the transmural one always is) "
                "instead of on the corner nodes");
  on(sub, [a] {
    fibers::HarmonicFiberOptions o;
    const double rad = M_PI / 180.0;
    o.angles = {{tags::intima, a->intima * rad}, {tags::media, a->media * rad}, {tags::adventitia, a->adventitia * rad}};
    o.centerline_weight = a->weight;
    o.linear_solver = solver::parse_linear_solver(a->solver, "--linear-solver");
    if (a->quadratic) o.linear_on_corners = false;
    Summary s;
    fibers::write_harmonic_fibers(a->mesh, a->centerline, o, a->out, s);
    const fs::path out(a->out);
    s.write((out.has_parent_path() ? out.parent_path() : fs::path(".")) / "summary.yaml");
    std::printf("wrote %s\n", a->out.c_str());
    return 0;
  });
}

}  // namespace stentsim::cli
