#pragma once
// Beam results for the VTU/PVD output (issue 8): the centerline sampled finer
// than the nodes (ParaView then draws the curved Hermite shape), one
// polyline per element, with point arrays (section quantities are those of the
// nearest Gauss point, piecewise constant along an element: BeamTerm::sample)
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
// and cell data ElementId. Section resultants are the material (convected)
// ones, F = C_F Γ, M = C_M Ω, components in the section triad.
#include "common/mesh_data.hpp"
#include "solver/beams/beam_term.hpp"

#include <Eigen/Core>

namespace stentsim::solver::beams {

/// `samples_per_element` ≥ 1 segments per element (points per element: +1).
MeshData beam_output_mesh(const BeamTerm& beam, const Eigen::VectorXd& u, int samples_per_element = 8);

}  // namespace stentsim::solver::beams
