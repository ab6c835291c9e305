#pragma once
// Beam results for the VTU/PVD output (issue 8): the centerline sampled finer
// than the nodes (ParaView then draws the curved Hermite shape), one
// polyline per element, with point arrays. Section forces (and, for elastic
// sections, moments) are recovered by equilibrium from each element's end
// actions (beam_resultants.hpp: n' + f = 0, m' + r' × n = 0), so they vary
// smoothly along s and are exact for the discrete solution; the line loads
// acting on the body must be passed for that. Elasto-plastic sections write
// the committed moment of the nearest Gauss point (BeamTerm::sample), the
// moment consistent with the plastic curvature written beside it.
//   Radius            section radius (ParaView's Tube filter: "Vary radius by scalar")
//   TriadD1..D3       the current section triad
//   AxialForce        N = F₁                     [N]
//   ShearForce        (F₂, F₃)                   [N]
//   TorsionalMoment   M₁                         [N·mm]
//   BendingMoment     ‖M_b‖ = √(M₂² + M₃²)       [N·mm]
//   OuterFibreStress  |N|/A + ‖M_b‖ R / I        [MPa]
//                     exact for circular sections (R the radius, I = πR⁴/4);
//                     for sections given by values (section: {A, I2, ...},
//                     no radius) it is an estimate: R = √(A/π) (the circle of
//                     equal area) and I = I₂, also for bending about d₃ — the
//                     array is still written, so read it as indicative only
//                     for non-circular sections (every stent section is circular)
//   Displacement      r − r₀                     [mm]
// and, for elasto-plastic sections (App. C), from the committed history of the
// nearest Gauss point:
//   PlasticCurvature             Ω_pl, material components   [1/mm]
//   AccumulatedPlasticCurvature  Ω̄_pl                        [1/mm]
//   OuterFibrePlasticStrain      R·‖Ω_pl‖                    [-]
//   Yielding                     1 where the nearest Gauss point flowed in the last committed step, else 0
// and cell data ElementId. Section resultants are material components
// (F = Λᵀ n, M = Λᵀ m in the section triad at the sample).
#include "common/mesh_data.hpp"
#include "solver/beams/beam_resultants.hpp"
#include "solver/beams/beam_term.hpp"

#include <Eigen/Core>

#include <span>

namespace stentsim::solver::beams {

/// `samples_per_element` ≥ 1 segments per element (points per element: +1);
/// `line_loads`: the dead line loads on the body at their current value.
MeshData beam_output_mesh(const BeamTerm& beam, const Eigen::VectorXd& u, int samples_per_element = 8,
                          std::span<const BeamDeadLineLoad> line_loads = {});

}  // namespace stentsim::solver::beams
