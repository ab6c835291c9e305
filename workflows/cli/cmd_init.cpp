// `stentsim init DIR --scene SCENE`: a commented, runnable example case.
#include <cstdio>

#include "workflows/cli/commands.hpp"
#include "workflows/init_case.hpp"

namespace stentsim::cli {

void register_init(CLI::App& app) {
  struct Args {
    std::string dir, scene = "patient";
    bool cohort = false, curved = false;
  };
  auto a = std::make_shared<Args>();
  auto* sub = app.add_subcommand("init", "Write a commented, runnable example case into DIR");
  sub->add_option("dir", a->dir, "Folder for the case")->required();
  sub->add_option("--scene", a->scene, "Scene of the example")
      ->check(CLI::IsMember({"free-expansion", "generic-artery", "patient"}));
  sub->add_flag("--curved", a->curved,
                "With --scene free-expansion: the paper's curved device (Section 3.2), placed along a phantom's centerline");
  sub->add_flag("--cohort", a->cohort, "Write an example cohort of six phantom patients (and its template case)");
  on(sub, [a, sub] {
    if (a->cohort && a->curved) {
      std::fprintf(stderr, "init: --curved and --cohort do not go together (the cohort's template is a patient case)\n");
      return 2;
    }
    if (a->cohort) {
      workflows::write_example_case(a->dir, "patient");
      const auto file = workflows::write_example_case(a->dir, "cohort");
      std::printf("wrote %s and its template patient.yaml\nrun it with: stentsim cohort run %s\n", file.c_str(), file.c_str());
      return 0;
    }
    if (a->curved && sub->count("--scene") == 0) a->scene = "free-expansion";
    if (a->curved && a->scene != "free-expansion") {
      std::fprintf(stderr, "init: --curved is the curved free expansion; use --scene free-expansion or leave --scene out\n");
      return 2;
    }
    const auto file = workflows::write_example_case(a->dir, a->curved ? "free-expansion-curved" : a->scene);
    std::printf("wrote %s\nrun it with: stentsim run %s\n", file.c_str(), file.c_str());
    return 0;
  });
}

}  // namespace stentsim::cli
