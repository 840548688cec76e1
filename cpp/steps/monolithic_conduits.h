// The conduit faults' pressure in the monolithic step (docs/theory.md "The
// monolithic solve with p_f"; twin python_prototype/steps/
// monolithic_conduits.py): p_f, one unknown per fault cell, appended to the
// coupled system x = (u, z, p), [[A + D, E], [B, C]] [x; p_f] = [b; b_f],
//     E = B_z^T - J^T |k|   the faces' pressure p_f (B_z: the exchange with
//                           their fluxes, fault_flow.h) and p_f pushing them
//                           apart (fault_aperture.h), zero on Dirichlet rows;
//     B = B_z + M J         the exchange and the open cells' opening (J: the
//                           cells' mean jump), M = G - (|k|/dt) O with G
//                           Newton's term of their transmissibilities;
//     C                     the fault's own rows (fault_flow.h), with no
//                           fixed-stress term in open cells.
#pragma once

#include "assembly/fault_aperture.h"
#include "assembly/fault_flow.h"
#include "assembly/problem.h"
#include "contact/contact.h"
#include "steps/system.h"
#include "time/time_scheme.h"

#include <array>
#include <dolfinx/fem/FunctionSpace.h>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace biotcontact
{

/// @brief The monolithic step's mixed space X and where its parts sit: the
/// displacement space V, its DOFs' places in X, the Dirichlet conditions
/// on X and the facet flux of X's flux basis functions.
struct MixedSpace
{
  const dolfinx::fem::FunctionSpace& X;
  const dolfinx::fem::FunctionSpace& V;
  const std::vector<std::int32_t>& V_to_X;
  const BCs& bcs;
  const FacetFlux& flux;
};

/// @brief The conduit faults of the monolithic step: their rows of the
/// coupled system and the iteration on their apertures.
///
/// Which cells are open, their transmissivity w_h^3/(12 mu_f) and a
/// closure's aperture follow the solution: each step iterates on them. At
/// iterate i, b_f holds the volume with its open cells' opening taken at
/// u^i, |k| (w_h^i - w_h^start)/dt - (|k|/dt) (O J u^i), and Newton's term
/// of the transmissibilities, G (J u^i - (w_h^i - w_c)) with G = dN/dw_c
/// at p_f^i (ConduitFaults::flux_jacobian), which the solve moves to
/// u^{i+1}: a Newton iteration on the open cells' apertures, from the
/// conducting ones w_c. Closed cells keep their closure's fixed-stress
/// term, which vanishes as p_f settles. The iteration stops when the
/// apertures and p_f move by at most the coupling's tolerance.
class MonolithicConduits
{
public:
  MonolithicConduits(const Problem& problem, const MixedSpace& space);
  ~MonolithicConduits();
  MonolithicConduits(const MonolithicConduits&) = delete;
  MonolithicConduits& operator=(const MonolithicConduits&) = delete;

  explicit operator bool() const { return bool(_faults); }
  /// The closure needs the faults' contact tractions after each solve.
  bool has_closure() const;

  /// Appends the rows at the current apertures and dt to `system` (again
  /// after a change: the same structure).
  void append(System& system);
  /// The step starts from x (the coupled unknowns, ghosts updated) and the
  /// cells' effective normal stress `s_n` (empty before any contact
  /// solve): p_f now is the step's p_f^old, and the apertures are x's.
  void begin_step(System& system, dolfinx::la::Vector<double>& x, std::span<const double> s_n);
  /// b_f of iterate i at time t from x = x^i, and p_f^i as the guess.
  void load(System& system, dolfinx::la::Vector<double>& x, double t);
  /// After a solve: p_f from `system`, the apertures from x and s_n, the
  /// rows appended again if they changed. Whether the iteration has
  /// converged.
  bool update(System& system, dolfinx::la::Vector<double>& x, std::span<const double> s_n);
  /// Whether the rows carry Newton's term of the transmissibilities.
  bool newton() const { return _faults->newton(); }
  /// A solve with Newton's term of the transmissibilities failed: the rows
  /// again without it (ConduitFaults::drop_newton).
  void drop_newton(System& system);
  /// What the last update measured against the tolerance, for an error.
  std::string last_change() const;

  /// The cells' mean contact traction, s_n (every cell on every rank;
  /// collective).
  std::vector<double> normal_stress(const ContactState& state) const;

  /// The cells' openings and the load of p_f on their faces.
  const FaultAperture& aperture() const { return *_aperture; }
  /// p_f (this rank's entries).
  std::vector<double>& pressure() { return _pressure; }
  const std::vector<double>& pressure() const { return _pressure; }
  /// The accepted step to t: the volumes take it (`x` the coupled unknowns).
  void accept(std::span<const double> x, double t);
  /// A fault that the step to t would leave unbalanced, or empty
  /// (`rock_flux` the rock's largest flux DOF: ConduitFaults::unbalanced).
  std::string unbalanced(std::span<const double> x, double t, double rock_flux) const;
  /// The faults' cell fields at t on rank 0 (ConduitFaults::cell_values).
  std::vector<double> cell_values(std::span<const double> x, double t) const;
  std::vector<std::pair<std::string, FaultVolumes>> volumes() const { return _faults->volumes(); }
  std::vector<IntersectionRate> intersection_rates() const { return _faults->intersection_rates(); }
  /// p_f, the volumes and the start apertures as a checkpoint keeps them
  /// (FlowStep::arrays' names), and back.
  void keep(std::map<std::string, std::vector<double>>& arrays) const;
  void restore(const std::map<std::string, std::vector<double>>& arrays);

  /// The step's time derivative (MonolithicStep::solve's): the faults'
  /// storage differentiates with it as the rock's (time_scheme.h); the
  /// rows appended again if it changed.
  void set_time_derivative(System& system, const TimeDerivative& d);

private:
  /// The FineStep of the step to t: the "dt" constant and the derivative.
  FineStep step(double t) const;
  /// E, once (see the file's comment).
  void make_load_rows(const MixedSpace& space);

  const Problem& _problem;
  std::unique_ptr<ConduitFaults> _faults;
  std::unique_ptr<FaultAperture> _aperture;
  Mat _J = nullptr;       // J R: the cells' mean jump of X's displacement
  Vec _cells = nullptr;   // on J's rows
  Mat _E = nullptr;       // B_z^T - J^T |k|, zero on Dirichlet rows: the same at every append
  Mat _G = nullptr;       // Newton's term of the transmissibilities at the last append (flux_jacobian)
  double _time = 0;       // of the last load: the held ends' p_D in G
  PetscInt _rows = 0;     // X's owned DOFs
  std::vector<double> _pressure, _pressure_old; // p_f, and at the step's start
  TimeDerivative _derivative;                   // of the step (set_time_derivative)
  // The last update's apertures' change (ConduitFaults::aperture_change)
  // and p_f's largest change relative to the largest p_f.
  std::array<double, 2> _change{0, 0};
};

} // namespace biotcontact
