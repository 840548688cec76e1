#!/usr/bin/python3
"""What a conduit fault costs in the coupled split: the same poroelastic
scene with a transparent fault and with a conduit fault, without and with
Anderson acceleration.

Phan et al.'s crack (meshes/phan2d.geo, refined once: about 3.3e5
unknowns; the fault holds 0.3 % of the facets), frictional (mu 0.6,
cohesion 30 MPa) and closed under 100 MPa, in a rock of 1e-15 m^2 (M =
1e10 Pa, alpha = 1) started in equilibrium with its load; the left side
held at 10 MPa drives the fluid across the plate for 10 steps of 0.1 s.
The transparent fault's faces carry the rock's pore pressure
(pore_pressure_load), the conduit's its own p_f (residual aperture 1e-4 m,
continuous exchange), so both are effective-stress faults.

    /usr/bin/python3 bench/conduit.py [--repeat 3] [--binary build/biotcontact]
        [--out-dir bench/results] [-- PETSc options]

Writes bench/results/conduit.csv, one row per run and repetition, and
prints the medians and the ratios conduit / transparent of the wall time
and the coupling iterations.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "conduit"
COLUMNS = ["fault", "acceleration", "repetition", "wall_s", "process_wall_s", "unknowns", "steps",
           "coupling_iterations", "flow_solve_s", "mechanics_solve_s", "assembly_s", "command"]
SCENE = """[mesh]
type = "gmsh"
file = "{meshes}/phan2d.geo"
dimension = 2
refine = 1
[mechanics]
E = 25.0e9
nu = 0.25
initial_equilibrium = true
[flow]
M = 1.0e10
c_f = 1.0e-9
mu_f = 1.0e-3
permeability = 1.0e-15
initial_pressure = 0.0
[coupling]
alpha = 1.0
tolerance = 1e-8
acceleration = "{acceleration}"
[time]
end = 1.0
dt = 0.1
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.left]
displacement = {{ x = 0.0 }}
pressure = 1.0e7
[boundary.right]
pressure = 0.0
[boundary.top]
traction = [0.0, -1.0e8]
[fault.crack]
normal = [-0.9396926207859083, 0.3420201433256687]
friction = 0.6
cohesion = 3.0e7
{fault}
"""
FAULTS = {"transparent": "pore_pressure_load = true",
          "conduit": 'flow = "conduit"\nresidual_aperture = 1.0e-4'}
ACCELERATIONS = ("none", "anderson")


def scene(work, fault, acceleration):
    path = os.path.join(work, f"conduit_{fault}_{acceleration}.toml")
    with open(path, "w") as f:
        f.write(SCENE.format(meshes=os.path.join(common.ROOT, "meshes"), acceleration=acceleration,
                             fault=FAULTS[fault]))
    return path


def row_of(fault, acceleration, repetition, result):
    s = result["summary"]
    t = s["timings"]
    return {"fault": fault, "acceleration": acceleration, "repetition": repetition,
            "wall_s": float(s["wall_time_s"]), "process_wall_s": result["process_wall_s"],
            "unknowns": sum(s["dofs"].values()), "steps": s["steps"],
            "coupling_iterations": s["coupling_iterations"], "flow_solve_s": t["flow"]["solve"],
            "mechanics_solve_s": t["mechanics"]["solve"], "assembly_s": t["assembly"], "command": result["command"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    args, petsc = common.parse_arguments(p)
    header = common.machine_header(args.binary)
    header["scene"] = "bench/conduit.py's scene on meshes/phan2d.geo (refine 1), 10 coupled steps"
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for repetition in range(1, args.repeat + 1):
            for acceleration in ACCELERATIONS:
                for fault in FAULTS:
                    out = work.run(f"conduit-{fault}-{acceleration}-r{repetition}")
                    result = common.run_case([args.binary], scene(work.path, fault, acceleration), args.sets,
                                             petsc, out)
                    row = row_of(fault, acceleration, repetition, result)
                    recorder.add(row)
                    print(f"  {fault}, acceleration {acceleration} #{repetition}: {row['wall_s']:.2f} s, "
                          f"{row['coupling_iterations']} coupling iterations", flush=True)
    recorder.finish()
    for acceleration in ACCELERATIONS:
        m = {fault: common.medians([r for r in recorder.rows if r["fault"] == fault
                                    and r["acceleration"] == acceleration], [], ["wall_s", "coupling_iterations"])[0]
             for fault in FAULTS}
        c, t = m["conduit"], m["transparent"]
        print(f"acceleration {acceleration}: conduit {c['wall_s']:.2f} s ({c['coupling_iterations']:.0f} "
              f"iterations), transparent {t['wall_s']:.2f} s ({t['coupling_iterations']:.0f}): ratios "
              f"{c['wall_s'] / t['wall_s']:.3f} (time), {c['coupling_iterations'] / t['coupling_iterations']:.3f} "
              f"(iterations)")
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
