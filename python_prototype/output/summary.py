"""summary.json: what a run computed and what it cost, whatever its end
(docs/user-guide.md, "summary.json"); cpp/output/summary.h."""
import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..scene.input import Acceleration, CouplingScheme, name_of
from ..solvers.solver import Method
from ..solvers.solver_statistics import SolverStatistics


@dataclass
class RunOutcome:
    """How a run ended and what it said on the way."""
    failure: str = ""            # empty when nothing failed
    signal: int = 0              # the interruption that ended it
    completed_time: float = 0.0  # of its last completed step
    left_out: str = ""
    warnings: str = ""
    wall_time: float = 0.0       # s
    output_time: float = 0.0     # s spent writing
    ranks: int = 1               # started
    working_ranks: int = 1       # holding the mesh (domain/working_ranks.py)


@dataclass
class SummaryInput:
    """Everything summary.json reports on: the Problem, the Scheme, the
    CouplingReport, the TimeGrid, the ContactState at the last mechanics
    output and the ReferenceErrors against the scene's closed form (None
    without one)."""
    problem: object
    scheme: object
    report: object
    grid: object
    contact: object
    errors: Optional[object] = None
    fallback: Optional[object] = None  # the monolithic scheme of coupling.fallback, once it solved a step


def _global_size(V):
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def _contact_json(c):
    j = {"contact_nodes": c.contact_nodes, "active_nodes": c.active_nodes,
         "max_penetration": c.max_penetration, "max_complementarity": c.max_complementarity,
         "max_contact_pressure": c.max_pressure, "min_contact_pressure": c.min_pressure,
         "gap_scale": c.gap_scale, "total_force": c.total_force,
         "boundaries": {name: {"force": force, "active_nodes": active} for name, force, active in c.boundaries}}
    if c.faults:
        # Per fault: its largest opening and slip (m), and the length (2D) or
        # area (3D) of it in contact, and of its pairs in the states slip and
        # stick (contact_law.py).
        j["faults"] = {f.name: {"max_opening": f.max_opening, "max_slip": f.max_slip, "closed": f.closed,
                                "slipping": f.slipping, "stuck": f.stuck}
                       for f in c.faults}
    return j


def _seismic_moment_json(m, dim):
    """Per fault the seismic moment of each accepted step
    (FaultSummary.moment) and their sum; in 3D the moment magnitude of the
    sum, Mw = (2/3) (log10 M0 - 9.1) (M0 in N m; in 2D M0 is per metre and
    has none)."""
    rows = np.reshape(m.steps, (-1, len(m.names) + 1))
    faults = {}
    for f, name in enumerate(m.names):
        total = float(np.sum(rows[:, f + 1]))
        fault = {"total": total}
        if dim == 3 and total > 0:
            fault["magnitude"] = 2.0 / 3.0 * (math.log10(total) - 9.1)
        fault.update({"times": [float(t) for t in rows[:, 0]], "moments": [float(m) for m in rows[:, f + 1]]})
        faults[name] = fault
    return faults


def _errors_json(e):
    errors = {"time": e.time, "pressure_rel_l2": e.pressure_rel_l2, "displacement_rel_l2": e.displacement_rel_l2}
    if e.settlement is not None:
        errors.update({"settlement": e.settlement.computed, "settlement_exact": e.settlement.exact,
                       "settlement_rel": e.settlement.relative})
    return errors


def _adaptive_json(spec, report, grid):
    """time.adaptive's part: the tolerance, the steps rejected or forced at
    dt_min, the contact breaks, the largest accepted estimate, the steps taken."""
    j = {"tolerance": spec.tolerance, "dt_min": spec.dt_min, "dt_max": spec.dt_max,
         "rejected_steps": report.adaptive.rejected_steps, "forced_steps": report.adaptive.forced_steps,
         "contact_breaks": report.adaptive.contact_breaks,
         "max_error_estimate": report.adaptive.max_error_estimate}
    taken = grid.dt[:report.windows]
    if taken:
        j.update(smallest_step=min(taken), largest_step=max(taken))
    return j


def _acceleration_text(c):
    """coupling.acceleration as summary.json gives it: "none", "anderson,
    depth m" or "auto, depth m" (Anderson's where the plain iteration
    stagnates)."""
    if not c or c.acceleration == Acceleration.none or c.scheme == CouplingScheme.monolithic:
        return "none"
    return f"{'anderson' if c.acceleration == Acceleration.anderson else 'auto'}, depth {c.depth}"


def _window_steps_json(c, report):
    """coupling.q = "auto"'s part: its settings, the windows' mean and
    largest q, the windows tried again with q = 1 (contact)."""
    return {"q_max": c.q_max, "q_tolerance": c.q_tolerance,
            "mean_q": report.fine_steps / report.windows if report.windows else 0.0,
            "largest_q": report.max_window_q, "q_rejections": report.q_rejections}


def _regions_json(cells, materials):
    """Each region's cells and its material's gamma and L, and the cells in
    no region (the top-level material)."""
    regions = {name: {"cells": count, "gamma": m.gamma, "L": m.L}
               for name, count, m in zip(cells.names, cells.counts, materials.regions)}
    regions["no region"] = {"cells": cells.outside, "gamma": materials.top.gamma, "L": materials.top.L}
    return regions


def _solving_steps(summary_input):
    """The steps whose systems solved the run: the scheme's, and those of
    the monolithic scheme that solved the steps the split failed at
    (coupling.fallback)."""
    i = summary_input
    return list(i.scheme.steps()) + (list(i.fallback.steps()) if i.fallback is not None else [])


def _solver_summaries(steps, inexact_coupling):
    """Per system: what solved it, how often it was set up (factorised) and
    solved, and where its time went; the solvers' and timings' tables."""
    solvers, timings = {}, {}
    for step in steps:
        system = step.system
        st = system.statistics()
        direct = system.method == Method.direct
        j = {"solver": system.method.name, "chosen_by": system.method_reason, "method": system.description(),
             "unknowns": system.unknowns(), "solves": st.solves, "factorizations": st.setups if direct else 0,
             "preconditioner_setups": st.setups, "inexact_coupling": not direct and inexact_coupling,
             "back_solves": st.back_solves, "linear_iterations": st.linear_iterations}
        if system.has_contact():
            j.update(newton_iterations=st.newton_iterations, active_set_changes=st.active_set_changes,
                     schur_columns=st.schur_columns, schur_factorizations=st.schur_factorizations,
                     contact_factorizations=st.contact_factorizations)
        solvers[step.name()] = j
        timings[step.name()] = {"total": st.total_time, "setup": st.setup_time, "solve": st.solve_time,
                                "schur_complement": st.schur_time,
                                "other": st.total_time - st.setup_time - st.solve_time - st.schur_time,
                                "matrix_assembly": st.assembly_time}
    return solvers, timings


def _statistics(steps):
    """The statistics of each system (zero for a system the scene has not)."""
    result = {name: SolverStatistics() for name in ("flow", "mechanics", "monolithic", "flow_second_pass")}
    result.update({step.name(): step.system.statistics() for step in steps})
    return result


def _dofs_json(scheme, domain):
    """The unknowns of each physics (global counts)."""
    dofs = {}
    if scheme.u is not None:
        dofs["displacement"] = _global_size(scheme.V)
    if scheme.p is not None:
        dofs["pressure"] = _global_size(scheme.p.function_space)
        dofs["flux"] = domain.mesh.topology.index_map(domain.dim - 1).size_global  # RT0: one per facet
    return dofs


def _scheme_json(problem, scheme):
    """The scheme's settings: its name, q, L and gamma, the acceleration."""
    c, parameters = problem.scene.coupling, problem.parameters
    return {"scene": problem.scene.name,
            "scheme": name_of(c.scheme) if c else ("flow-only" if scheme.p is not None else "mechanics-only"),
            "q": "auto" if c and c.q_auto else parameters.q,
            "L_choice": name_of(c.L_choice) if c else "none",
            "acceleration": _acceleration_text(c),
            "fallback": name_of(c.fallback) if c else "none",
            "L": parameters.L,
            "gamma": parameters.gamma}


def run_summary(summary_input, outcome):
    """The summary (a dict in the order of summary.json, which
    Output.summary writes) of the SummaryInput and the RunOutcome: the
    scheme, sizes, counts, contraction measures, solvers, timings, contact
    and closed-form errors of the run."""
    i, r = summary_input, summary_input.report
    scene = i.problem.scene
    steps = _solving_steps(i)
    st = _statistics(steps)
    monolithic = scene.coupling is not None and scene.coupling.scheme == CouplingScheme.monolithic
    solvers, timings = _solver_summaries(steps, not monolithic and scene.solver.inexact_coupling)
    timings["assembly"] = (i.scheme.assembly_time() + (i.fallback.assembly_time() if i.fallback is not None else 0.0)
                           + sum(s.assembly_time for s in st.values()))
    timings["output"] = outcome.output_time
    summary = _scheme_json(i.problem, i.scheme)
    summary.update({
        "dofs": _dofs_json(i.scheme, i.problem.domain),
        "dt": scene.dt,
        "dt_growth": scene.growth,
        "time_scheme": name_of(scene.time_scheme),
        "steps": r.windows,
        "retries": r.retries,
        "accelerated_windows": r.accelerated_windows,
        "pinned_windows": r.pinned_windows,
        "fallback_steps": r.fallback_steps,
        "fine_steps": r.fine_steps,
        "coupling_iterations": r.coupling_iterations,
        "max_iterations_per_step": r.max_iterations_per_step,
        "max_contraction_ratio": r.max_contraction_ratio,
        "mean_contraction_ratio": r.mean_contraction_ratio,
        "bound_violations": r.bound_violations,
        "resolved_ratios": r.ratios,
        "unresolved_ratios": r.unresolved_ratios,
        "max_coupled_residual": r.max_coupled_residual,
        "converged": not outcome.failure,
        "status": "failed" if outcome.failure else "interrupted" if outcome.signal else "completed",
        "last_completed_time": outcome.completed_time,
        "flow_solves": st["flow"].solves + st["flow_second_pass"].solves,  # both passes
        "mechanics_solves": st["mechanics"].solves,
        "monolithic_solves": st["monolithic"].solves,
        "newton_iterations": st["mechanics"].newton_iterations + st["monolithic"].newton_iterations,
        "linear_iterations": {"flow": st["flow"].linear_iterations + st["flow_second_pass"].linear_iterations,
                              "mechanics": st["mechanics"].linear_iterations,
                              "monolithic": st["monolithic"].linear_iterations},
        "solvers": solvers,
        "timings": timings,
        "wall_time_s": outcome.wall_time,
        "left_out": outcome.left_out,
        "warnings": outcome.warnings,
        "mpi_ranks": outcome.ranks,
        "working_ranks": outcome.working_ranks})
    if scene.coupling and scene.coupling.q_auto:
        summary["window_steps"] = _window_steps_json(scene.coupling, r)
    if scene.adaptive:
        summary["adaptive"] = _adaptive_json(scene.adaptive, r, i.grid)
    if i.problem.domain.regions.names:
        summary["regions"] = _regions_json(i.problem.domain.regions, i.problem.materials)
    if i.scheme.contact_pressure is not None:
        summary["contact"] = _contact_json(i.contact)
    moments = i.scheme.seismic_moments()
    if moments.names and moments.steps:
        summary["seismic_moment"] = _seismic_moment_json(moments, i.problem.domain.dim)
    if i.scheme.fault_volumes():
        # Per conduit fault, its fluid volumes since the start (FaultVolumes).
        summary["fault_volumes"] = {name: {"injected": v.injected, "stored": v.stored, "exchanged": v.exchanged,
                                           "outflow": v.outflow, "intersections": v.intersections}
                                    for name, v in i.scheme.fault_volumes()}
    if i.scheme.fault_intersections():
        # Per set of conduit faults that meet ("a & b"): the volume rate
        # through their junctions at the last step's end.
        summary["intersections"] = {" & ".join(r.faults): {"junctions": r.junctions, "rate": r.rate}
                                    for r in i.scheme.fault_intersections()}
    if i.errors is not None:
        summary["errors"] = _errors_json(i.errors)
    if outcome.failure:
        summary["failure"] = outcome.failure
    return summary
