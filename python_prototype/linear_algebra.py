"""Assembly and solver helpers shared by the steps (cpp/linear_algebra.cpp).

Right-hand sides are Functions used as vectors: `.x.array` holds owned and
ghost entries (assembly adds into both), `.vector` is the PETSc view.
"""
import numpy as np
from dolfinx import fem
from dolfinx.cpp.la import ScatterMode
from mpi4py import MPI
from petsc4py import PETSc


class SolverError(Exception):
    """A solver did not converge: the run stops with this message (exit 3)."""


class OptionsError(Exception):
    """PETSc options that do not make a solver (exit 2, bad input)."""


def reason_name(enum, reason):
    """PETSc's name of a converged reason, as the C++ prints it (petsc4py
    3.18 knows -11 only by its deprecated name)."""
    name = next((k for k in dir(enum) if not k.startswith("_") and getattr(enum, k) == reason), str(reason))
    return name.replace("DIVERGED_PCSETUP_FAILED", "DIVERGED_PC_FAILED")


def set_default_option(name, value):
    """Sets a PETSc option unless the command line gave it."""
    options = PETSc.Options()
    if not options.hasName(name):
        options.setValue(name, value)


def assemble_matrix(a, bcs):
    """Rows and columns of Dirichlet DOFs become identity rows."""
    A = fem.petsc.assemble_matrix(a, bcs)
    A.assemble()
    return A


def reassemble_matrix(A, a, bcs):
    """Assembles a into A (same sparsity); its solvers refactorise it at their next solve."""
    A.zeroEntries()
    fem.petsc.assemble_matrix(A, a, bcs)
    A.assemble()


def add_vector(b, L):
    """Adds the local contributions of L to the Function-vector b (ghosts too)."""
    fem.assemble_vector(b.x.array, L)


def accumulate_ghosts(b):
    b.x.scatter_reverse(ScatterMode.add)


def finish_rhs(b, a, bcs):
    """Lifts the Dirichlet values of `a`, accumulates ghosts, sets the Dirichlet rows."""
    if bcs:
        fem.apply_lifting(b.x.array, [a], [bcs])
    accumulate_ghosts(b)
    if bcs:
        fem.set_bc(b.x.array, bcs)


def owned(V):
    """Number of owned (unrolled) DOFs of V on this rank."""
    return V.dofmap.index_map.size_local * V.dofmap.index_map_bs


def owned_norm(x, V, comm):
    """Euclidean norm of the owned part of a DOF array (collective)."""
    n = owned(V)
    return np.sqrt(comm.allreduce(float(np.dot(x[:n], x[:n])), op=MPI.SUM))


def dof_map(space, sub):
    """For every DOF of `space` (unrolled, ghosts too) its DOF in the parent
    of `sub`, a subspace with the same element (cpp collapse() maps)."""
    collapsed, to_parent = sub.collapse()
    bs = space.dofmap.index_map_bs
    im = space.dofmap.index_map
    node = np.empty(im.size_local + im.num_ghosts, dtype=np.int64)
    node[space.dofmap.list.array] = collapsed.dofmap.list.array
    unrolled = (bs * node[:, None] + np.arange(bs)).ravel()
    return np.asarray(to_parent)[unrolled]


def set_solver_defaults(prefix):
    """Direct-solver defaults of a solver with this options prefix: LU
    (preonly) unless the command line says otherwise, MUMPS (with more
    workspace than its default, for refactorisations) when the factorisation
    is LU or Cholesky (as cpp/linear_algebra.cpp)."""
    # A preconditioner other than a factorisation is no solver by itself:
    # then the default Krylov method is GMRES instead of a single application.
    direct = PETSc.Options().getString(prefix + "pc_type", "lu") in ("lu", "cholesky")
    set_default_option(prefix + "ksp_type", "preonly" if direct else "gmres")
    set_default_option(prefix + "pc_type", "lu")
    if direct:
        set_default_option(prefix + "pc_factor_mat_solver_type", "mumps")
        set_default_option(prefix + "mat_mumps_icntl_14", "400")


class LinearSolver:
    """KSP with an options prefix; MUMPS LU unless -<prefix>ksp_type/pc_type
    say otherwise. The operator is factorised once and reused."""

    def __init__(self, comm, prefix, A):
        self.prefix = prefix
        set_solver_defaults(prefix)
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setOperators(A, A)
        try:
            self.ksp.setFromOptions()
        except PETSc.Error as e:  # e.g. -flow_pc_type ilu with the default MUMPS factorisation
            raise OptionsError(f"the PETSc options of the {prefix[:-1]} solver do not make a solver "
                               f"(PETSc error {e.ierr}; see -{prefix}pc_factor_mat_solver_type)") from None

    def solve(self, x, b):
        try:
            self.ksp.solve(b, x)
        except PETSc.Error as e:  # e.g. a factorisation PETSc does not have for this matrix
            raise SolverError(f"the {self.prefix[:-1]} linear solver failed: PETSc error {e.ierr}") from None
        reason = self.ksp.getConvergedReason()
        if reason < 0:
            raise SolverError(f"the {self.prefix[:-1]} linear solver failed: "
                              f"{reason_name(PETSc.KSP.ConvergedReason, reason)}")
        return self.ksp.getIterationNumber()
