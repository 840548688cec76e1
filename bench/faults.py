#!/usr/bin/python3
"""What a fault costs in a coupled run: the fixed-stress split on a scene
with a sealing frictionless fault, 2D (meshes/fault_depletion.geo, 1.2e5
unknowns) and 3D (meshes/fault3d.geo, about 4e5), the formation drained
from one side. Per coupling iteration: the wall time against the time of
its solve phases (the flow's back-solve, the mechanics' contact solve on
the condensed fault), as for the foundations.

Writes bench/results/faults.csv, one row per run and repetition, and prints
the medians.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "faults"
COLUMNS = ["dim", "repetition", "wall_s", "process_wall_s", "unknowns", "coupling_iterations", "pairs",
           "flow_solve_s", "mechanics_solve_s", "schur_s", "setup_s", "assembly_s", "flow_back_solves",
           "mechanics_back_solves", "command"]
SCENE = """[scene]
name = "fault{dim}d_coupled"
[mesh]
type = "gmsh"
file = "{mesh}"
dimension = {dim}
[mechanics]
E = 14.95e9
nu = 0.15
[flow]
M = 5.0e10
mu_f = 1.0e-3
permeability = 1.0e-14
initial_pressure = 0.0
[coupling]
alpha = 0.9
L = "kdr"
tolerance = 1e-8
[time]
end = 4.0
dt = 1.0
[fault.fault]
normal = {normal}
flow = "sealing"
[boundary.left]
displacement = {{ x = 0.0 }}
pressure = "-2.0e7 * min(t, 1)"
[boundary.right]
displacement = {{ x = {push} }}
[boundary.bottom]
displacement = {{ {bottom} = 0.0 }}
"""
CASES = {2: {"mesh": "fault_depletion.geo", "normal": "[1.0, 0.0]", "push": -32.0, "bottom": "y"},
         3: {"mesh": "fault3d.geo", "normal": "[0.866, 0.0, 0.5]", "push": -4.0, "bottom": "z"}}


def scene(work, dim):
    path = os.path.join(work, f"fault{dim}d.toml")
    case = dict(CASES[dim], mesh=os.path.join(common.ROOT, "meshes", CASES[dim]["mesh"]))
    text = SCENE.format(dim=dim, **case)
    if dim == 3:
        text += "[boundary.front]\ndisplacement = { y = 0.0 }\n"
    with open(path, "w") as f:
        f.write(text)
    return path


def row_of(dim, repetition, result):
    s = result["summary"]
    t, solvers = s["timings"], s["solvers"]
    return {"dim": dim, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
            "process_wall_s": result["process_wall_s"], "unknowns": sum(s["dofs"].values()),
            "coupling_iterations": s["coupling_iterations"], "pairs": s["contact"]["contact_nodes"],
            "flow_solve_s": t["flow"]["solve"], "mechanics_solve_s": t["mechanics"]["solve"],
            "schur_s": t["mechanics"]["schur_complement"], "setup_s": t["flow"]["setup"] + t["mechanics"]["setup"],
            "assembly_s": t["assembly"], "flow_back_solves": solvers["flow"]["back_solves"],
            "mechanics_back_solves": solvers["mechanics"]["back_solves"], "command": result["command"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--dims", default="2,3", help="comma-separated subset of 2,3")
    args, petsc = common.parse_arguments(p)
    dims = [int(d) for d in args.dims.split(",")]
    header = common.machine_header(args.binary)
    header["scene"] = "bench/faults.py's coupled scenes on meshes/fault_depletion.geo and meshes/fault3d.geo"
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for dim in dims:
            path = scene(work.path, dim)
            for repetition in range(1, args.repeat + 1):
                out = work.run(f"fault{dim}d-r{repetition}")
                row = row_of(dim, repetition, common.run_case([args.binary], path, args.sets, petsc, out))
                recorder.add(row)
                print(f"  {dim}D #{repetition}: {row['wall_s']:.2f} s, {row['coupling_iterations']} iterations",
                      flush=True)
    recorder.finish()
    fields = ["wall_s", "coupling_iterations", "flow_solve_s", "mechanics_solve_s", "schur_s", "setup_s"]
    for dim in dims:
        m = common.medians([r for r in recorder.rows if r["dim"] == dim], [], fields)[0]
        n = m["coupling_iterations"]
        per = (m["wall_s"] - m["setup_s"] - m["schur_s"]) / n
        solves = (m["flow_solve_s"] + m["mechanics_solve_s"]) / n
        print(f"{dim}D: {m['wall_s']:.2f} s, {n:.0f} iterations; per iteration {1e3 * per:.1f} ms after the "
              f"set-ups, of which the solve phases {1e3 * solves:.1f} ms (ratio {per / solves:.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
