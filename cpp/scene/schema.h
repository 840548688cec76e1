// The scene's schema: what a scene says, table by table (docs/user-guide.md,
// "Scene reference"), as the scene's readers fill it in (scene.h reads a
// scene, the *_input.h the tables) and every stage of a run reads it.
#pragma once

#include "scene/expression.h"
#include "scene/input.h"

#include <array>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace biotcontact
{

struct MeshSpec
{
  MeshType type = MeshType::rectangle;
  std::vector<double> lower, upper; // corners (built-in meshes)
  std::vector<std::size_t> cells;   // cells per direction (built-in meshes)
  std::string file;                 // .msh or .geo (gmsh), resolved path
  int dimension = 2;
  int refine = 0;                   // uniform refinements of a gmsh mesh (nested: each halves h)
  double size_factor = 1;           // every size gmsh meshes a .geo with, times this (not nested)
};

/// Friction on a contact (a foundation, or a fault's two faces): the
/// tangential traction |t_T| <= cohesion + friction t_N (Coulomb, t_N the
/// contact's normal traction, an effective stress where the faces carry a
/// fluid pressure), or <= tresca, a given bound. Frictionless by default.
struct FrictionSpec
{
  double friction = 0, cohesion = 0;
  std::optional<double> tresca;
};

/// Signorini contact against a rigid foundation:
/// u.nu_F <= gap at the nodes of the boundary, nu_F the foundation's
/// outward normal (from the body into the foundation), a constant vector or
/// one given by expressions of x, y, z (a curved foundation), normalised at
/// each node.
struct ContactSpec
{
  Expression gap;
  std::vector<Expression> normal; // d components
  FrictionSpec friction;
};

struct BoundarySpec
{
  enum class Mechanics
  {
    traction_free,
    displacement, // some components prescribed ("clamp" prescribes all to 0)
    traction,
    contact
  };
  enum class Flow
  {
    no_flow,
    pressure,
    flux
  };
  Mechanics mechanics = Mechanics::traction_free;
  std::array<std::optional<Expression>, 3> displacement;
  std::vector<Expression> traction; // also on a contact boundary (a fluid-loaded fracture face)
  std::optional<ContactSpec> contact;
  /// The pore pressure of the cells beside the face pushes on it: the total
  /// traction -p n of a fracture whose fluid is in pressure equilibrium with
  /// the rock beside it (a contact boundary of a coupled scene).
  bool pore_pressure_load = false;
  Flow flow = Flow::no_flow;
  Expression pressure;
  Expression flux;                  // the outward normal Darcy flux z.n (m/s; negative flows in)
  std::optional<Expression> rate;   // or the total rate through the boundary (m^3/s, per metre
                                    // in 2D; injection positive), spread uniformly: flux = -rate/area
};

/// @brief A well: a point source or sink in 2D, a vertical line segment
/// in 3D; injection positive.
struct WellSpec
{
  std::vector<double> position; // (x, y) of the point (2D) or of the vertical segment (3D)
  double bottom = 0, top = 0;   // the segment's z range (3D)
  Expression rate;              // the total volumetric rate (m^3/s; per metre of thickness in 2D), a function of t
  std::string fault;            // a conduit fault the well injects into (where it meets it), or the rock
};

struct MechanicsSpec
{
  double G = 0, lambda = 0;
  std::optional<std::vector<Expression>> body_force;
  /// Start from the displacement in equilibrium with the loads at t = 0 and
  /// the initial pressure (a geostatic initialisation), instead of u = 0.
  bool initial_equilibrium = false;
  /// A given pore pressure (of x, y, z, t) loading the skeleton in a scene
  /// without [flow]: one-way coupling, for depletion studies. `alpha` is its
  /// Biot coefficient (0 without it).
  std::optional<Expression> pore_pressure;
  double alpha = 0;
};

/// @brief Barton-Bandis closure of a conduit fault's hydraulic aperture
/// under its effective normal stress s_n (docs/theory.md "Flow in a
/// fault"): the closed fault's aperture w_r + V_m - V_m s_n/(K_ni V_m + s_n),
/// V_m the largest closure (m), K_ni the initial normal stiffness (Pa/m).
struct ClosureSpec
{
  double V_m = 0, K_ni = 0;
};

/// @brief A fault ([fault.NAME], issue 37): an interior physical group of a
/// gmsh mesh whose two faces may open and slide. The scene reader reads and
/// checks it; the split of the mesh along it and the contact of its faces
/// use it.
struct FaultSpec
{
  Expression gap;                     // the initial normal aperture g0, of x, y, z
  std::optional<Expression> pressure; // the fluid pressure in the fault, pushing both faces apart (x, y, z, t)
  /// The pore pressure of the cells beside each face pushes on it (not
  /// with `pressure`).
  bool pore_pressure_load = false;
  FaultFlow flow = FaultFlow::transparent;
  /// d numbers: the hint that orients the fault's normal; its + side is the
  /// side the normal points into.
  std::vector<double> normal;
  FrictionSpec friction;
  /// flow = "conduit": the hydraulic aperture w_h of the closed fault (m),
  /// and the permeability across each face's half aperture (inf: the rock's
  /// pressure at a face is the fault's).
  double residual_aperture = 0;
  double normal_permeability = std::numeric_limits<double>::infinity();
  /// flow = "conduit": the fault's own tangential permeability k_f (m^2),
  /// its transmissivity k_f w_h; 0: the cubic law's, w_h^3 / 12.
  double permeability = 0;
  /// flow = "conduit" in a scene with mechanics: the closed aperture's
  /// Barton-Bandis closure (none: w_r at any stress).
  std::optional<ClosureSpec> closure;
  /// The mesh size at the fault's tips (its edges inside the body, m; 0:
  /// the mesh as drawn) and its growth per metre away from them: gmsh
  /// meshes a .geo with at most tip_size + tip_grading * distance.
  double tip_size = 0, tip_grading = 0.5;
};

/// Permeability: a scalar (number or expression evaluated at cell midpoints)
/// or a constant tensor.
struct FlowSpec
{
  double M = std::numeric_limits<double>::infinity();
  double c_f = 0, phi0 = 0, mu_f = 1;
  std::optional<Expression> permeability;
  std::optional<std::vector<double>> permeability_tensor; // row-major d x d
  std::optional<double> rho_f;
  std::optional<std::vector<double>> gravity;
  std::optional<Expression> source;
  Expression initial_pressure;
  /// S = 1/M + c_f phi0 (alg. "Parameters")
  double storage() const { return 1.0 / M + c_f * phi0; }
};

struct CouplingSpec
{
  double alpha = 1;
  CouplingScheme scheme = CouplingScheme::fixed_stress;
  int q = 1;                // 1 with q = "auto" (the first window's)
  /// coupling.q = "auto" (time/window_control.h): each window's q, at
  /// most q_max, from the predicted relative change of the displacement
  /// over the window, at most q_tolerance.
  bool q_auto = false;
  int q_max = 16;
  double q_tolerance = 1e-2;
  LChoice L_choice = LChoice::paper;
  double L_number = 0; // L_choice = number
  double tolerance = 1e-8;
  int max_iterations = 100;
  /// Anderson's keeps `depth` differences.
  Acceleration acceleration = Acceleration::automatic;
  int depth = 8;
  Fallback fallback = Fallback::none;
  /// A cycle of the split at a pair's kink is ended by pins (coupling/pins.h).
  bool pin_cycles = true;
  /// q flow steps per mechanics step (either multirate scheme).
  bool multirate() const
  {
    return scheme == CouplingScheme::multirate or scheme == CouplingScheme::multirate_two_pass;
  }
};

/// Closed-form solution to compare with at the final time.
struct ReferenceSpec
{
  ReferenceSolution solution = ReferenceSolution::terzaghi;
  double load = 0;      // terzaghi: q_load, the compressive traction on the top
  double height = 0;    // terzaghi: h
  double force = 0;     // mandel: F (2F on the full specimen, per unit thickness)
  std::string plate;    // mandel: the boundary (y = b) carrying the rigid plate
};

/// Below this many cells per rank, 15000 triangles or 2000 tetrahedra, a
/// second rank costs a run more than it saves (docs/performance.md,
/// "nineteenth session"; in 2D, where each rank makes every back-solve,
/// "forty-second session"): a tetrahedron carries more work.
constexpr int default_cells_per_rank(int dimension) { return dimension == 2 ? 15000 : 2000; }

/// How each system is solved. PETSc options of a system's prefix override.
struct SolverSpec
{
  SolverChoice flow = SolverChoice::automatic, mechanics = SolverChoice::automatic,
               monolithic = SolverChoice::automatic;
  /// Inexact coupling (fixed_stress.h): the iterative solves of a coupling
  /// iteration are only as accurate as its increment needs.
  bool inexact_coupling = true;
  /// The fewest cells a rank works on (domain/working_ranks.h); 0: every
  /// rank works.
  int cells_per_rank = default_cells_per_rank(2);
};

/// @brief A material region: cells (a gmsh physical group of cells, or the
/// cells whose midpoint satisfies `where`) whose physics are the scene's
/// own with some material values replaced (docs/user-guide.md, "Material regions").
struct RegionSpec
{
  std::optional<Expression> where;         // the cells whose midpoint satisfies it (non-zero)
  std::optional<MechanicsSpec> mechanics;  // the scene's [mechanics] with the region's E, nu or G, lambda,
                                           // body_force
  bool body_force = false;                 // the region gives its own body force
  std::optional<FlowSpec> flow;            // the scene's [flow] with the region's M, c_f, phi0, permeability
  double alpha = 0;                        // the scene's alpha or the region's
};

/// time.adaptive: steps chosen by a local error estimate
/// (time/step_control.h); time.dt is the first step.
struct AdaptiveSpec
{
  double tolerance = 0; // of the error per unit step, relative to the field's largest norm
  double dt_min = 0, dt_max = 0;
};

struct Scene
{
  std::string file, name, description;
  MeshSpec mesh;
  std::map<std::string, BoundarySpec> boundaries;
  std::map<std::string, WellSpec> wells;
  std::map<std::string, RegionSpec> regions; // cells in no region take the top-level values
  std::map<std::string, FaultSpec> faults;
  std::optional<MechanicsSpec> mechanics;
  std::optional<FlowSpec> flow;
  std::optional<CouplingSpec> coupling; // present iff mechanics and flow
  double end_time = 0, dt = 0;
  double growth = 1; // time.growth: dt_k = dt growth^(k-1)
  int retry = 0;      // time.retry: a failed step is retried with halved steps up to this many times
  TimeScheme time_scheme = TimeScheme::backward_euler; // time.scheme
  std::optional<AdaptiveSpec> adaptive;       // time.adaptive
  bool write_xdmf = true;
  /// output.times or output.every (and time.end): the times written after
  /// t = 0; empty: every step.
  std::vector<double> output_times;
  int checkpoint_every = 0; // output.checkpoint_every: steps between checkpoints, 0 none
  double progress_interval = 10; // output.progress_interval: seconds between lines within a step
  std::optional<ReferenceSpec> reference;
  SolverSpec solver;

  /// At most this many (fine) time steps: a larger count is refused.
  static constexpr int max_steps = 1000000;

  bool has_contact() const;
  /// Some region gives its own body force: the body force is applied cell
  /// by cell (each cell its material's), not interpolated at the nodes.
  bool cellwise_body_force() const;
  int num_steps() const;
  /// t_0 = 0, t_1, ..., t_N = end_time (fine steps) of fixed or growing
  /// steps (adaptive steps are planned by time/time_grid.h).
  std::vector<double> times() const;
  /// The times a step must land on: the output times and time.end.
  std::vector<double> stops() const;
  /// Whether t is one of the output times (every t with no output.times).
  bool is_output_time(double t) const;
};

/// The names of the boundaries a built-in mesh provides.
std::vector<std::string> builtin_boundary_names(int dimension);

} // namespace biotcontact
