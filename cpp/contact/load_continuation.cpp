#include "contact/load_continuation.h"

#include "assembly/petsc_error.h"

#include <algorithm>

namespace biotcontact
{

SolvedLoad::~SolvedLoad()
{
  warn_petsc(VecDestroy(&_b), "load continuation: VecDestroy");
  warn_petsc(VecDestroy(&_x), "load continuation: VecDestroy");
}

void SolvedLoad::keep(Vec b, Vec x)
{
  if (!_b)
  {
    check_petsc(VecDuplicate(b, &_b), "load continuation: VecDuplicate");
    check_petsc(VecDuplicate(x, &_x), "load continuation: VecDuplicate");
  }
  check_petsc(VecCopy(b, _b), "load continuation: VecCopy");
  check_petsc(VecCopy(x, _x), "load continuation: VecCopy");
  _known = true;
}

namespace
{
/// The continuation's load and iterate, destroyed however it ends (also
/// by an error of another kind than SolverError).
struct WorkVectors
{
  Vec b = nullptr, y = nullptr;
  ~WorkVectors()
  {
    warn_petsc(VecDestroy(&b), "load continuation: VecDestroy");
    warn_petsc(VecDestroy(&y), "load continuation: VecDestroy");
  }
};
} // namespace

bool continue_load(const SolvedLoad& from, Vec target, Vec x, const std::function<void(Vec b, Vec x)>& solve,
                   int max_solves)
{
  WorkVectors work;
  Vec& b = work.b;
  Vec& y = work.y;
  check_petsc(VecDuplicate(target, &b), "load continuation: VecDuplicate");
  check_petsc(VecDuplicate(x, &y), "load continuation: VecDuplicate");
  check_petsc(VecCopy(from.solution(), y), "load continuation: VecCopy");
  // The solution is piecewise smooth in the load: where a step's states
  // change too much for one Newton solve, a shorter step changes fewer.
  double tau = 0, advance = 0.5;
  for (int solves = 0; tau < 1 and advance >= 1.0 / 64 and solves < max_solves; ++solves)
  {
    const double next = std::min(1.0, tau + advance);
    check_petsc(VecCopy(from.load(), b), "load continuation: VecCopy");
    check_petsc(VecAXPBY(b, next, 1 - next, target), "load continuation: VecAXPBY");
    try
    {
      solve(b, y);
      tau = next;
    }
    catch (const SolverError&)
    {
      advance /= 2;
    }
  }
  const bool reached = tau >= 1;
  if (reached)
    check_petsc(VecCopy(y, x), "load continuation: VecCopy");
  return reached;
}

} // namespace biotcontact
