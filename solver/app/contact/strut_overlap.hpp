#pragma once
// Beam–beam contact is not modelled (paper 2.5): struts may pass through each
// other. This observer detects it after every step: points of the centerline
// (4 per element) that started farther apart than 4 R but are now closer
// than 2 R, i.e. sections that overlap. It warns with the count and the worst
// place, and summary.yaml gets strut_overlap_points_max_<beam> (over the run)
// and strut_overlap_depth_max_<beam> (2 R − the smallest such distance, mm).
#include <memory>

#include "solver/app/run_observer.hpp"
#include "solver/beams/beam_term.hpp"

namespace stentsim::solver {

std::unique_ptr<RunObserver> make_strut_overlap_check(const beams::BeamTerm& beam, double radius);

}  // namespace stentsim::solver
