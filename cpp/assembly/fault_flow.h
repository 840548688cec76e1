// The flow inside "conduit" faults (docs/theory.md "Flow in a fault"): the
// fault's pressure p_f, one unknown per fault cell (domain/fault_cells.h),
// appended to the flow system after the rock's unknowns (fault_rows.h).
// Per cell k, the mass balance times -1 (as forms/biot.py writes the rock's),
//
//     sum_i c_i z_i - ((S_k + L_k)/dt) p_k - sum_l T_kl (p_k - p_l) - sum_ends T_e (p_k - p_D)
//         = -(S_k/dt) p_k^old - (L_k/dt) p_k^i + |k| (w_k - w_k^old)/dt,
// w_k the hydraulic aperture w_h (set_openings), S_k = w_h c_f |k|, T_kl
// the two-point transmissibility (to other faults' cells at intersections),
// c_i the faces' facet fluxes, L_k = L_f |k| the fixed-stress term (BDF2:
// dt/c0 and history values for ^old, FineStep). The operator stays
// symmetric. Twin: python_prototype/assembly/fault_flow.py.
#pragma once

#include "assembly/boundary_conditions.h"
#include "assembly/fault_compliance.h"
#include "assembly/fault_rows.h"
#include "assembly/fault_volumes.h"
#include "domain/domain.h"
#include "scene/scene.h"

#include <array>
#include <optional>
#include <petscmat.h>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// @brief Fine step m (1..q) of a window of q flow steps, ending at t,
/// of length dt: with the mechanics once per window, each fine step takes
/// 1/q of the window's change of aperture, as the rock's flow takes
/// (alpha/q) div(u^n - u_K) (paper eq. 4.17). A step of the single-rate
/// split is m = q = 1. `c` holds the time derivative's (c0, c1, c2)
/// (time/time_scheme.h): dt is then the effective step dt_n/c0, and the
/// history value y* = (c1 y_n - c2 y_{n-1})/c0 of the fault's pressure and
/// aperture stands where backward Euler reads y_n (BDF2; single rate only).
struct FineStep
{
  double t = 0, dt = 0;
  int m = 1, q = 1;
  std::array<double, 3> c = {1, 1, 0}; // backward Euler by default
};

/// The history value y* = (c1 y - c2 y_before)/c0 of `step` (FineStep::c,
/// as time_scheme.h's), y itself for backward Euler.
std::vector<double> history_value(const FineStep& step, std::span<const double> y, std::span<const double> y_before);

/// The two-point transmissibility |e| / (sum_k d_k / t_k) of each of the
/// FaultEdges `edges` (t: per cell, the cubic law's w_h^3 / (12 mu_f)): |e|
/// the measure of the edge between the cells, d_k its distance to each
/// centroid.
std::vector<double> transmissibilities(std::span<const double> t, const FaultEdges& edges);

/// Below this fraction of the residual aperture a cell's mean opening is the
/// round-off of u+ - u- at closed pairs (1e-17 m at 0.1 m of displacement),
/// not an opening: amplified by 1/(c_f w_r) it would move p_f, and a
/// closed cell taken for open would take the fixed-stress term L_f, under
/// which it converges at the rate L_f/(L_f + S), nearly 1.
constexpr double open_fraction = 1e-6;

/// The conducting apertures of the cubic law follow w_h whole while the lag
/// between them shrinks by this factor per iteration (the monolithic step's
/// aperture iterations, the split's coupling iterations); once it does not,
/// the split relaxes them by Aitken's factor and the monolithic step takes
/// Newton's term of the transmissibilities (theory.md, "Flow in a fault").
constexpr double relaxed_above = 0.9;
/// In the split, whose lag shrinks at the coupling's rate after a transient,
/// Aitken's relaxation starts once the lag grew at this many coupling
/// iterations in a row (the lagged cubic law's 2-cycle).
constexpr int stalled_iterations = 3;
/// A lag below the openings' round-off that has not halved over this many
/// of the split's iterations is noise: the floor of the relaxation holds
/// the apertures from then to the step's end (Aitken's factor from noise
/// cycled with period 4).
constexpr std::size_t lag_window = 4;

/// @brief The conduit faults of a scene: their cells, numbered fault by
/// fault in the scene's order, appended after the flow system's unknowns,
/// each on the rank that owns its first node (fault_rows.h); the faces'
/// flux DOFs on the ranks that own them. Every rank keeps every cell's
/// geometry and apertures (a fault holds few facets); "this rank's
/// entries" of the pressure are its owned cells', in the cells' order.
class ConduitFaults
{
public:
  /// `flux`: the facet flux of the flux basis functions (facet_flux); Z the
  /// flux subspace.
  ConduitFaults(const Scene& scene, const Domain& domain, const dolfinx::fem::FunctionSpace& Z,
                const FacetFlux& flux);

  explicit operator bool() const { return _size > 0; }
  /// The cells of every conduit fault, and this rank's share of them.
  std::int64_t size() const { return _size; }
  std::int32_t owned() const { return _rows.owned(); }

  /// p_f at the start: the expression p0 at the cells' centroids (this
  /// rank's entries).
  std::vector<double> initial_pressure(const Expression& p0) const;
  /// B: the fault's rows against the flow unknowns, c_i at each face DOF
  /// (`flow_rows`: the flow system's local size; collective). The faces'
  /// RT0 fluxes z_i enter with their facet flux c_i = <w_i.n, 1>, and the
  /// rows of z_i get +c_i p_k: the rock's pressure at a face is p_f (the
  /// boundary-pressure term with p_D = p_f), plus mu_f (w_h/2)/k_n z.n
  /// across a finite normal permeability k_n (face_resistance).
  Mat exchange(PetscInt flow_rows) const;
  /// The rows of the face DOFs across a finite normal permeability: (dof,
  /// mu_f (w_h/2)/k_n <w_i.n, w_i.n>) with w_i.n = c_i/|face|.
  std::vector<std::pair<PetscInt, double>> face_resistance() const;
  /// C: the fault's rows against its own unknowns at step dt (collective).
  Mat operator_matrix(double dt) const;
  /// The hydraulic apertures w_h = w_r + b(s_n) + (w - e)^+ of the
  /// cells' mean openings w (FaultAperture::opening) and effective normal
  /// stresses s_n (FaultAperture::cell_means of the contact tractions;
  /// empty without a closure) of the last mechanics iterate, every cell on
  /// every rank: b the closure's share (closure_aperture, 0 without one),
  /// e = open_fraction w_r (rigid walls, without mechanics, keep the residual
  /// aperture w_r); and which cells are open (w > e). The first
  /// call of a run also sets the apertures at the step's start. Whether
  /// w_h or an open cell changed, and with them the operator and the
  /// faces' resistance.
  bool set_openings(std::span<const double> opening, std::span<const double> traction);
  /// A step starts: no cell was open at an iterate before (the next
  /// set_openings's).
  void begin_step();
  /// The cells whose open state flipped at least twice in the step are
  /// pinned open from the next set_openings on, open whatever their w,
  /// with w_h = w_r + b + w - e linear in w (coupling/pins.h); the
  /// apertures' relaxation starts anew. How many cells are pinned (every
  /// rank alike).
  int pin_flipped();
  /// Each pinned cell whose mean opening at the last set_openings
  /// contradicts its pin turns it: pinned open with w < -e to pinned
  /// closed (w_h = w_r + b), pinned closed with w > e to pinned open.
  /// Whether any turned (every rank alike).
  bool turn_contradicted_pins();
  /// Every pin turned (open to closed, closed to open).
  void turn_pins();
  /// No cell pinned from the next set_openings on.
  void release_pins();
  /// No fixed-stress term from now on (the second pass of
  /// "multirate-two-pass", which solves without L).
  void without_stabilisation() { _stabilised = false; }
  /// The open cells' opening is an unknown of the same system (the
  /// monolithic step, whose rows -(|k|/dt) J u carry it: opening_rates):
  /// they take no fixed-stress term; closed cells keep their closure's.
  void with_implicit_openings() { _implicit = true; }
  /// Per appended row (this rank's entries) the fixed-stress term L_k/dt =
  /// L_f |k|/dt that the split gives an open cell (its open patch's
  /// patch_compliance), 0 in the others: what the monolithic system's
  /// fixed-stress preconditioner adds to C's diagonal, its open cells
  /// taking none in the system itself (with_implicit_openings).
  std::vector<double> open_stabilisation(double dt) const;
  /// Per appended row (this rank's entries) the factor of the cell's mean
  /// opening in its mass balance at iterate i, -(|k|/dt) (1 + c_f (p^i -
  /// p^old)) (p^old the history value of `step`) where the cell was open
  /// at the last set_openings (the volume it opens, and Newton's term of
  /// its fluid's storage c_f w_h (p - p^old) in w_h), 0 where closed (there
  /// the closure's aperture, explicit in load, moves p_f).
  std::vector<double> opening_rates(const FineStep& step, std::span<const double> p_old,
                                    std::span<const double> p_iterate) const;
  /// Whether the monolithic step's aperture iteration carries Newton's term
  /// of the transmissibilities (flux_jacobian), the conducting apertures
  /// then following w_h whole: from the iteration at which its relaxation's
  /// Aitken factor comes out negative (the map w_c -> w_h amplifies the
  /// lag: a positive factor can only crawl) to the step's end, unless
  /// dropped (the lag grew under it, or a solve with it failed:
  /// drop_newton). Not sooner:
  /// far from the solution Newton's step on the cubic law overshoots and
  /// the contact solve fails (docs/theory.md).
  bool newton() const { return _newton; }
  /// Leaves Newton's term for the rest of the step where a solve with it
  /// failed: the conducting apertures back to the relaxation it began from,
  /// w_c = w_c^old + omega lag, omega the factor before it (theory.md,
  /// "Flow in a fault").
  void drop_newton();
  /// Newton's term of the cubic law: D_km = dN_k/dw_m, the derivative of
  /// cell k's flux terms N_k = -sum_l T_kl (p_k - p_l) - sum_ends T_e (p_k -
  /// p_D) (junctions' links included) by the conducting aperture w_m of
  /// each cell m open at the last set_openings, at the faults' pressure `p`
  /// (this rank's entries) and time t (p_D); zero before newton(). Entries of
  /// closed cells stay as zeros, so the structure does not change as cells
  /// open (collective).
  Mat flux_jacobian(std::span<const double> p, double t) const;
  /// w_h - w_c per cell, the hydraulic aperture's lead on the conducting
  /// one that relax_conducting left (this rank's entries).
  std::vector<double> conducting_lag() const;
  /// How far the last set_openings moved the hydraulic apertures: the
  /// largest change relative to the largest aperture, infinite where a
  /// cell opened or closed (the monolithic step's aperture iteration).
  double aperture_change() const { return _aperture_change; }
  /// The hydraulic apertures at the start of the step, every cell (the
  /// same on every rank): the last accepted step's (add_volumes), which a
  /// checkpoint keeps and restores (set_start_apertures).
  std::vector<double> start_apertures() const;
  void set_start_apertures(std::span<const double> w_h);
  /// The fault's right-hand side of fine step `step` into b (its owned
  /// entries): -(S/dt) p_old - (L/dt) p_iterate - T_e p_D at the ends on
  /// pressure boundaries, -R(t) share in the cells a well meets (injection
  /// positive), and the fine step's share of the volume the cell's opening
  /// made since the start of the window, |k| (w_h - w_h_start)/(q dt). In a
  /// coupled split p_iterate is the last flow iterate's p^i, and w_h the
  /// last mechanics iterate's (collective).
  void load(const FineStep& step, std::span<const double> p_old, std::span<const double> p_iterate,
            std::span<double> b) const;
  /// The conduit cells' fields at time t, every fault in turn, on rank 0
  /// (empty elsewhere; collective): per cell pressure, hydraulic aperture,
  /// exchange (the rock's volume rate per area into the fault, sum_i c_i
  /// z_i / |k|) and mean flux (3). `w` the flow unknowns (this rank's), `p`
  /// the fault's pressure (this rank's entries).
  std::vector<double> cell_values(std::span<const double> w, std::span<const double> p, double t) const;

  /// Each fault's volumes of fine step `step` (every rank): `w` the flow
  /// unknowns (this rank's), `p` and `p_old` the fault's pressure at its
  /// end and start (this rank's entries; collective).
  std::vector<StepVolumes> step_volumes(std::span<const double> w, std::span<const double> p,
                                        std::span<const double> p_old, const FineStep& step) const;
  /// The first fault that `step` (step_volumes) leaves unbalanced by more
  /// than volume_balance_tolerance (volume_imbalance, `rock_flux` the
  /// rock's largest flux DOF): one line naming it and the imbalance; empty
  /// when every fault balances.
  std::string unbalanced(const std::vector<StepVolumes>& step, double rock_flux) const;
  /// Adds the accepted fine step's volumes (step_volumes) to each fault's.
  /// After a window's last fine step its apertures become the next
  /// window's start, and the start's apertures and pressure `p_start` (this
  /// rank's entries) the values one step before, which BDF2 reads
  /// (collective).
  void add_volumes(const std::vector<StepVolumes>& volumes, const FineStep& step, std::span<const double> p_start);
  /// Sets each intersection's rate from `p`, the faults' pressure at an
  /// accepted step's end (this rank's entries; collective).
  void set_intersection_rates(std::span<const double> p);
  /// The rates by set of faults that meet, in the order of their names
  /// (the same on every rank).
  std::vector<IntersectionRate> intersection_rates() const;
  /// Each conduit fault's name and volumes (the same on every rank).
  std::vector<std::pair<std::string, FaultVolumes>> volumes() const;
  /// The volumes as 4 numbers per fault (a checkpoint's), and back.
  std::vector<double> volume_values() const;
  void set_volume_values(std::span<const double> values);
  /// What a checkpoint keeps of the faults: their pressure p (the last
  /// rank's), "fault_pressure" (every cell on every rank), the volumes,
  /// "fault_volumes", the start apertures, "fault_apertures", and the
  /// pressure and apertures one step before (BDF2), "fault_pressure_before"
  /// and "fault_apertures_before" (collective); and their restoration into
  /// p and the faults.
  std::map<std::string, std::vector<double>> arrays(std::span<const double> p) const;
  void restore_arrays(const std::map<std::string, std::vector<double>>& arrays, std::span<double> p);

private:
  /// Moves the apertures of the cubic law toward w_h, by Aitken's factor
  /// once a cell's open state flipped back in this step (or the lag
  /// stopped shrinking); returns how far w_h lay from them (the lag, m).
  double relax_conducting();
  /// Whether `lag` (|w_h - w_c|) has not halved over the last
  /// lag_window iterations of the step.
  bool stagnant(double lag) const;
  struct Conduit
  {
    std::string name;
    std::int64_t offset;     // its first cell among the appended unknowns
    const FaultCells* cells;
    std::vector<double> aperture; // w_h per cell (m)
    std::vector<double> aperture_start; // w_h at the start of the step
    std::vector<double> aperture_before; // w_h at the start of the step before (BDF2)
    double residual;                    // w_r
    std::optional<ClosureSpec> closure;
    double modulus;                     // E' of the softest rock, 0 without mechanics
    std::vector<char> open, open_before; // per cell: w > e at the last mechanics iterate, at the one before
    std::vector<double> compliance;     // per cell: L_f (m/Pa) of its patch or closure, 0 where no L
    std::vector<double> traction;       // per cell: s_n at the last mechanics iterate (with a closure)
    double normal_resistance;     // mu_f / (2 k_n): times w_h, the face's resistance (0 for k_n = inf)
    double permeability;          // k_f (m^2): the transmissivity k_f w_h; 0: the cubic law's w_h^3 / 12
    FaultVolumes volumes;         // since the run's start
    std::vector<double> conducting = {}; // the aperture of the cubic law: w_h relaxed (Aitken)
    std::vector<double> lag = {};        // w_h - conducting at the last set_openings
    FaultEdges links = FaultEdges(2);    // the cells' links but those at junctions (fault_network)
    std::vector<int> flips = {};         // per cell: changes of its open state in the step
    std::vector<signed char> pins = {};  // per cell: -1 pinned open, 1 pinned closed, 0 free (pin_flipped)
    std::vector<double> opening = {};    // per cell: w at the last set_openings
  };
  struct Face
  {
    std::int64_t dof;    // global
    std::size_t conduit; // index into _conduits
    std::int64_t cell;   // within its fault
    double flux;         // c = <w_i.n, 1>
  };
  struct Well
  {
    std::int64_t row; // among the appended unknowns
    double share;
    const Expression* rate;
    std::size_t conduit; // index into _conduits
  };
  /// The wells into the fault `fault`, per cell each meets (mesh_checks.h's
  /// check_expressions has checked that each meets one).
  void locate_wells(const Scene& scene, const std::string& fault, const FaultCells& cells, std::int64_t offset);
  std::vector<double> storage(const Conduit& c, double dt) const;
  /// The history value of the pressure p_old (every cell) at `step`.
  std::vector<double> pressure_history(const FineStep& step, std::span<const double> p_old) const;
  /// Each cell's L_f, with L_k = L_f |k| the fault's fixed-stress term
  /// (Girault, Kumar and Wheeler): in the cells open (w > e) at either of
  /// the last two mechanics iterates of the step, the mean opening per unit
  /// pressure of the open patch the cell belongs to (patch_compliance); in
  /// the other cells the closure's compliance -b'(s_n) (closure_compliance:
  /// there s_n falls as p_f rises), or 0 without a closure, where p_f moves
  /// nothing. Why not L in every cell, and why the cells open at the iterate
  /// before keep the patch's L: docs/theory.md, "Flow in a fault".
  void set_compliance(Conduit& c) const;
  /// Per cell of c, patch_compliance of the patch of cells open at either
  /// of the last two mechanics iterates that it belongs to, -1 outside one.
  std::vector<double> patch_compliances(const Conduit& c) const;
  /// L_k/dt = L_f |k|/dt in the open cells, 0 in the others.
  std::vector<double> stabilisation(const Conduit& c, double dt) const;
  /// t per cell: k_f w / mu_f with the fault's own permeability, else the
  /// cubic law's w^3 / (12 mu_f); w the conducting aperture.
  std::vector<double> conductance(const Conduit& c) const;
  /// dt/dw per cell at the conducting aperture where the cell is open, 0
  /// where closed and before newton() (fault_flow_jacobian.cpp).
  std::vector<double> conductance_slope(const Conduit& c) const;
  /// The intersection's own resistance r_j at junction j: the mean of
  /// mu_f / (2 k_n) over the faults that meet there.
  double junction_resistance(const FaultJunction& j) const;
  /// Adds the junctions' share of flux_jacobian to D.
  void add_junction_jacobian(std::span<const double> p, Mat D) const;
  /// @brief Two members of a junction and the transmissibility between them.
  struct JunctionLink
  {
    std::array<std::int64_t, 2> rows;     // among the appended unknowns
    std::array<std::size_t, 2> conduits; // indices into _conduits
    double T;
    const std::array<double, 3>* point;  // the junction's
    std::size_t junction;                // index into _junctions
  };
  /// Every junction's links, the intersection's pressure eliminated.
  std::vector<JunctionLink> junction_links() const;
  /// The ends on pressure boundaries: (indices into the ends, T_e).
  std::pair<std::vector<std::size_t>, std::vector<double>> held_ends(const Conduit& c) const;
  std::vector<double> end_pressures(const Conduit& c, const std::vector<std::size_t>& held, double t) const;
  /// Per cell the mean cubic-law flux, sum_e F_e (m_e - x_k) / |k| (3 each);
  /// `p` every conduit's pressure, `links` the junctions' (junction_links).
  std::vector<double> mean_flux(const Conduit& c, std::span<const double> p, const std::vector<JunctionLink>& links,
                                double t) const;

  MPI_Comm _comm;
  const FlowSpec& _flow;
  std::map<std::string, const Expression*> _pressure_boundaries;
  std::vector<Conduit> _conduits;
  std::vector<Face> _faces;
  std::vector<Well> _wells;
  std::vector<FaultJunction> _junctions; // where the conduits meet (fault_network)
  std::vector<double> _through;          // per junction: its rate (set_intersection_rates)
  std::vector<double> _pressure_before; // p_f at the start of the step before (every cell; BDF2)
  std::int64_t _size = 0, _start = 0;
  FaultRows _rows;
  int _dim = 2;
  bool _started = false;   // whether the start apertures are known
  bool _stabilised = true; // whether the cells take L (set_compliance)
  bool _implicit = false;   // whether open cells' openings are unknowns (with_implicit_openings)
  double _aperture_change = 0;
  double _relaxation = 1;  // Aitken's factor of the conducting apertures
  bool _lagged = false;    // a lag of this step is known
  bool _relaxing = false;  // the conducting apertures are relaxed (relax_conducting)
  bool _overshot = false;  // Newton's term was dropped in this step (relax_conducting, drop_newton)
  double _relaxed = 1;     // the relaxation factor before Newton's term (relax_conducting)
  bool _newton = false;    // Newton's term of the transmissibilities is on (newton())
  int _stalled = 0;        // iterations in a row whose lag did not shrink (relax_conducting)
  bool _held = false;      // the lag stagnated below round-off: the floor holds the apertures
  std::vector<double> _lags; // |w_h - w_c| at each iteration of the step (relax_conducting)
};

} // namespace biotcontact
