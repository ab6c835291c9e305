#include "workflows/cli/commands.hpp"

namespace stentsim::cli {

void register_version(CLI::App& app);
void register_run(CLI::App& app);
void register_init(CLI::App& app);
void register_cohort(CLI::App& app);
void register_solve(CLI::App& app);
void register_segmentation(CLI::App& app);
void register_device(CLI::App& app);
void register_fibers(CLI::App& app);
void register_mesh(CLI::App& app);
void register_study(CLI::App& app);

void register_all(CLI::App& app) {
  register_init(app);
  register_run(app);
  register_cohort(app);
  register_segmentation(app);
  register_device(app);
  register_mesh(app);
  register_fibers(app);
  register_solve(app);
  register_study(app);
  register_version(app);
}

}  // namespace stentsim::cli
