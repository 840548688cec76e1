"""What one system's solver did, and the PETSc log stage it is read from:
set-ups (PCSetUp) and back-solves (KSPSolve) of the system's own stage.
Twin: cpp/solvers/solver_statistics.h."""
from petsc4py import PETSc


class SolverStatistics:
    """What one system's solver did (cpp/solvers/solver_statistics.h)."""

    def __init__(self):
        self.solves = self.setups = self.back_solves = self.linear_iterations = 0
        self.newton_iterations = self.active_set_changes = self.schur_columns = self.schur_factorizations = 0
        self.contact_factorizations = 0  # the condensed contact solve's (its own log stage)
        self.setup_time = self.solve_time = self.total_time = self.assembly_time = self.schur_time = 0.0


# The counts of SolverStatistics by name: the one list that checkpoints,
# restarts and the sum with an earlier run's counts read.
solver_counts = ("solves", "setups", "back_solves", "linear_iterations", "newton_iterations", "active_set_changes",
                 "schur_columns", "schur_factorizations", "contact_factorizations")


class SolverStage:
    """A PETSc log stage named after a system, pushed while it solves."""

    def __init__(self, name):
        self.stage = PETSc.Log.Stage(name)

    def read(self, statistics):
        setup = PETSc.Log.Event("PCSetUp").getPerfInfo(self.stage.id)
        solve = PETSc.Log.Event("KSPSolve").getPerfInfo(self.stage.id)
        statistics.setups, statistics.setup_time = setup["count"], setup["time"]
        statistics.back_solves, statistics.solve_time = solve["count"], solve["time"]

    def __enter__(self):
        self.stage.push()

    def __exit__(self, *_):
        self.stage.pop()
