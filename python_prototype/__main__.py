"""Command line, as cpp/main.cpp (plus `compare`).

Exit status: 0 success, 2 bad input (one line naming the key or file),
3 a solver or the coupling did not converge (what was finished is
written), 1 anything else; `compare` exits 1 when the runs differ.
"""
import array
import os
import sys
import types
from contextlib import contextmanager

if not __package__:  # run as a path, `python3 /path/to/python_prototype run ...`, from any directory
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [os.path.dirname(here)] + [p for p in sys.path if os.path.abspath(p or ".") != here]
    import importlib
    importlib.import_module("python_prototype")  # the parent of the relative imports below
    __package__ = "python_prototype"

from .output.progress import RUN_OUTPUT_FAILED  # noqa: E402

USAGE = """usage:
  python3 -m python_prototype run SCENE.toml [--out DIR | --restart DIR] [--set key.path=value ...] [PETSc options]
  python3 -m python_prototype check SCENE.toml [--set key.path=value ...]
  python3 -m python_prototype compare DIR_A DIR_B [--tolerance 1e-8]
  python3 -m python_prototype --help | --version

run      simulate the scene; writes DIR/solution.xdmf (+ .h5), DIR/iterations.csv
         and DIR/summary.json (DIR defaults to results/<scene name>)
check    validate the scene and exit
compare  compare the outputs of two runs (fields, coupling iterations, contact sets)
--set    override a scene value, e.g. --set coupling.L=kdr --set time.dt=0.5
--restart DIR  continue the run in DIR from its checkpoint (output.checkpoint_every)

The scene's [solver] table picks "direct", "iterative" or "auto" (by size)
per system; PETSc options with the system's prefix override it (flow_,
mechanics_, monolithic_), e.g.
-flow_ksp_type gmres -flow_pc_type hypre -mechanics_snes_monitor.
The contact solver is SNES vinewtonrsls with bounds on the contact DOFs.
"""


def parse(argv):
    """Our own arguments first; the rest go to PETSc (an option and its value)."""
    command, scene, out, overrides, petsc, bad, restart = "", "", "", [], [], "", ""
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--help", "-h"):
            command = "help"
        elif a == "--version":
            command = "version"
        elif a in ("--out", "--set", "--restart"):
            if i + 1 >= len(argv):
                bad = a + " needs a value"
            elif a == "--out":
                i += 1
                out = argv[i]
            elif a == "--restart":
                i += 1
                restart = argv[i]
            else:
                i += 1
                overrides.append(argv[i])
        elif not command and a in ("run", "check"):
            command = a
        elif not scene and command and not a.startswith("-"):
            scene = a
        elif a.startswith("--"):
            bad = f"unknown option '{a}' (PETSc options take one dash)"
        elif a.startswith("-"):
            petsc.append(a)
            if i + 1 < len(argv) and not argv[i + 1].startswith("-"):
                i += 1
                petsc.append(argv[i])
        else:
            bad = f"unexpected argument '{a}'"
        i += 1
    return command, scene, out, overrides, petsc, bad, restart


def compare_main(argv):
    """`compare DIR_A DIR_B [--tolerance T]`: 0 when the runs agree, 1 when
    they differ, 2 (one line) when the command or a run directory is bad."""
    def refuse(reason):
        print(f"biotcontact: error: {reason}", file=sys.stderr)
        return 2
    tolerance = 1e-8
    if "--tolerance" in argv:
        k = argv.index("--tolerance")
        try:
            tolerance = float(argv[k + 1])
        except (IndexError, ValueError):
            return refuse("--tolerance: expected a number after it")
        argv = argv[:k] + argv[k + 2:]
    if len(argv) != 2:
        return refuse("expected 'compare DIR_A DIR_B [--tolerance T]' (see --help)")
    for directory in argv:
        for name in ("solution.xdmf", "iterations.csv"):
            if not os.path.isfile(os.path.join(directory, name)):
                return refuse(f"{os.path.join(directory, name)}: not found (compare takes two run directories "
                              "written with output.xdmf = true)")
    from xml.etree.ElementTree import ParseError
    from .output.compare import compare
    try:
        return compare(argv[0], argv[1], tolerance)
    except (OSError, ParseError, KeyError, ValueError) as e:
        return refuse(f"cannot read the runs {argv[0]} and {argv[1]}: {e}")


def _start_mpi_alone():
    """A run started without mpirun is one process: Open MPI need not start its
    runtime daemon nor probe the network for peers (0.4 s of every start, as
    cpp/main.cpp), nor have hwloc read every PCI device's configuration,
    nor create the session directory that all isolated processes share (one
    removes it as it ends while another creates it: cpp/main.cpp). A user's
    own setting wins; under mpirun nothing changes."""
    if "OMPI_COMM_WORLD_SIZE" in os.environ or "PMIX_RANK" in os.environ:
        return
    if os.environ.setdefault("OMPI_MCA_ess_singleton_isolated", "1") == "1":
        os.environ.setdefault("OMPI_MCA_orte_create_session_dirs", "0")
    os.environ.setdefault("OMPI_MCA_pml", "ob1")
    os.environ.setdefault("HWLOC_COMPONENTS", "-pci,-linuxio")


def _partition_reproducibly():
    """PT-Scotch partitions the mesh over the ranks with one thread, so that
    the partition, and with it the DOFs' order, is the same at every run of
    one command (as cpp/main.cpp). A user's own setting wins."""
    os.environ.setdefault("SCOTCH_PTHREAD_NUMBER", "1")


def _one_openmp_thread():
    """One OpenMP thread per process unless OMP_NUM_THREADS says otherwise,
    set before PETSc's libraries load the OpenMP runtime, which reads it
    then (as cpp/main.cpp): SuperLU_DIST solves wrongly with more."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")


def _refused_options(PETSc):
    """The error for options that name SuperLU_DIST with several OpenMP
    threads or give a relative tolerance outside [0, 1) ("" when there is
    none), from every PETSc option however given."""
    import ctypes
    from .solvers.options import relative_tolerance_out_of_range, threaded_superlu
    threads = ctypes.CDLL("libgomp.so.1").omp_get_max_threads()
    options = PETSc.Options().getAll()
    return threaded_superlu(options, threads) or relative_tolerance_out_of_range(options)


@contextmanager
def _versions_without_pkg_resources():
    """UFL and FFCx read their own versions at import with pkg_resources,
    whose import scans every installed distribution: 0.19 of the 1.2 s a
    start of the prototype takes (docs/performance.md). While dolfinx
    imports them, a stand-in answers get_distribution(name).version from
    importlib.metadata, the same string (it enters FFCx's cache keys); it is
    then removed, so that setuptools, which the JIT compiler may import
    later, gets the real module."""
    if "pkg_resources" in sys.modules:
        yield
        return
    from importlib import metadata
    stand_in = types.ModuleType("pkg_resources")
    stand_in.get_distribution = lambda name: types.SimpleNamespace(version=metadata.version(name))
    sys.modules["pkg_resources"] = stand_in
    try:
        yield
    finally:
        if sys.modules.get("pkg_resources") is stand_in:
            del sys.modules["pkg_resources"]


def _check_scene(scene, scene_file, comm):
    """`check`: the scene on its mesh (a gmsh file's boundary names are
    known once read): expressions, materials, contact, the split's warning."""
    from .assembly.materials import check_materials, gamma_warning, largest_gamma_of
    from .contact.locate_contact import check_contact
    from .domain.create_domain import create_domain
    from .domain.mesh_checks import check_expressions
    domain = create_domain(scene, comm)
    if domain is None:
        return 0  # this rank waits
    check_expressions(scene, domain, domain.mesh.comm)
    check_materials(scene, domain)
    if scene.mechanics:
        check_contact(scene, domain)
    warning = gamma_warning(scene, largest_gamma_of(scene, domain.regions))
    if comm.rank == 0 and warning:
        print(f"warning: {warning}")
    if comm.rank == 0:
        print(f"{scene_file}: ok ({scene.name}, {scene.num_steps()} steps)")
    return 0


def main(argv):
    if argv[:1] == ["compare"]:
        return compare_main(argv[1:])
    command, scene_file, out, overrides, petsc, bad, restart = parse(argv)
    if command == "help":
        print(USAGE, end="")
        return 0

    _start_mpi_alone()
    _partition_reproducibly()
    _one_openmp_thread()
    # PETSc reads its options once, at initialisation: before dolfinx is imported.
    import petsc4py
    petsc4py.init([sys.argv[0]] + petsc)
    import logging
    from mpi4py import MPI
    with _versions_without_pkg_resources():
        import dolfinx
    from petsc4py import PETSc
    # The solver statistics are read from PETSc's event log (solver.py).
    PETSc.Log.begin()
    # The JIT compiler (setuptools) logs to the root logger at INFO: keep warnings only.
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    dolfinx.log.set_log_level(dolfinx.log.LogLevel.WARNING)
    from .output.checkpoint import restart_fingerprint
    from .output.interruption import install_interruption_handlers
    from .scene.scene import SceneError, agree_on_error, read_scene
    from .simulation import run
    from .solvers.options import OptionsError
    from .solvers.solver import SolverError, petsc_error_text

    comm = MPI.COMM_WORLD
    install_interruption_handlers()
    if command == "version":
        print(f"biotcontact python prototype (dolfinx {dolfinx.__version__}, PETSc "
              f"{'.'.join(map(str, PETSc.Sys.getVersion()))})")
        return 0

    def fail(message, status=2):
        if comm.rank == 0:
            print(f"biotcontact: error: {message}", file=sys.stderr, flush=True)
        return status

    if bad:
        return fail(bad + " (see --help)")
    if not command or not scene_file:
        return fail("expected 'run SCENE.toml' or 'check SCENE.toml' (see --help)")
    refused = _refused_options(PETSc)
    if refused:
        return fail(refused)
    try:
        # Each rank reads the file: one that cannot (its node's file system
        # or memory) stops every rank, before any other collective call.
        try:
            scene, refused = read_scene(scene_file, overrides), ""
        except SceneError as e:
            scene, refused = None, str(e)
        agree_on_error(refused, comm)
        if command == "check":
            return _check_scene(scene, scene_file, comm)
        # A restart goes on in the directory of the run it continues.
        with open(scene_file) as f:
            fingerprint = restart_fingerprint(f.read(), overrides, scene)
        return run(scene, restart or out or os.path.join("results", scene.name), comm, fingerprint, bool(restart))
    except (SceneError, OptionsError) as e:
        return fail(str(e))
    except SolverError as e:
        return fail(str(e), 3)
    except Exception as e:  # noqa: BLE001  (anything else: one line, status 1)
        # a PETSc error in PETSc's words, as check_petsc gives them (its first
        # line, "error code N", names nothing)
        return _unexpected_error(comm, petsc_error_text(e) if isinstance(e, PETSc.Error)
                                 else f"{type(e).__name__}: {(str(e).splitlines() or [''])[0]}")


def _unexpected_error(comm, what):
    """An error of no kind the program expects (a defect, status 1). On
    several ranks this one cannot know whether the others met it too or
    wait for it in a collective, which would hang the run for ever: it says
    the error itself and stops every rank (cpp/main.cpp)."""
    if comm.size == 1:
        print(f"biotcontact: error: {what}", file=sys.stderr, flush=True)
        return 1
    print(f"biotcontact: error on rank {comm.rank}: {what} (every rank stopped)", file=sys.stderr, flush=True)
    comm.Abort(1)
    return 1


def _status_of_rank0(status):
    """Rank 0's exit status, on every rank (cpp/main.cpp). A rank that did
    not work (domain/working_ranks.py) waits for it here, asleep."""
    if "mpi4py.MPI" not in sys.modules:  # help: MPI never started
        return status
    from mpi4py import MPI
    from .domain.working_ranks import wait_quietly
    shared = array.array("i", [status])
    wait_quietly(MPI.COMM_WORLD.Ibcast(shared, root=0))
    return shared[0]


if __name__ == "__main__":
    status = _status_of_rank0(main(sys.argv[1:]))
    if status == RUN_OUTPUT_FAILED:
        # The HDF5 file stays as its last flush left it: the interpreter's
        # teardown would close it, writing metadata the full disk cannot hold
        # (h5py then crashes). Everything finished is flushed already.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)
