// How a conduit fault's aperture answers its pressure: the closure of a
// closed fault (Barton-Bandis), the opening of an open patch (Sneddon), the
// patches of open cells; their compliances are the fault's fixed-stress
// term L_f (docs/theory.md "Flow in a fault"). Twin:
// python_prototype/assembly/fault_compliance.py.
#pragma once

#include "domain/fault_cells.h"
#include "scene/scene.h"

#include <cstdint>
#include <span>
#include <vector>

namespace biotcontact
{

/// The smallest plane-strain modulus E' = E/(1 - nu^2) of the scene's
/// materials (the softest rock).
double softest_modulus(const Scene& scene);

/// The mean opening per unit pressure of an open patch of measure `size`
/// (its length in 2D, its area in 3D) in an infinite body of plane-strain
/// modulus E': Sneddon's pi a/E' for a 2D crack of half-length a = size/2,
/// 16 a/(3 pi E') for a penny of radius a (area pi a^2) in 3D; the
/// fault's fixed-stress L_f of the patch's cells.
double patch_compliance(double size, double modulus, int dim);

/// Barton-Bandis: the closure's share of a closed fault's hydraulic
/// aperture at the effective normal stress s_n (>= 0 pressing; 0 below),
/// V_m - V_m s_n/(K_ni V_m + s_n): V_m at s_n = 0, falling to 0 as s_n
/// grows.
double closure_aperture(const ClosureSpec& closure, double s_n);

/// The closure's compliance, minus the derivative of closure_aperture in
/// s_n, K_ni V_m^2/(K_ni V_m + s_n)^2 (m/Pa): the fault's fixed-stress L_f
/// of a closed cell, whose s_n falls as much as its p_f rises.
double closure_compliance(const ClosureSpec& closure, double s_n);

/// The open patches of a fault: per cell the index of the patch of open
/// cells joined by any of `links` that holds it, -1 where the cell is
/// closed.
std::vector<std::int64_t> open_patches(const std::vector<const FaultEdges*>& links, std::span<const char> open);

} // namespace biotcontact
