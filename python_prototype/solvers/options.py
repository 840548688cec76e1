"""The project's PETSc options as the solvers read them (cpp/solvers/options.h):
the error that options which do not make a solver raise, and the name of a
system in messages, from its options prefix. Below solver.py and
field_split.py, which both report bad options."""


class OptionsError(Exception):
    """PETSc options that do not make a solver (exit 2, bad input)."""


def system_name(prefix):
    """"the mechanics" from "mechanics_"."""
    return "the " + prefix[:-1]
