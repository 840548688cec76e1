// What every module shares about a scene's input: bad input raises
// SceneError, one line naming the file and the key; a choice is one of a
// few named values, read into its enum once, when the scene is read
// (schema.h the schema, section.h the reader).
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace biotcontact
{

/// Bad input: the message is one line naming the file and the key.
struct SceneError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// What is wrong with a value that must be >= 0: "is NaN", "is infinite"
/// or "must be >= 0, got V"; empty when it is fine.
inline std::string nonnegative_problem(double v)
{
  if (std::isnan(v))
    return "is NaN";
  if (std::isinf(v))
    return "is infinite";
  return v >= 0 ? std::string() : "must be >= 0, got " + std::to_string(v);
}

/// A point for a message: "(x, y)" or "(x, y, z)".
inline std::string point_text(const double* x, int d)
{
  std::string s = "(" + std::to_string(x[0]) + ", " + std::to_string(x[1]);
  return s + (d == 3 ? ", " + std::to_string(x[2]) : "") + ")";
}

/// @brief The names a scene gives the values of a choice, in the order its
/// messages list them: Choices<E>::names for every choice E below. A
/// choice is read into its enum once, when the scene is read.
template <class E>
struct Choices;

/// The scene's name of a choice's value.
template <class E>
const char* name_of(E value)
{
  for (const auto& [v, text] : Choices<E>::names)
    if (v == value)
      return text;
  return "";
}

enum class MeshType
{
  rectangle,
  box,
  gmsh
};
template <>
struct Choices<MeshType>
{
  static constexpr std::array<std::pair<MeshType, const char*>, 3> names{
      {{MeshType::rectangle, "rectangle"}, {MeshType::box, "box"}, {MeshType::gmsh, "gmsh"}}};
};

/// The coupling scheme: "fixed-stress" (single rate), "multirate" (the
/// paper's, as printed), "multirate-two-pass" (docs/multirate-two-pass.md: a
/// second flow pass without L corrects the fine steps) or "monolithic".
enum class CouplingScheme
{
  fixed_stress,
  multirate,
  multirate_two_pass,
  monolithic
};
template <>
struct Choices<CouplingScheme>
{
  static constexpr std::array<std::pair<CouplingScheme, const char*>, 4> names{
      {{CouplingScheme::fixed_stress, "fixed-stress"},
       {CouplingScheme::multirate, "multirate"},
       {CouplingScheme::multirate_two_pass, "multirate-two-pass"},
       {CouplingScheme::monolithic, "monolithic"}}};
};

/// The fixed-stress stabilisation L: alpha^2/lambda ("paper"), alpha^2/K_dr
/// ("kdr"), half of that ("half-kdr"), or a number.
enum class LChoice
{
  paper,
  kdr,
  half_kdr,
  number
};
template <>
struct Choices<LChoice>
{
  static constexpr std::array<std::pair<LChoice, const char*>, 4> names{
      {{LChoice::paper, "paper"}, {LChoice::kdr, "kdr"}, {LChoice::half_kdr, "half-kdr"}, {LChoice::number, "number"}}};
};

/// The acceleration of the split: none (the paper's iteration), Anderson's
/// (coupling/anderson.h), or "auto": the paper's iteration, Anderson's in a
/// window from where it stagnates (coupling/cycle.h).
enum class Acceleration
{
  none,
  anderson,
  automatic
};
template <>
struct Choices<Acceleration>
{
  static constexpr std::array<std::pair<Acceleration, const char*>, 3> names{
      {{Acceleration::none, "none"}, {Acceleration::anderson, "anderson"}, {Acceleration::automatic, "auto"}}};
};

/// coupling.fallback: what solves a step the split fails at (after
/// time.retry's halvings): nothing (the run ends there) or the monolithic
/// scheme, from the last completed step; the split goes on after it.
enum class Fallback
{
  none,
  monolithic
};
template <>
struct Choices<Fallback>
{
  static constexpr std::array<std::pair<Fallback, const char*>, 2> names{
      {{Fallback::none, "none"}, {Fallback::monolithic, "monolithic"}}};
};

/// time.scheme: the discrete time derivative (time/time_scheme.h).
enum class TimeScheme
{
  backward_euler,
  bdf2
};
template <>
struct Choices<TimeScheme>
{
  static constexpr std::array<std::pair<TimeScheme, const char*>, 2> names{
      {{TimeScheme::backward_euler, "backward-euler"}, {TimeScheme::bdf2, "bdf2"}}};
};

/// How a system is solved: a factorisation, a Krylov method, or chosen by
/// size ("auto", solvers/solver.h choose_method).
enum class SolverChoice
{
  automatic,
  direct,
  iterative
};
template <>
struct Choices<SolverChoice>
{
  static constexpr std::array<std::pair<SolverChoice, const char*>, 3> names{
      {{SolverChoice::direct, "direct"}, {SolverChoice::iterative, "iterative"}, {SolverChoice::automatic, "auto"}}};
};

/// fault.NAME.flow: what the fault is to the flow (issue 37): no obstacle
/// ("transparent"), a barrier ("sealing"), held at its `pressure`, or a
/// conduit with a pressure and a flow of its own (issue 39, docs/theory.md
/// "Flow in a fault").
enum class FaultFlow
{
  transparent,
  sealing,
  pressure,
  conduit
};
template <>
struct Choices<FaultFlow>
{
  static constexpr std::array<std::pair<FaultFlow, const char*>, 4> names{{{FaultFlow::transparent, "transparent"},
                                                                           {FaultFlow::sealing, "sealing"},
                                                                           {FaultFlow::pressure, "pressure"},
                                                                           {FaultFlow::conduit, "conduit"}}};
};

/// The closed form of [reference].
enum class ReferenceSolution
{
  terzaghi,
  mandel
};
template <>
struct Choices<ReferenceSolution>
{
  static constexpr std::array<std::pair<ReferenceSolution, const char*>, 2> names{
      {{ReferenceSolution::terzaghi, "terzaghi"}, {ReferenceSolution::mandel, "mandel"}}};
};

} // namespace biotcontact
