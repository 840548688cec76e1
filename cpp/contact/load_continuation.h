// Continuation in the load: a contact solve that fails from its start is
// approached from the last load the solver solved, through loads between
// (docs/theory.md, "Friction"). It knows no physics: a solve of the VI at a
// load, and the last solved load and solution.
#pragma once

#include <functional>
#include <petscvec.h>

namespace biotcontact
{

/// @brief The last load a VI was solved for and its solution (in the VI's
/// unknowns), while its operator stays the one they were solved with.
class SolvedLoad
{
public:
  ~SolvedLoad();
  /// b and x solve the VI (collective).
  void keep(Vec b, Vec x);
  /// The operator changed: (b, x) no longer solve it.
  void forget() { _known = false; }
  bool known() const { return _known; }
  Vec load() const { return _b; }
  Vec solution() const { return _x; }

private:
  Vec _b = nullptr, _x = nullptr;
  bool _known = false;
};

/// The solves a continuation takes at most: halving steps from 1/2 reach a
/// load whose last step needs 1/8 in about 12.
constexpr int continuation_solves = 12;

/// Solves the VI at `target` by `solve` (which throws SolverError when it
/// fails, leaving its x as it was) along b(tau) = b_0 + tau (target - b_0)
/// from the solved load (b_0, x_0): tau advances by 1/2, and by half of
/// the last advance after a failure, at most `max_solves` solves and not
/// below 1/64. Where tau reaches 1, x holds the solution and it returns
/// true; else x is unchanged (collective).
bool continue_load(const SolvedLoad& from, Vec target, Vec x, const std::function<void(Vec b, Vec x)>& solve,
                   int max_solves);

} // namespace biotcontact
