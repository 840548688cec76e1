"""A run of one scene (cpp/simulation.cpp): scene -> mesh and tags -> forms ->
flow step / mechanics step (or the monolithic step) -> coupling scheme ->
output and diagnostics."""
from dataclasses import replace
import sys
import time

import numpy as np
from dolfinx import fem

from .output.checkpoint import Checkpoint, read_checkpoint, write_checkpoint
from .diagnostics.closed_form import Mandel, Terzaghi
from .domain.domain import check_expressions, create_domain
from .coupling.fixed_stress import CouplingError, CouplingReport, run_fixed_stress
from .assembly.forms import Forms
from .assembly.parameters import derive_parameters, set_constants, set_time_step
from .output.output import Output
from .contact.contact import ContactState
from .output.interruption import interruption_signal
from .steps.time_grid import retry_step, time_grid
from .solvers.solver import Method, SolverError, SolverStatistics
from .diagnostics.diagnostics import ContractionNorm, relative_error, volumetric_stress
from .steps.flow_step import FlowStep
from .steps.mechanics_step import MechanicsStep
from .steps.monolithic_step import MonolithicStep

RUN_OK, RUN_NOT_CONVERGED = 0, 3


def _global_size(V):
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def _boundary_mean(u, facets, component, comm):
    """Mean of one displacement component over the nodes of a boundary."""
    V = u.function_space
    dofs = fem.locate_dofs_topological(V.sub(component), V.mesh.topology.dim - 1, facets)
    dofs = dofs[dofs < V.dofmap.index_map.size_local * V.dofmap.index_map_bs]
    total, count = comm.allreduce(np.array([u.x.array[dofs].sum(), len(dofs)]))
    return total / count


def _solvers_json(systems, stats, inexact_coupling):
    result = {}
    for name, system in systems.items():
        if system is None:
            continue
        st = stats[name]
        direct = system.method == Method.direct
        j = {"solver": system.method.name, "method": system.description(), "unknowns": system.unknowns(),
             "solves": st.solves, "factorizations": st.setups if direct else 0,
             "preconditioner_setups": st.setups,
             "inexact_coupling": not direct and name != "monolithic" and inexact_coupling,
             "back_solves": st.back_solves, "linear_iterations": st.linear_iterations}
        if system.has_contact():
            j.update(newton_iterations=st.newton_iterations, active_set_changes=st.active_set_changes,
                     schur_columns=st.schur_columns)
        result[name] = j
    return result


def _timings_json(systems, stats):
    return {name: {"total": stats[name].total_time, "setup": stats[name].setup_time,
                   "solve": stats[name].solve_time, "schur_complement": stats[name].schur_time,
                   "other": stats[name].total_time - stats[name].setup_time - stats[name].solve_time
                   - stats[name].schur_time,
                   "matrix_assembly": stats[name].assembly_time}
            for name, system in systems.items() if system is not None}


def _contact_json(c):
    return {"contact_nodes": c.contact_nodes, "active_nodes": c.active_nodes,
            "max_penetration": c.max_penetration, "max_complementarity": c.max_complementarity,
            "max_contact_pressure": c.max_pressure, "min_contact_pressure": c.min_pressure,
            "gap_scale": c.gap_scale, "total_force": c.total_force}


def closed_form_errors(scene, P, F, domain, u, p, comm):
    """The relative L2 errors (and Terzaghi's settlement) at the final time
    against the scene's closed form, Terzaghi or Mandel (cpp/simulation.cpp)."""
    ref, fs = scene.reference, scene.flow
    mobility = fs.permeability(0, 0, 0, 0) / fs.mu_f
    t, y0 = scene.end_time, scene.mesh.lower[1]
    terzaghi = None
    if ref.solution == "terzaghi":
        terzaghi = Terzaghi(ref.height, P.G, P.lmbda, P.alpha, P.storage, mobility, ref.load)
        p_exact = lambda x: terzaghi.pressure(x[1] - y0, t)  # noqa: E731
        u_exact = lambda x: [0.0 * x[0], terzaghi.displacement(x[1] - y0, t)]  # noqa: E731
    else:
        mandel = Mandel(scene.mesh.upper[0], scene.mesh.upper[1], P.G, P.lmbda, P.alpha, P.storage,
                        mobility, ref.force)
        p_exact = lambda x: mandel.pressure(x[0], t)  # noqa: E731
        u_exact = lambda x: [mandel.displacement_x(x[0], t), mandel.displacement_y(x[1], t)]  # noqa: E731
    F["p_reference"].interpolate(p_exact)
    F["u_reference"].interpolate(lambda x: np.vstack(u_exact(x)))
    F["p_out"].x.array[:] = p.x.array
    F["u_out"].x.array[:] = u.x.array
    errors = {
        "time": t,
        "pressure_rel_l2": relative_error(F, F.compile("M_pressure_error"),
                                          F.compile("M_pressure_reference"), comm),
        "displacement_rel_l2": relative_error(F, F.compile("M_displacement_error"),
                                              F.compile("M_displacement_reference"), comm)}
    if terzaghi:
        settlement = -_boundary_mean(u, domain.boundaries["top"], 1, comm)
        exact = terzaghi.settlement(t)
        errors.update({"settlement": settlement, "settlement_exact": exact,
                       "settlement_rel": abs(settlement - exact) / abs(exact)})
    return errors


REPORT_NUMBERS = ("windows", "coupling_iterations", "max_iterations_per_step", "max_contraction_ratio", "ratios",
                  "bound_violations", "unresolved_ratios", "max_coupled_residual", "ratio_sum", "p_size", "u_size",
                  "retries")
COUNTS = ("solves", "setups", "back_solves", "linear_iterations", "newton_iterations", "active_set_changes",
          "schur_columns")


def step_state(flow, mechanics, coupled):
    """The unknowns at the start of a step, to go back to when it is retried."""
    return (flow.state().copy() if flow else None, mechanics.u.x.array.copy() if mechanics else None,
            coupled.state().copy() if coupled else None)


def set_step_state(state, flow, mechanics, coupled):
    flow_state, displacement, monolithic = state
    if flow:
        flow.set_state(flow_state)
    if mechanics:
        mechanics.u.x.array[:] = displacement
    if coupled:
        coupled.set_state(monolithic)


def equilibrate(scene, domain, F, mechanics, coupled):
    """mechanics.initial_equilibrium (cpp/simulation.cpp): replaces u = 0 by
    the displacement in equilibrium with the loads at t = 0 and the initial
    pressure (a geostatic initialisation), so that loads present from the
    start are not applied in the first step as a sudden, undrained load."""
    if mechanics:
        mechanics.solve(0.0)
        return
    # the coupled system has no mechanics system of its own: one mechanics
    # step on its displacement space, loaded by its pressure, solved once
    step = MechanicsStep(scene, domain, F, coupled.pressure)
    step.solve(0.0)
    coupled.set_displacement(step.u.x.array, 0.0)


def capture_state(steps, t, flow, mechanics, coupled, report, systems, output_state, grid):
    """The state a restart needs after `steps` completed steps (checkpoint.py)."""
    c = Checkpoint(steps, t, output=output_state)
    # The grid as retries left it (the same on every rank).
    c.arrays["times"], c.arrays["time_steps"] = np.array(grid.t), np.array(grid.dt)
    if flow:
        c.arrays["flow"] = flow.state().copy()
    if mechanics:
        c.arrays["displacement"] = mechanics.u.x.array.copy()
    if coupled:
        c.arrays["monolithic"] = coupled.state().copy()
    c.numbers = {name: float(getattr(report, name)) for name in REPORT_NUMBERS}
    for i, system in enumerate(systems):
        if system is not None:
            s = system.statistics()
            c.numbers.update({f"{i}.{name}": float(getattr(s, name)) for name in COUNTS})
    return c


def restore_state(c, flow, mechanics, coupled, report, systems, grid):
    """Loads a checkpoint into the steps, the report, the time grid and the
    solver counts."""
    grid.t, grid.dt = list(c.arrays["times"]), list(c.arrays["time_steps"])
    if flow:
        flow.set_state(c.arrays["flow"])
    if mechanics:
        mechanics.u.x.array[:] = c.arrays["displacement"]
    if coupled:
        coupled.set_state(c.arrays["monolithic"])
    for name in REPORT_NUMBERS:
        value = c.numbers[name]
        setattr(report, name, int(value) if isinstance(getattr(report, name), int) else value)
    for i, system in enumerate(systems):
        if system is not None:
            for name in COUNTS:
                setattr(system.earlier, name, int(c.numbers[f"{i}.{name}"]))


def run(scene, directory, comm, fingerprint="", restart=False):
    """Runs `scene` into `directory`; returns RUN_OK, or RUN_NOT_CONVERGED
    after writing what was finished and the iteration log."""
    start = time.perf_counter()

    def say(s):
        if comm.rank == 0:
            print(s, flush=True)

    # ---- scene -> mesh and tags -> forms ----------------------------------------
    domain = create_domain(scene, comm)
    check_expressions(scene, domain, comm)
    F = Forms(domain.mesh)
    P = derive_parameters(scene)
    set_constants(F, scene, P)
    d = domain.dim

    # Each scene allocates only the physics it has.
    left_out = []
    if not scene.flow:
        left_out.append("flow (no [flow] table): no flux or pressure unknowns")
    if not scene.mechanics:
        left_out.append("mechanics (no [mechanics] table): no displacement unknowns")
    if scene.mechanics and not scene.has_contact():
        left_out.append("contact solver (no contact boundary): linear mechanics solve")
    if scene.flow and not scene.flow.gravity:
        left_out.append("gravity")
    if scene.mechanics and not scene.mechanics.body_force:
        left_out.append("body force")
    left_out = "; ".join(left_out)
    say(f"biotcontact (python prototype): scene {scene.name} ({scene.file}), {d}D, "
        f"{domain.mesh.topology.index_map(d).size_global} cells")
    say("left out: " + (left_out or "nothing"))

    # Where the method is known to degrade, the run says so instead of
    # returning poor numbers silently (docs/stability.md has the data).
    warnings = []

    def warn(what):
        warnings.append(what)
        say("warning: " + what)
    if scene.mechanics:
        nu = P.lmbda / (2 * (P.lmbda + P.G))
        if nu > 0.49:
            warn(f"nu = {nu:f} > 0.49: P1 displacements lock as nu -> 0.5 "
                 "(too stiff a response, worse on coarse meshes)")
    if scene.coupling and scene.coupling.scheme != "monolithic" and P.gamma > 0.99:
        warn(f"gamma = {P.gamma:f} > 0.99: the contraction theorems guarantee almost nothing, expect many "
             "coupling iterations or none converging (monolithic is the robust choice)")

    # ---- flow step / mechanics step, or the monolithic system ------------------
    monolithic = scene.coupling is not None and scene.coupling.scheme == "monolithic"
    flow = mechanics = coupled = second_pass = None
    u = p = contact_pressure = contact_active = contact_boundary = None
    compute_contact = ContactState
    if monolithic:
        coupled = MonolithicStep(scene, domain, F)
        u, p, compute_flux = coupled.u, coupled.pressure, coupled.flux
        if coupled.system.has_contact():
            contact_pressure, contact_active = coupled.contact_pressure, coupled.contact_active
            contact_boundary = coupled.contact_boundary
            compute_contact = coupled.contact_state
    else:
        if scene.flow:
            flow = FlowStep(scene, domain, F, coupled=scene.coupling is not None)
            p, compute_flux = flow.pressure, flow.flux
            if scene.coupling and scene.coupling.scheme == "multirate-two-pass":
                # The second pass is the flow step without the stabilisation L:
                # forms of its own, whose constant L is 0.
                F_second = Forms(domain.mesh)
                set_constants(F_second, scene, replace(P, L=0.0))
                second_pass = FlowStep(scene, domain, F_second, coupled=True)
        if scene.mechanics:
            mechanics = MechanicsStep(scene, domain, F, p if scene.coupling is not None else None)
            u = mechanics.u
            if mechanics.system.has_contact():
                contact_pressure, contact_active = mechanics.contact_pressure, mechanics.contact_active
                contact_boundary = mechanics.contact_boundary
                compute_contact = mechanics.contact_state

    # ---- output fields ---------------------------------------------------------------
    resumed = read_checkpoint(comm, directory, fingerprint) if restart else None
    output = Output(comm, directory, domain.mesh, scene.write_xdmf, resumed.output if resumed else None)
    try:
        flux = sigma_v = L_sigma_v = None
        if p is not None:
            p.name = "pressure"
            flux = fem.Function(F["Qv"], name="flux")
        if u is not None:
            u.name = "displacement"
            sigma_v = fem.Function(F["Q"], name="sigma_v")
            L_sigma_v = F.compile("L_sigma_v")
            if contact_pressure is not None:
                contact_pressure.name, contact_active.name = "contact_pressure", "contact_active"

        def write_flow(t):
            output.write(p, t)
            compute_flux(flux)
            output.write(flux, t)

        contact = ContactState()

        def write_mechanics(t):
            nonlocal contact
            contact = compute_contact()  # also fills the contact fields
            volumetric_stress(F, L_sigma_v, u, p, sigma_v)
            output.write(u, t)
            output.write(sigma_v, t)
            if contact_pressure is not None:
                output.write(contact_pressure, t)
                output.write(contact_active, t)

        completed = [0, 0.0]  # mechanics steps (windows) written, and their last time

        grid = time_grid(scene)  # the time steps; a retry (time.retry) halves some of them

        def progress(step, t, iterations):
            completed[:] = [step, t]
            say(f"step {step:4d}/{grid.steps() // P.q}  t = {t:<11.5g}  coupling iterations "
                f"{iterations:3d}  active contact nodes {contact.active_nodes}")

        # ---- initial state, or the state of the checkpoint ----------------------------
        report = CouplingReport()
        systems = [flow.system if flow else None, mechanics.system if mechanics else None,
                   coupled.system if coupled else None, second_pass.system if second_pass else None]
        if resumed:
            restore_state(resumed, flow, mechanics, coupled, report, systems, grid)
            completed[:] = [resumed.steps, resumed.time]
            if u is not None:
                contact = compute_contact()
            say(f"restarted from the checkpoint at step {completed[0]}, t = {completed[1]:f}")
        else:
            if scene.mechanics and scene.mechanics.initial_equilibrium:
                equilibrate(scene, domain, F, mechanics, coupled)
            if p is not None:
                write_flow(0.0)
            if u is not None:
                write_mechanics(0.0)
            if contact_boundary is not None:
                output.write(contact_boundary, 0.0)  # once: every later time repeats it

        # ---- time stepping -----------------------------------------------------------
        failure, interrupted = "", 0
        saved = [completed[0] if resumed else 0]

        def save():
            write_checkpoint(comm, directory, fingerprint,
                             capture_state(completed[0], completed[1], flow, mechanics, coupled, report, systems,
                                           output.state(), grid))
            saved[0] = completed[0]

        def stop():
            """After each completed (and written) step: a checkpoint every
            checkpoint_every steps and at an interruption; then whether to stop."""
            nonlocal interrupted
            if scene.checkpoint_every > 0 and completed[0] % scene.checkpoint_every == 0:
                save()
            interrupted = interruption_signal(comm)
            if interrupted and scene.checkpoint_every > 0 and saved[0] != completed[0]:
                save()
            return interrupted != 0

        try:
            if scene.coupling and not monolithic:
                contraction = ContractionNorm(F, comm)

                def on_mechanics_state(t, window, iterations):
                    write_mechanics(t)
                    progress(window, t, iterations)
                run_fixed_stress(scene, P, F, flow, second_pass, mechanics, contraction, output, write_flow,
                                 on_mechanics_state, report, comm, grid, stop, say)
            else:
                # One solve per step: the monolithic system, or the single physics.
                attempts = [0]  # retries of the current step (time.retry)
                k = report.windows + 1
                while k <= grid.steps():
                    t = grid.t[k]
                    if set_time_step(F, grid.dt[k - 1]):
                        for solver in (coupled, flow):
                            if solver:
                                solver.time_step_changed()
                    at_step_start = step_state(flow, mechanics, coupled)
                    try:
                        if coupled:
                            coupled.solve(t)
                        if flow:
                            flow.p_previous.x.array[:] = p.x.array
                            flow.solve(t)
                        if mechanics:
                            mechanics.solve(t)
                    except SolverError as e:
                        # time.retry: back to the start of the step, halved.
                        message = retry_step(scene, str(e), k, attempts, grid, k - 1, 1, report)
                        if message is None:
                            raise
                        say(message)
                        set_step_state(at_step_start, flow, mechanics, coupled)
                        continue
                    attempts[0] = 0
                    if p is not None:
                        write_flow(t)
                    if u is not None:
                        write_mechanics(t)
                    progress(k, t, 1)
                    report.windows = k
                    k += 1
                    if stop():
                        break
        except CouplingError as e:
            failure = str(e)  # names its step and the last increments
        except SolverError as e:
            # A solve that fails names the step it was computing.
            step = completed[0] + 1
            failure = f"step {step} (t = {grid.t[min(step * P.q, len(grid.t) - 1)]:g}): {e}"
            report.windows = completed[0]
        contact = compute_contact()

        # ---- errors against a closed form at the final time --------------------------
        errors = None
        if scene.reference and not failure and not interrupted:
            errors = closed_form_errors(scene, P, F, domain, u, p, comm)

        # ---- summary ---------------------------------------------------------------
        wall = time.perf_counter() - start
        dofs = {}
        if u is not None:
            dofs["displacement"] = _global_size(u.function_space)
        if p is not None:
            dofs["pressure"] = _global_size(p.function_space)
            dofs["flux"] = domain.mesh.topology.index_map(d - 1).size_global  # RT0: one per facet
        # Per system: what solved it, how often it was set up and solved, where its time went.
        steps = [s for s in (flow, mechanics, coupled, second_pass) if s]
        systems = {"flow": flow.system if flow else None,
                   "mechanics": mechanics.system if mechanics else None,
                   "monolithic": coupled.system if coupled else None,
                   "flow_second_pass": second_pass.system if second_pass else None}
        stats = {name: system.statistics() if system else SolverStatistics() for name, system in systems.items()}
        flow_solves = stats["flow"].solves + stats["flow_second_pass"].solves  # both passes
        summary = {
            "scene": scene.name,
            "scheme": scene.coupling.scheme if scene.coupling else ("flow-only" if flow else "mechanics-only"),
            "q": P.q,
            "L_choice": scene.coupling.L_choice if scene.coupling else "none",
            "acceleration": (f"anderson, depth {scene.coupling.depth}"
                             if scene.coupling and scene.coupling.acceleration == "anderson" else "none"),
            "L": P.L,
            "gamma": P.gamma,
            "dofs": dofs,
            "dt": scene.dt,
            "dt_growth": scene.growth,
            "steps": report.windows,
            "retries": report.retries,
            "fine_steps": report.windows * P.q,
            "coupling_iterations": report.coupling_iterations,
            "max_iterations_per_step": report.max_iterations_per_step,
            "max_contraction_ratio": report.max_contraction_ratio,
            "mean_contraction_ratio": report.mean_contraction_ratio,
            "bound_violations": report.bound_violations,
            "resolved_ratios": report.ratios,
            "unresolved_ratios": report.unresolved_ratios,
            "max_coupled_residual": report.max_coupled_residual,
            "converged": not failure,
            "status": "failed" if failure else "interrupted" if interrupted else "completed",
            "last_completed_time": completed[1],
            "flow_solves": flow_solves,
            "mechanics_solves": stats["mechanics"].solves,
            "monolithic_solves": stats["monolithic"].solves,
            "newton_iterations": stats["mechanics"].newton_iterations + stats["monolithic"].newton_iterations,
            "linear_iterations": {"flow": stats["flow"].linear_iterations
                                  + stats["flow_second_pass"].linear_iterations,
                                  "mechanics": stats["mechanics"].linear_iterations,
                                  "monolithic": stats["monolithic"].linear_iterations},
            "solvers": _solvers_json(systems, stats, scene.solver.inexact_coupling),
            "timings": dict(_timings_json(systems, stats),
                            assembly=sum(s.assembly_time for s in steps)
                            + sum(stats[name].assembly_time for name in systems),
                            output=output.time),
            "wall_time_s": wall,
            "left_out": left_out,
            "warnings": "; ".join(warnings),
            "mpi_ranks": comm.size,
        }
        if contact_pressure is not None:
            summary["contact"] = _contact_json(contact)
        if errors:
            summary["errors"] = errors
        if failure:
            summary["failure"] = failure
        output.summary(summary)
    finally:
        output.close()

    if interrupted:
        if comm.rank == 0:
            print(f"biotcontact: interrupted (signal {interrupted}) after step {completed[0]}, t = {completed[1]:g}: "
                  f"everything up to there is in {directory}", file=sys.stderr, flush=True)
        return 128 + interrupted
    if failure:
        if comm.rank == 0:
            print(f"biotcontact: error: {failure} (log: {directory}/iterations.csv)", file=sys.stderr, flush=True)
        return RUN_NOT_CONVERGED
    say(f"wrote {output.xdmf_path()} and {directory}/summary.json ({wall:f} s)")
    return RUN_OK
