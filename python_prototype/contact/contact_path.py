"""Which system the contact VI is posed on (docs/theory.md, "Solvers";
cpp/contact/contact_path.h): the Schur complement of the contact DOFs
(schur_complement.py) or the whole system, chosen by what each costs, and
what answers a failed full solve."""
import dataclasses
import enum

from petsc4py import PETSc

from ..solvers.options import OptionsError
from ..solvers.solver import Method

# Above this many contact DOFs the dense H (m^2 doubles, m back-solves to
# form, m^3/3 flops per active-set change) costs more than refactorising the
# sparse inactive-set matrix.
MAX_CONDENSED_DOFS = 2000

_help_printed = set()  # the prefixes whose -help lines are out, as PETSc keeps them for the C++


class ContactPath(enum.Enum):
    """Where the contact VI is posed: on the Schur complement of the contact
    DOFs, on the whole system, or on the whole system for one Newton step
    (two with friction) and, if that did not solve it, condensed."""
    condensed = 0
    full = 1
    full_then_condensed = 2


@dataclasses.dataclass
class PathCosts:
    """What the path depends on: the system's solver, the contact DOFs over
    all ranks, whether A changes between most solves (the monolithic system
    with conduit faults) and whether the run solves the contact once."""
    method: Method
    contact_dofs: int
    changing: bool = False
    once: bool = False


@dataclasses.dataclass
class ContactPathChoice:
    """The path, and whether a solve that fails on the whole system is solved
    again condensed (and the run goes on condensed): where the user did not
    choose the path and the condensed one is open (a direct solver, at most
    MAX_CONDENSED_DOFS contact DOFs)."""
    path: ContactPath
    condensed_on_failure: bool = False


def _read_condensed(comm, prefix, fallback):
    """-<prefix>contact_condensed, `fallback` when not given, and whether it
    was given; with -help, the lines PETSc prints for the option the C++
    registers (read_condensed), which petsc4py 3.18 cannot register."""
    options = PETSc.Options()
    try:
        condensed = options.getBool(prefix + "contact_condensed", fallback)
    except PETSc.Error:
        raise OptionsError(f"-{prefix}contact_condensed: not a boolean (true or false)") from None
    if options.hasName("help") and prefix not in _help_printed:
        _help_printed.add(prefix)
        text = ("pose the contact VI on the Schur complement of the contact DOFs (default with a direct solver and "
                f"at most {MAX_CONDENSED_DOFS} contact DOFs, after one full Newton step, two with "
                "friction, that did not converge when the run solves the contact once), else on the whole system")
        PETSc.Sys.Print(f"----------------------------------------\nContact solver (biotcontact):\n"
                        f"  -{prefix}contact_condensed: <{str(fallback).upper()} : {str(condensed).upper()}> {text} "
                        "(docs/user-guide.md)", comm=comm)
    return condensed, options.hasName(prefix + "contact_condensed")


def _check_bound_method(prefix, method):
    """Only the VI methods take bounds; any other would ignore the contact.
    Asked of both prefixes, so that a type given for the path not taken is
    not ignored silently either. An iterative `method` preconditions the
    reduced-space steps on their inactive set (InactiveSetPreconditioner),
    which vinewtonssls, stepping on the whole space, does not have."""
    for p in (prefix, prefix + "contact_"):
        given = PETSc.Options().getString(p + "snes_type", "")
        if given and given not in ("vinewtonrsls", "vinewtonssls"):
            raise OptionsError(f"-{p}snes_type {given}: the contact solver needs a bound-constrained method "
                               "(vinewtonrsls or vinewtonssls)")
        # nleqerr failed on the reduced space ("Incompatible vector local
        # lengths", PETSc error 60, at the first Newton step)
        search = PETSc.Options().getString(p + "snes_linesearch_type", "")
        if search and search not in ("basic", "bt", "l2", "cp"):
            raise OptionsError(f"-{p}snes_linesearch_type {search}: the contact solver takes the line searches "
                               "basic, bt, l2 or cp")
    if method == Method.iterative and PETSc.Options().getString(prefix + "snes_type", "") == "vinewtonssls":
        raise OptionsError(f"-{prefix}snes_type vinewtonssls: the iterative contact solver needs vinewtonrsls "
                           "(its preconditioner works on the reduced space's inactive set); vinewtonssls needs the "
                           "direct solver")


def choose_contact_path(comm, prefix, costs):
    """-<prefix>contact_condensed, by default condensed when the system is
    solved directly, C is small enough and A is not `changing` (forming H
    takes m solves, m more at each change of A). A run that solves the
    contact once would pay the Schur complement for one solve: there the
    whole system's first Newton steps come first, all a solve whose active
    set they find costs; else the condensed path follows. Raises
    OptionsError for a value that is not a boolean, or a -snes_type of
    either prefix (<prefix>, <prefix>contact_) that takes no bounds
    (collective)."""
    _check_bound_method(prefix, costs.method)
    open_ = costs.method == Method.direct and costs.contact_dofs <= MAX_CONDENSED_DOFS
    condensed, given = _read_condensed(comm, prefix, open_ and not costs.changing)
    if not condensed:
        return ContactPathChoice(ContactPath.full, open_ and not given)
    return ContactPathChoice(ContactPath.full_then_condensed if costs.once and not given else ContactPath.condensed)
