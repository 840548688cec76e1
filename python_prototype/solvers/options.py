"""The project's PETSc options as the solvers read them (cpp/solvers/options.h):
the error that options which do not make a solver raise, the name of a
system in messages, from its options prefix, and the packages refused.
Below solver.py and field_split.py, which both report bad options."""


class OptionsError(Exception):
    """PETSc options that do not make a solver (exit 2, bad input)."""


def system_name(prefix):
    """"the mechanics" from "mechanics_"."""
    return "the " + prefix[:-1]


def threaded_superlu(options, threads):
    """The error for PETSc options (`options`: name -> value, as
    PETSc.Options().getAll() gives them) that name SuperLU_DIST while
    OpenMP runs `threads` threads per process; "" when none does or there
    is one thread. Debian's SuperLU_DIST 8.1.2 solves wrongly with more
    than one (cpp/solvers/options.h)."""
    if threads <= 1:
        return ""
    for name, value in options.items():
        if value == "superlu_dist":
            return (f"-{name} superlu_dist: SuperLU_DIST solves wrongly with {threads} OpenMP threads "
                    "(Debian's 8.1.2: the contact solver cycles, the split diverges); set OMP_NUM_THREADS=1")
    return ""


def relative_tolerance_out_of_range(options):
    """The error for a relative tolerance (-<prefix>ksp_rtol,
    -<prefix>snes_rtol) in `options` (name -> value, as getAll gives them)
    outside [0, 1): from 1 on, any first iterate meets it (a Hertz contact
    147 times off with exit 0); "" when there is none (cpp/solvers/options.h)."""
    for name, value in options.items():
        if not name.endswith("_rtol"):
            continue
        try:
            number = float(value)
        except ValueError:
            continue
        if not 0 <= number < 1:
            return f"-{name} {value}: a relative tolerance lies in [0, 1) (from 1 on any first iterate meets it)"
    return ""
