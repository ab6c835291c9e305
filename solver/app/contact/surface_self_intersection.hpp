#pragma once
// Self-contact is not modelled (paper 2.5): a balloon folding inward in a bend
// (paper 4.2) or a wall pressed through itself passes through its own surface
// unopposed. This observer detects it on a solid body's contact surface, in
// the initial state and after every step: the surface's faces as flat
// triangles at the current positions, tested pairwise for intersections other
// than along shared edges and vertices (common/self_intersection.hpp). It
// warns with the count and the first place, and summary.yaml gets
// self_intersection_pairs_max_<body> (the most triangle pairs at any step,
// counted up to kSelfIntersectionLimit) and self_intersection_first_time_<body>
// (-1 when it never happened).
#include <memory>

#include "solver/app/run_observer.hpp"
#include "solver/contact/contact_surface.hpp"

namespace stentsim::solver {

inline constexpr std::size_t kSelfIntersectionLimit = 1000;

/// `surface` must outlive the observer (the contact pair that owns it does).
std::unique_ptr<RunObserver> make_surface_self_intersection_check(const contact::ContactSurface& surface, std::string body);

}  // namespace stentsim::solver
