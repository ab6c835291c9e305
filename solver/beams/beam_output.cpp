#include "solver/beams/beam_output.hpp"

#include "solver/beams/beam_resultants.hpp"

#include "common/error.hpp"

#include <cmath>
#include <numbers>

namespace stentsim::solver::beams {

MeshData beam_output_mesh(const BeamTerm& beam, const Eigen::VectorXd& u, int samples_per_element,
                          std::span<const BeamDeadLineLoad> line_loads) {
  if (samples_per_element < 1) throw InputError("beam output: samples_per_element must be >= 1");
  const BeamSection& sec = beam.body().section;
  const double R = sec.radius > 0 ? sec.radius : std::sqrt(sec.area / std::numbers::pi);
  const double A = sec.area, I = sec.bending_inertia;
  MeshData m;
  auto arr = [&](const char* name, int comps) -> DataArray& {
    DataArray& a = m.point_data[name];
    a.components = comps;
    return a;
  };
  DataArray &radius = arr("Radius", 1), &d1 = arr("TriadD1", 3), &d2 = arr("TriadD2", 3), &d3 = arr("TriadD3", 3);
  DataArray &axial = arr("AxialForce", 1), &shear = arr("ShearForce", 2), &torsion = arr("TorsionalMoment", 1);
  DataArray &bending = arr("BendingMoment", 1), &stress = arr("OuterFibreStress", 1), &disp = arr("Displacement", 3);
  // Forces (and, for elastic sections, moments) by equilibrium from each
  // element's end actions (beam_resultants.hpp): smooth along the element and
  // exact for the discrete solution, unlike C_F Γ of a stiff section.
  // Elasto-plastic sections (App. C): the moments, the plastic history and
  // Yielding are the committed ones of the nearest Gauss point
  // (BeamTerm::sample; the plastic state exists only at Gauss points), the
  // outer-fibre plastic strain is R·‖Ω_pl‖, and Yielding = 1 where that Gauss
  // point flowed in the last committed step.
  const bool plastic = sec.plastic.has_value();
  DataArray* kpl = plastic ? &arr("PlasticCurvature", 3) : nullptr;
  DataArray* kacc = plastic ? &arr("AccumulatedPlasticCurvature", 1) : nullptr;
  DataArray* eps = plastic ? &arr("OuterFibrePlasticStrain", 1) : nullptr;
  DataArray* yielding = plastic ? &arr("Yielding", 1) : nullptr;
  DataArray& element_id = m.cell_data["ElementId"];
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(u.size());
  for (std::size_t e = 0; e < beam.body().elements.size(); ++e) {
    std::vector<std::int64_t> ids;
    const ElementResultants resultants(beam, u, e, line_load_on(line_loads, e));
    for (int k = 0; k <= samples_per_element; ++k) {
      const double xi = -1.0 + 2.0 * k / samples_per_element;
      SectionState s = beam.sample(u, e, xi);
      Eigen::Vector3d n, mom;
      resultants.at(xi, n, mom);
      s.F = s.triad.transpose() * n;  // material components N = Λᵀ n
      if (!plastic) s.M = s.triad.transpose() * mom;
      const Eigen::Vector3d r0 = beam.sample(zero, e, xi).position;  // reference centerline
      ids.push_back(static_cast<std::int64_t>(m.points.size()));
      m.points.push_back(s.position);
      radius.values.push_back(R);
      for (int c = 0; c < 3; ++c) {
        d1.values.push_back(s.triad(c, 0));
        d2.values.push_back(s.triad(c, 1));
        d3.values.push_back(s.triad(c, 2));
        disp.values.push_back(s.position[c] - r0[c]);
      }
      const double Mb = std::hypot(s.M[1], s.M[2]);
      axial.values.push_back(s.F[0]);
      shear.values.push_back(s.F[1]);
      shear.values.push_back(s.F[2]);
      torsion.values.push_back(s.M[0]);
      bending.values.push_back(Mb);
      stress.values.push_back((A > 0 ? std::abs(s.F[0]) / A : 0.0) + (I > 0 ? Mb * R / I : 0.0));
      if (plastic) {
        const PlasticBendingLaw& law = *sec.plastic;
        for (int c = 0; c < 3; ++c) kpl->values.push_back(s.plastic.plastic_curvature[c]);
        kacc->values.push_back(s.plastic.accumulated);
        eps->values.push_back(law.radius * s.plastic.plastic_curvature.norm());
        yielding->values.push_back(s.yielding ? 1.0 : 0.0);
      }
    }
    m.add_cell(CellType::polyline, ids);
    element_id.values.push_back(static_cast<double>(e));
  }
  m.field_text["units"] = "mm, N, MPa";
  if (plastic) m.field_text["plastic_curvature"] = "material components (d1, d2, d3) of the section frame, 1/mm";
  m.field_text["beam_resultants"] =
      plastic ? "material frame; forces by equilibrium from the element end forces (n' + f = 0), moments the committed "
                "Gauss-point ones (elasto-plastic return)"
              : "material frame; by equilibrium from the element end actions (n' + f = 0, m' + r' x n = 0)";
  return m;
}

}  // namespace stentsim::solver::beams
