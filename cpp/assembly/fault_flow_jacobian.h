// Newton's term of the conduit faults' transmissibilities (docs/theory.md
// "Flow in a fault", "Newton on the cubic law"): the derivatives of the
// two-point transmissibilities and of a junction's star by the cells'
// apertures, from which ConduitFaults::flux_jacobian (fault_flow.h, defined
// in fault_flow_jacobian.cpp) assembles the monolithic step's term. Twin:
// python_prototype/assembly/fault_flow_jacobian.py.
#pragma once

#include "domain/fault_cells.h"

#include <span>
#include <vector>

namespace biotcontact
{

/// The derivatives dT/dw of each of the FaultEdges' transmissibilities
/// T = |e| / R, R = sum_k d_k/t_k (fault_flow.h's transmissibilities) by
/// each of its cells' aperture, width per edge: dT/dt_k = |e| d_k / (R^2
/// t_k^2) times `slope`, dt/dw per cell.
std::vector<double> transmissibility_slopes(std::span<const double> t, std::span<const double> slope,
                                           const FaultEdges& edges);

/// A junction's star: with its members' transmissibilities h to the
/// intersection and pressures p, the intersection's p_j = sum h_i p_i /
/// sum h_i, member a's flux term N_a = -h_a (p_a - p_j); returns dN_a/dh_c
/// (row-major, a by c).
std::vector<double> star_flux_derivative(std::span<const double> h, std::span<const double> p);

} // namespace biotcontact
