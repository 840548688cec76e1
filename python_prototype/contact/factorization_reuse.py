"""How a factorised VI's Newton steps meet a changed Jacobian
(cpp/contact/factorization_reuse.h): by GMRES on an earlier factorisation
where a factorisation costs about 100 back-solves (3D friction, a 3D conduit
fault's apertures), or by factorising each change with a cheap analysis
where it costs fewer (2D friction, a 2D conduit fault). docs/theory.md,
"Solvers"; docs/performance.md, "thirty-fourth session", "fortieth
session"."""
from petsc4py import PETSc

from ..solvers.solver import factor_prefix, given_by_user, set_default_option


def reuse_options(prefix):
    """The options (name without its dash, value) under which the Newton
    steps of the VI with options prefix `prefix` run GMRES on the last
    factorisation: to 1e-12 (near a direct solve's round-off) in at most
    100 iterations, each unless the user gave it. SNES VI sets its KSP up
    from the options again when the inactive set changes, hence options."""
    return [(prefix + name, value) for name, value in (("ksp_type", "gmres"), ("ksp_rtol", "1e-12"),
                                                       ("ksp_max_it", "100"))
            if not given_by_user(prefix + name)]


# The largest system whose factorisations analyse_quickly hands to AMD: above
# it AMD's fill costs more than METIS's analysis saves (a 2D frictional crack
# of 3.7e5 unknowns 3 % slower, factorised twice).
QUICK_ANALYSIS_ROWS = 300000


def analyse_quickly(prefix, K):
    """MUMPS's analysis by AMD instead of its own choice (METIS) for the
    factorisations of K, the system with options prefix `prefix` (or of
    its copy on each rank), unless the user chose or K has more than
    QUICK_ANALYSIS_ROWS rows: 0.009 s against 0.13 s at 13,414 unknowns,
    for back-solves about 10 % dearer."""
    if K.getSize()[0] > QUICK_ANALYSIS_ROWS:
        return
    options = PETSc.Options()
    factor = factor_prefix(prefix)
    if options.getString(factor + "pc_factor_mat_solver_type", "") == "mumps":
        set_default_option(factor + "mat_mumps_icntl_7", "0")


class KrylovOnReuse:
    """reuse_options in PETSc's database while the VI solves (the system's
    own solvers share its prefix and stay direct), the values before
    restored after: `with KrylovOnReuse(snes, options):`."""

    def __init__(self, snes, options):
        self.snes, self.options = snes, options

    def __enter__(self):
        database = PETSc.Options()
        self.before = [(name, database.getString(name) if database.hasName(name) else None)
                       for name, _ in self.options]
        for name, value in self.options:
            database.setValue(name, value)
        self.snes.getKSP().setFromOptions()
        return self

    def __exit__(self, *exception):
        database = PETSc.Options()
        for name, value in self.before:
            if value is None:
                database.delValue(name)
            else:
                database.setValue(name, value)
        return False
