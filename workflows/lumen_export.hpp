#pragma once
// The deformed lumen after the angioplasty, for a flow simulation of the
// stented vessel: the artery's endothelium in the solver's last frame, moved
// by its displacement, as a triangle surface in the input's frame and units.
#include <filesystem>
#include <string>

#include "common/mesh_data.hpp"

namespace stentsim::workflows {

/// The endothelium faces (FaceGroup endothelium) of an artery result frame
/// (`results/artery_*.vtu`), at reference + Displacement, as linear triangles
/// (a tri6 face as the four through its mid-side nodes, a quad as two), with
/// only the points they use, scaled from mm to `units` (mm, cm, m, um), with
/// normals out of the lumen (into the wall), as a flow domain's boundary. The
/// surface is open at the vessel's two cuts (a flow tool caps them).
/// InputError naming the frame when it has no endothelium faces or no Displacement.
MeshData deformed_lumen(const std::filesystem::path& frame, const std::string& units);

/// Writes the surface as .vtp (ParaView) and as binary .stl (flow tools), atomically.
void write_lumen(const MeshData& surface, const std::filesystem::path& vtp, const std::filesystem::path& stl);

}  // namespace stentsim::workflows
