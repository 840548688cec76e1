#include "solvers/solver_statistics.h"

#include <map>

namespace biotcontact
{

SolverStage::SolverStage(const std::string& name)
{
  // One stage per name for the whole process (a stage cannot be removed).
  static std::map<std::string, PetscLogStage> stages;
  auto it = stages.find(name);
  if (it == stages.end())
  {
    check_petsc(PetscLogStageRegister(name.c_str(), &_stage), "the log stage " + name + ": PetscLogStageRegister");
    stages[name] = _stage;
  }
  else
    _stage = it->second;
}

void SolverStage::read(SolverStatistics& s) const
{
  auto info = [&](const char* event)
  {
    PetscLogEvent id = 0;
    PetscEventPerfInfo perf{};
    check_petsc(PetscLogEventGetId(event, &id), std::string("a solver's log stage: PetscLogEventGetId ") + event);
    check_petsc(PetscLogEventGetPerfInfo(_stage, id, &perf), "a solver's log stage: PetscLogEventGetPerfInfo");
    return perf;
  };
  const PetscEventPerfInfo setup = info("PCSetUp"), solve = info("KSPSolve");
  s.setups = setup.count;
  s.setup_time = setup.time;
  s.back_solves = solve.count;
  s.solve_time = solve.time;
}

} // namespace biotcontact
