"""The readers of how a scene is run (cpp/scene/run_input.h): [time] (the
steps), [output] (what is written, when), [solver] (how each system is
solved) and [reference] (the closed form a run is compared with). Mirrors
cpp/scene/run_input.cpp key by key."""
import bisect

from .input import MeshType, ReferenceSolution, SolverChoice, TimeScheme
from .physics_input import positive
from .schema import MAX_STEPS, AdaptiveSpec, ReferenceSpec, default_cells_per_rank


def _read_adaptive(time, scene):
    """time.adaptive: the tolerance and the bounds of the step (the first step
    is time.dt)."""
    if not time.has("adaptive"):
        return None
    a = time.section("adaptive", False)
    s = AdaptiveSpec()
    s.tolerance = a.number("tolerance")
    if not 0 < s.tolerance < 1:
        a.fail("tolerance", "must lie in (0, 1)")
    s.dt_min = a.number("dt_min", min(scene.dt, max(scene.dt / 1000, scene.end_time / MAX_STEPS)))
    s.dt_max = a.number("dt_max", scene.end_time)
    if not 0 < s.dt_min <= scene.dt:
        a.fail("dt_min", "must lie in (0, time.dt] (default time.dt / 1000)")
    if not s.dt_max >= scene.dt:
        a.fail("dt_max", "must be >= time.dt (default time.end)")
    if scene.end_time / s.dt_min > MAX_STEPS:
        a.fail("dt_min", f"time.end / dt_min is more than the limit of {MAX_STEPS} steps")
    a.finish()
    if scene.growth > 1.0:
        time.fail("adaptive", "adaptive steps and time.growth exclude each other")
    if scene.coupling and (scene.coupling.q != 1 or scene.coupling.q_auto):
        q = '"auto"' if scene.coupling.q_auto else scene.coupling.q
        time.fail("adaptive", f"adaptive steps need q = 1 (coupling.q is {q})")
    return s


def _check_step_count(time, scene):
    """Fixed steps: time.end must be a whole number of at most MAX_STEPS
    steps dt."""
    steps = scene.end_time / scene.dt
    if steps > MAX_STEPS:
        time.fail("dt", f"time.end / time.dt = {steps:.3g} steps, more than the limit of {MAX_STEPS}")
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        time.fail("dt", "time.end must be a whole number of steps dt")


def read_time(top, scene):
    """[time]: the end, the first step, its growth or adaptation, the retries
    and the scheme; fixed steps must be whole, at most MAX_STEPS and, with
    q > 1, whole windows."""
    time = top.section("time", True)
    scene.end_time = time.number("end")
    scene.dt = time.number("dt")
    positive(time, "dt", scene.dt)
    positive(time, "end", scene.end_time)
    scene.growth = time.number("growth", 1.0)
    scene.retry = time.integer("retry", 0)
    if not 0 <= scene.retry <= 20:
        time.fail("retry", "must lie in [0, 20] (each retry halves the step)")
    if not (1.0 <= scene.growth <= 10.0):
        time.fail("growth", "must lie in [1, 10]")
    scene.time_scheme = time.choice("scheme", TimeScheme, TimeScheme.backward_euler)
    scene.adaptive = _read_adaptive(time, scene)
    if scene.adaptive:
        time.finish()
        return
    if scene.growth == 1.0:
        _check_step_count(time, scene)
    if scene.growth > 1.0 and scene.coupling and (scene.coupling.q != 1 or scene.coupling.q_auto):
        time.fail("growth", "growing time steps need q = 1")
    if scene.num_steps() > MAX_STEPS:
        time.fail("growth", f"more than {MAX_STEPS} time steps")
    time.finish()
    if scene.coupling and scene.num_steps() % scene.coupling.q != 0:
        top.fail("coupling.q", "the number of fine steps (time.end/time.dt) must be a multiple of q")


def _read_output_times(output, scene):
    """output.times or output.every: the times written, increasing, in
    (0, time.end], time.end added; with fixed or growing steps each must be
    the end of a step (of a window for q > 1)."""
    if output.has("times") and output.has("every"):
        output.fail("every", "give output.times or output.every, not both")
    end = scene.end_time
    slack = 1e-9 * end
    if output.has("times"):
        t = output.number_vector("times", 0)
        for i, ti in enumerate(t):
            if not (ti > 0 and ti <= end + slack and (i == 0 or ti > t[i - 1] + slack)):
                output.fail("times", "must increase strictly within (0, time.end]")
    elif output.has("every"):
        every = output.number("every")
        if not 0 < every <= end:
            output.fail("every", "must lie in (0, time.end]")
        t, k = [], 1
        while k * every <= end + slack:
            t.append(k * every)
            k += 1
    else:
        return []
    if not t or t[-1] < end - slack:
        t.append(end)
    t[-1] = end
    if scene.adaptive:
        return t
    run, q = scene.times(), scene.coupling.q if scene.coupling else 1
    for s in t:
        k = bisect.bisect_left(run, s - slack)
        if k == len(run) or abs(run[k] - s) > slack or k % q != 0:
            what = "window" if q > 1 else "step"
            output.fail("times" if output.has("times") else "every",
                        f"{s:.6g} is not the end of a {what} of the run (time.dt = {scene.dt:g}"
                        f"{f', q = {q}' if q > 1 else ''}); time.adaptive lands on any time")
    return t


def read_output(output, scene):
    """[output]: XDMF on or off, the times written, the checkpoint interval
    (in steps) and the progress interval (seconds)."""
    scene.write_xdmf = output.boolean("xdmf", True)
    scene.output_times = _read_output_times(output, scene)
    scene.checkpoint_every = output.integer("checkpoint_every", 0)
    if scene.checkpoint_every < 0:
        output.fail("checkpoint_every", "must be >= 0 (0: no checkpoints)")
    scene.progress_interval = output.number("progress_interval", 10.0)
    positive(output, "progress_interval", scene.progress_interval)
    output.finish()


def read_solver(solver, dimension, choices):
    """[solver]: direct, iterative or auto for each system, inexact
    coupling, and the fewest cells a rank works on (by default that of the
    mesh's `dimension`)."""
    for key in ("flow", "mechanics", "monolithic"):
        setattr(choices, key, solver.choice(key, SolverChoice, SolverChoice.automatic))
    choices.inexact_coupling = solver.boolean("inexact_coupling", True)
    choices.cells_per_rank = solver.integer("cells_per_rank", default_cells_per_rank(dimension))
    if choices.cells_per_rank < 0:
        solver.fail("cells_per_rank", "must be >= 0 (0: every rank works)")
    solver.finish()


def _check_mandel_plate(r, scene, ref):
    """Mandel's rigid frictionless plate goes on the boundary ref.plate,
    which must be free: set-up imposes the exact u_y there
    (diagnostics/closed_form.py, with_mandel_plate)."""
    if scene.mesh.lower[0] != 0.0 or scene.mesh.lower[1] != 0.0:
        r.fail("solution", "mandel needs mesh.lower = [0, 0] (the quarter specimen)")
    plate = scene.boundaries.get(ref.plate)
    if plate is None or plate.mechanics != "traction_free":
        r.fail("plate", "must name a boundary with no mechanics condition of its own")


def read_reference(r, scene):
    """[reference]: the closed form the run is compared with ("none" switches
    the comparison of a reference scene off, e.g. from --set)."""
    solution = r.string("solution")
    if solution not in ("terzaghi", "mandel", "none"):
        r.fail("solution", 'must be "terzaghi", "mandel" or "none"')
    if solution == "none":
        r.used.update(r.keys())
        r.finish()
        return
    ref = ReferenceSpec(solution=ReferenceSolution(solution))
    if not scene.coupling or scene.mesh.type != MeshType.rectangle:
        r.fail("solution", solution + " needs a coupled scene on a rectangle")
    if scene.flow.permeability is None or not scene.flow.permeability.is_constant:
        r.fail("solution", solution + " needs a constant scalar flow.permeability")
    if scene.regions:
        r.fail("solution", solution + " is the closed form of a homogeneous medium: the scene has regions")
    if ref.solution == ReferenceSolution.terzaghi:
        ref.load = r.number("load")
        ref.height = scene.mesh.upper[1] - scene.mesh.lower[1]
    else:
        ref.force = r.number("force")
        ref.plate = r.string("plate", "top")
        _check_mandel_plate(r, scene, ref)
    r.finish()
    scene.reference = ref
