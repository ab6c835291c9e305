#pragma once
// The three device stages as the runner and the CLI call them (DESIGN.md §1):
// each reads files, writes its artifacts atomically and fills the Summary.
//
//   placement: centerline.vtp (+ lumen.vtp) -> placement.yaml, balloon_centerline.vtp
//   balloon:   placement.yaml (or none: straight along +z, centred at the origin) -> balloon.vtu
//   stent:     placement.yaml (or none: straight) -> stent.vtu
#include <filesystem>
#include <optional>

#include "common/summary.hpp"
#include "device_gen/balloon_design.hpp"
#include "device_gen/placement.hpp"
#include "device_gen/stent_design.hpp"

namespace stentsim::device_gen {

/// Places the device. `lumen_vtp` (optional) gives the clearance by the
/// distance to the endothelium; without it the inscribed sphere bounds it.
void run_placement_stage(const PlacementParams& params, const std::filesystem::path& centerline_vtp,
                         const std::optional<std::filesystem::path>& lumen_vtp, const BalloonDesign& balloon,
                         const StentDesign& stent, const std::filesystem::path& out_placement_yaml,
                         const std::filesystem::path& out_balloon_centerline_vtp, Summary& summary);

/// Builds balloon.vtu along the placement's axis, or straight when none is given.
void run_balloon_stage(const BalloonDesign& design, const std::optional<std::filesystem::path>& placement_yaml,
                       const std::filesystem::path& out_balloon_vtu, Summary& summary);

/// Builds stent.vtu: generated straight, warped onto the placement's axis (or left straight).
void run_stent_stage(const StentDesign& design, const std::optional<std::filesystem::path>& placement_yaml,
                     const std::filesystem::path& out_stent_vtu, Summary& summary);

}  // namespace stentsim::device_gen
