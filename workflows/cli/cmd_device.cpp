// `stentsim place`, `stentsim balloon`, `stentsim stent`: the device stages as
// tools of their own. An optional --device YAML holds the same keys as a
// case's `device:` section (balloon, stent, placement).
#include <cstdio>
#include <filesystem>
#include <optional>

#include "common/config.hpp"
#include "common/summary.hpp"
#include "device_gen/stages.hpp"
#include "segmentation_io/segmentation_stage.hpp"
#include "workflows/cli/commands.hpp"

namespace fs = std::filesystem;

namespace stentsim::cli {
namespace {

struct DeviceFile {
  device_gen::BalloonDesign balloon;
  device_gen::StentDesign stent;
  device_gen::PlacementParams placement;
};

DeviceFile read_device(const std::string& file) {
  std::optional<ConfigMap> top;
  if (file.empty()) top = ConfigMap::from_string("{}", "(defaults)");
  else top = ConfigMap::load(file);
  DeviceFile d;
  auto b = top->map("balloon");
  d.balloon = device_gen::parse_balloon_design(b);
  auto s = top->map("stent");
  d.stent = device_gen::parse_stent_design(s);
  auto p = top->map("placement");
  d.placement = device_gen::parse_placement_params(p);
  top->finish();
  return d;
}

void write_summary(const Summary& s, const fs::path& artifact) { s.write(artifact.parent_path() / "summary.yaml"); }

}  // namespace

void register_device(CLI::App& app) {
  struct Args {
    std::string device, centerline, lumen, placement, out;
  };
  auto a = std::make_shared<Args>();
  const char* device_help = "Device settings (YAML with balloon/stent/placement sections as in a case's device:)";

  auto* place = app.add_subcommand("place", "Place the balloon at the stenosis: placement.yaml + balloon_centerline.vtp");
  place->add_option("--centerline", a->centerline, "centerline.vtp (VMTK arrays)")->required();
  place->add_option("--lumen", a->lumen, "lumen.vtp, for the clearance check");
  place->add_option("--device", a->device, device_help);
  place->add_option("--out", a->out, "Output folder")->required();
  on(place, [a] {
    const auto d = read_device(a->device);
    const fs::path out(a->out);
    Summary s;
    std::optional<fs::path> lumen;
    if (!a->lumen.empty()) {
      (void)segmentation::load_stage_lumen(a->lumen, "stentsim place");  // the case path's surface checks
      lumen = a->lumen;
    }
    device_gen::run_placement_stage(d.placement, a->centerline, lumen, d.balloon, d.stent, out / "placement.yaml",
                                    out / "balloon_centerline.vtp", s);
    write_summary(s, out / "placement.yaml");
    std::printf("wrote %s/placement.yaml and balloon_centerline.vtp\n", a->out.c_str());
    return 0;
  });

  for (const char* name : {"balloon", "stent"}) {
    auto* sub = app.add_subcommand(name, std::string(name == std::string("balloon") ? "Balloon hex8 mesh" : "Stent beam model") +
                                             ": straight along +z, or along a placement's balloon centerline");
    sub->add_option("--placement", a->placement, "placement.yaml from `stentsim place`");
    sub->add_option("--device", a->device, device_help);
    sub->add_option("--out", a->out, std::string("Output ") + name + ".vtu")->required();
    const std::string n = name;
    on(sub, [a, n] {
      const auto d = read_device(a->device);
      std::optional<fs::path> placement;
      if (!a->placement.empty()) placement = a->placement;
      Summary s;
      if (n == "balloon") device_gen::run_balloon_stage(d.balloon, placement, a->out, s);
      else device_gen::run_stent_stage(d.stent, placement, a->out, s);
      write_summary(s, a->out);
      std::printf("wrote %s\n", a->out.c_str());
      return 0;
    });
  }
}

}  // namespace stentsim::cli
