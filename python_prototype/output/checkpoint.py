"""Checkpoint and restart (cpp/output/checkpoint.h): the state a run needs to
continue after its last completed step, written every N steps
(output.checkpoint_every) and when the run is interrupted; `run SCENE
--restart DIR` goes on in the same files and ends as the uninterrupted run.

The state does not depend on the partition: every unknown is stored under a
name taken from the mesh's input numbering (keyed_values.py), so a run may
be restarted on any partition and any number of ranks. A restart needs the same
scene (its fingerprint: restart_fingerprint) and a mesh
that holds every stored name; otherwise it is refused in one line. The files
and how one replaces the last: write_checkpoint."""
import glob
import io
import os
from dataclasses import dataclass

import numpy as np

from ..assembly.linear_algebra import UnknownsPart
from ..coupling.coupling import for_each_checkpointed
from ..scene.input import CouplingScheme, Fallback
from ..scene.scene import SceneError, agree_on_error
from ..solvers.solver_statistics import SolverStatistics, solver_counts
from .keyed_values import keyed_values, mesh_difference, mesh_signature, restore_values
from .write_failure import agree_on_output_error, write_failure_reason

FORMAT = "biotcontact checkpoint 2 (prototype)"


class Checkpoint:
    def __init__(self, steps=0, time=0.0, arrays=None, numbers=None, output=""):
        self.steps, self.time = steps, time
        self.arrays = arrays or {}    # the same on every rank (the time grid, the mesh signature)
        self.fields = {}              # name -> (keys, values): this rank's owned entries, or every rank's once read
        self.numbers = numbers or {}  # counters and scales
        self.output = output          # Output.position()


@dataclass
class RunState:
    """The parts of a run a checkpoint keeps and a restart restores: the
    scheme's unknowns, time-scheme memory and solver counts, the report,
    the controllers' state and the time grid (as retries left it)."""
    scheme: object  # coupling/scheme.py
    mesh: object
    report: object  # CouplingReport
    state: object   # ControllerState
    grid: object    # TimeGrid


def _state_path(directory):
    return os.path.join(directory, "checkpoint", "state.npz")


def _values_path(directory, steps, rank):
    return os.path.join(directory, "checkpoint", f"values.{steps}.{rank}.npz")


def _write_file(path, contents):
    """Writes an npz through `path`.new and renames it into place; returns
    why it could not (the new file removed), or an empty string."""
    buffer = io.BytesIO()  # in memory first: numpy's zip writer does not fail cleanly on a full disk
    np.savez(buffer, **contents)
    try:
        with open(path + ".new", "wb") as f:
            f.write(buffer.getbuffer())
        os.replace(path + ".new", path)
        return ""
    except OSError as e:
        if os.path.exists(path + ".new"):
            os.remove(path + ".new")
        return f"cannot write {path}: {write_failure_reason(os.path.dirname(path), e)}"


def _write_state(directory, fingerprint, ranks, c):
    """Everything but the values (rank 0); once it is in place, the values of
    earlier checkpoints (of any number of ranks) go."""
    failure = _write_file(_state_path(directory), dict(
        format=FORMAT, fingerprint=fingerprint, ranks=ranks, steps=c.steps, time=c.time, output=c.output,
        number_names=list(c.numbers), number_values=np.array(list(c.numbers.values()), dtype=float),
        **{"array_" + name: values for name, values in c.arrays.items()}))
    if not failure:
        current = f"values.{c.steps}."
        for path in glob.glob(os.path.join(directory, "checkpoint", "values.*")):
            if not os.path.basename(path).startswith(current):
                os.remove(path)
    return failure


def write_checkpoint(comm, directory, fingerprint, c):
    """Writes the checkpoint (collective); raises OutputError on every rank
    when a file could not be written, leaving the previous checkpoint.
    Layout of DIR/checkpoint (the C++ solver writes .bin files of its own
    format): state.npz (rank 0: the step, the time, the counters, the time
    grid, the output position, the number of value files) and
    values.<step>.<rank>.npz (each rank's owned unknowns with their names).
    A checkpoint replaces the previous one when its state.npz is renamed
    into place, after every value file is complete; the value files of other
    steps go after that."""
    if comm.rank == 0:
        os.makedirs(os.path.join(directory, "checkpoint"), exist_ok=True)
    comm.Barrier()
    contents = {"format": FORMAT, "steps": c.steps, "names": list(c.fields)}
    for i, (keys, values) in enumerate(c.fields.values()):
        contents[f"keys_{i}"], contents[f"values_{i}"] = keys, values
    # Every rank's values are complete before the state points at them.
    agree_on_output_error(_write_file(_values_path(directory, c.steps, comm.rank), contents), comm)
    agree_on_output_error(_write_state(directory, fingerprint, comm.size, c) if comm.rank == 0 else "", comm)


# The --set keys a restart may change (docs/user-guide.md, "Restart"): the
# split's iteration, its acceleration, the retries of a failed step, the
# single-rate scheme and its fallback, and the linear solvers, so that a run
# the split could not carry through a step goes on monolithic from its
# checkpoint, by the solver that carries it.
RESTART_KEYS = ("coupling.scheme", "coupling.acceleration", "coupling.depth", "coupling.max_iterations",
                "coupling.fallback", "time.retry", "solver.flow", "solver.mechanics", "solver.monolithic")


def restart_fingerprint(text, overrides, scene):
    """The fingerprint a checkpoint is written and read with: the scene
    file's `text` and its --set `overrides`, but those of RESTART_KEYS (how
    the coupling is solved, not what), and the scheme's time stepping:
    "fixed-stress" and "monolithic" take the same steps and may replace
    each other, a multirate scheme is another scene."""
    fingerprint = text + "".join(f"\n--set {o}" for o in overrides
                                 if "".join(o.split("=", 1)[0].split()) not in RESTART_KEYS)
    if scene.coupling and scene.coupling.scheme not in (CouplingScheme.fixed_stress, CouplingScheme.monolithic):
        fingerprint += f"\ncoupling.scheme = {scene.coupling.scheme.value}"
    return fingerprint


def restart_proposal(failure, scene):
    """The --set of the restart that takes what `failure` proposes, where it
    proposes the monolithic scheme: coupling.scheme between the single-rate
    split and it (restart_fingerprint), a multirate run's coupling.fallback
    (none where it had it); otherwise empty."""
    if 'coupling.scheme = "monolithic"' not in failure:
        return ""
    if scene.coupling is None or not scene.coupling.multirate():
        return " --set coupling.scheme=monolithic"
    return "" if scene.coupling.fallback == Fallback.monolithic else " --set coupling.fallback=monolithic"


def _changeable():
    """The keys a restart may change, for its refusal."""
    return (f" (a restart may change with --set {RESTART_KEYS[0]} between \"fixed-stress\" and \"monolithic\", "
            + ", ".join(RESTART_KEYS[1:]) + ")")


def _read_state(directory, fingerprint):
    path = _state_path(directory)
    if not os.path.exists(path):
        raise SceneError(f"--restart {directory}: no checkpoint there ({path}; runs write one with "
                         "output.checkpoint_every)")
    with np.load(path) as data:
        if str(data["format"]) != FORMAT:
            raise SceneError(f"--restart {directory}: {path} is no checkpoint of this version of the prototype")
        if str(data["fingerprint"]) != fingerprint:
            raise SceneError(f"--restart {directory}: the checkpoint was written for another scene or other "
                             "--set values" + _changeable())
        c = Checkpoint(int(data["steps"]), float(data["time"]), output=str(data["output"]))
        c.numbers = dict(zip((str(n) for n in data["number_names"]), (float(v) for v in data["number_values"])))
        c.arrays = {k[len("array_"):]: data[k] for k in data.files if k.startswith("array_")}
        return c, int(data["ranks"])


def _read_values(path, c, parts):
    """Every rank's values of one file, appended to parts[name]."""
    with np.load(path) as data:
        if str(data["format"]) != FORMAT or int(data["steps"]) != c.steps:
            raise ValueError(path)
        for i, name in enumerate(str(n) for n in data["names"]):
            parts.setdefault(name, []).append((data[f"keys_{i}"], data[f"values_{i}"]))


def read_checkpoint(comm, directory, fingerprint):
    """The checkpoint with every rank's values (collective); SceneError
    when there is none, or it belongs to another scene, or is damaged."""
    error, c, path = "", Checkpoint(), _state_path(directory)
    try:
        c, ranks = _read_state(directory, fingerprint)
        parts = {}
        for rank in range(ranks):
            path = _values_path(directory, c.steps, rank)
            _read_values(path, c, parts)
        c.fields = {name: (np.concatenate([k for k, _ in p]), np.concatenate([v for _, v in p]))
                    for name, p in parts.items()}
    except SceneError as e:
        error = str(e)
    except (OSError, KeyError, ValueError):
        error = f"--restart {directory}: the checkpoint {path} is damaged or missing"
    agree_on_error(error, comm)
    return c


def capture_checkpoint(run, steps, time, output):
    """The checkpoint of the RunState `run` after `steps` completed steps
    ending at `time`, with the output's position (collective)."""
    c = Checkpoint(steps, time, output=output)
    # The grid as retries left it (the same on every rank).
    c.arrays["times"], c.arrays["time_steps"] = np.array(run.grid.t), np.array(run.grid.dt)
    c.arrays["mesh"] = mesh_signature(run.mesh)
    for step in run.scheme.steps():
        for part in step.parts():
            c.fields[part.name] = keyed_values(run.mesh, part, step.unknowns())
    for name, f in run.scheme.history():
        c.fields[name] = keyed_values(run.mesh, UnknownsPart(name, f.function_space), f.x.array)
    for step in run.scheme.steps():  # copies: the run's last completed step is kept in memory (simulation.py)
        c.arrays.update({name: np.array(a) for name, a in step.arrays().items()})
    for_each_checkpointed(run.report, run.state,
                          lambda holder, name: c.numbers.__setitem__(name, float(getattr(holder, name))))
    for step in run.scheme.steps():
        st = step.system.statistics()
        c.numbers.update({f"{step.name()}.{name}": float(getattr(st, name)) for name in solver_counts})
    return c


def _stored_history_name(c, name, path):
    """The checkpoint's field for history field `name` of a scheme whose
    history has `path` (displacement_path_before: the split with BDF2).
    The displacement one fine step before t_K is the split's
    displacement_path_before and the monolithic scheme's
    displacement_before (each of its steps a window of one fine step), so
    each reads the other's where it goes on from the other's state (a
    restart with another coupling.scheme, coupling.fallback); the split's
    displacement_before is one window before t_K."""
    by_path = "displacement_path_before"
    if name == by_path and by_path not in c.fields:
        return "displacement_before"
    if name == "displacement_before" and not path and by_path in c.fields:
        return by_path
    return name


def _restore_unknowns(c, run, comm, directory):
    """Loads the stored unknowns into the steps; refuses a checkpoint of
    another mesh, or one that lacks any of them (collective)."""
    difference = mesh_difference(c.arrays.get("mesh"), mesh_signature(run.mesh))
    if difference:
        raise SceneError(f"--restart {directory}: the checkpoint does not match this mesh ({difference})")

    def restore(parts, unknowns):
        for part in parts:
            stored = c.fields.get(part.name)
            missing = comm.allreduce(1 if stored is None else restore_values(run.mesh, part, stored, unknowns))
            if missing > 0:
                raise SceneError(f"--restart {directory}: the checkpoint does not match this mesh ({missing} "
                                 f"values of the {part.name} not in it)")
    for step in run.scheme.steps():
        parts = step.parts()
        if parts:
            x = step.unknowns().copy()
            restore(parts, x)
            step.set_unknowns(x)
    history = run.scheme.history()
    path = any(name == "displacement_path_before" for name, _ in history)
    for name, f in history:
        restore([UnknownsPart(_stored_history_name(c, name, path), f.function_space)], f.x.array)
    for step in run.scheme.steps():
        for name in step.arrays():
            if name not in c.arrays:
                raise SceneError(f"--restart {directory}: the checkpoint has no {name}")
        step.restore_arrays(c.arrays)


def _stored_count(c, system, count):
    """The stored count `count` of system `system`: by name, or by the
    system's position in the layout before names (flow, mechanics,
    monolithic, second pass)."""
    by_name = c.numbers.get(f"{system}.{count}")
    if by_name is not None:
        return by_name
    positions = ("flow", "mechanics", "monolithic", "flow_second_pass")
    # A count newer than the checkpoint (schur_factorizations) is 0.
    return c.numbers.get(f"{positions.index(system)}.{count}", 0.0)


def restore_run_state(c, run, comm, directory):
    """What restore_checkpoint loads but the solver counts: the unknowns,
    the time grid, the report and the controllers' state; for a scheme that
    goes on from another's state in the same run (coupling.fallback), whose
    systems keep counting their own solves."""
    run.grid.t, run.grid.dt = list(c.arrays["times"]), list(c.arrays["time_steps"])
    _restore_unknowns(c, run, comm, directory)
    # A number newer than the checkpoint (fallback_steps) keeps its value
    # at the run's start.
    for_each_checkpointed(run.report, run.state, lambda holder, name: setattr(
        holder, name, type(getattr(holder, name))(c.numbers.get(name, getattr(holder, name)))))


def restore_checkpoint(c, run, comm, directory):
    """Loads the checkpoint `c` into the RunState `run`, whatever the
    partition; refuses one of another mesh, or one that lacks any of the
    unknowns, naming `directory` (collective). Solver counts stored by
    system name, or by the position of the layout before names, are both
    read."""
    restore_run_state(c, run, comm, directory)
    for step in run.scheme.steps():
        earlier = SolverStatistics()
        for name in solver_counts:
            setattr(earlier, name, int(_stored_count(c, step.name(), name)))
        step.system.add_earlier(earlier)
