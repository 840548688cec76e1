#!/usr/bin/python3
"""What a conduit fault costs in the coupled split: the same poroelastic
scene with a transparent fault and with a conduit fault, without and with
Anderson acceleration (`--compare fault`, the default); or what its
Barton-Bandis closure costs (`--compare closure`).

Writes bench/results/conduit.csv (conduit_closure.csv), one row per run and
repetition, and prints the medians and the ratios of the second case to the
first (conduit / transparent, closure / conduit) of the wall time and the
coupling iterations.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "conduit"
COLUMNS = ["fault", "acceleration", "repetition", "wall_s", "process_wall_s", "unknowns", "steps",
           "coupling_iterations", "flow_solve_s", "mechanics_solve_s", "assembly_s", "command"]
# Both comparisons' rock, fluid and coupling (a format string's text: its
# {{ }} are filled by the scene's own format).
ROCK = """[mechanics]
E = 25.0e9
nu = 0.25
initial_equilibrium = true
[flow]
M = 1.0e10
c_f = 1.0e-9
mu_f = 1.0e-3
permeability = {permeability}
initial_pressure = {initial_pressure}
[coupling]
alpha = 1.0
tolerance = {tolerance}
acceleration = "{{acceleration}}"
"""
# `fault`: Phan et al.'s crack refined once (about 3.3e5 unknowns; the fault
# holds 0.3 % of the facets), frictional and closed under 100 MPa, the rock
# started in equilibrium with its load; the left side held at 10 MPa drives
# the fluid across for 10 steps. The transparent fault's faces carry the
# rock's pore pressure, the conduit's its own p_f: both are effective-stress
# faults.
SCENE = ("""[mesh]
type = "gmsh"
file = "{meshes}/phan2d.geo"
dimension = 2
refine = 1
"""
         + ROCK.format(permeability="1.0e-15", initial_pressure="0.0", tolerance="1e-8") + """[time]
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
""")
# `closure`: a conduit across a 3D box at mesh size 0.1 (about 1.4e5
# unknowns, the flow solved iteratively by `auto`), closed under 20 MPa, its
# ends held at 15 and 1 MPa; the Barton-Bandis closure makes w_h, and so the
# fault's block of the flow system, change at every coupling iteration.
BOX_SCENE = ("""[mesh]
type = "gmsh"
file = "{work}/fault_box.geo"
dimension = 3
"""
         + ROCK.format(permeability="1.0e-25", initial_pressure="1.0e6", tolerance="1e-11") + """[time]
end = 4.0e6
dt = 1.0e6
[boundary.bottom]
displacement = {{ z = 0.0 }}
[boundary.left]
displacement = {{ x = 0.0 }}
pressure = 1.5e7
[boundary.right]
pressure = 1.0e6
[boundary.top]
traction = [0.0, 0.0, -2.0e7]
[boundary.sides]
displacement = {{ y = 0.0 }}
[fault.crack]
normal = [0.0, 0.0, 1.0]
flow = "conduit"
residual_aperture = 1.0e-5
{fault}
""")
# Each comparison: its CSV's name, its scene, the two cases (the fault's
# keys) and the accelerations.
COMPARISONS = {
    "fault": ("conduit", SCENE, {"transparent": "pore_pressure_load = true",
                                 "conduit": 'flow = "conduit"\nresidual_aperture = 1.0e-4'}, ("none", "anderson")),
    "closure": ("conduit_closure", BOX_SCENE, {"conduit": "", "closure": "closure = { V_m = 1.0e-4, K_ni = 1.0e11 }"},
                ("none",)),
}


def scene(work, compare, case, acceleration):
    """The scene file of one case (and the box's mesh, at size 0.1)."""
    name, text, cases, _ = COMPARISONS[compare]
    if compare == "closure":
        with open(os.path.join(common.ROOT, "meshes", "fault_box.geo")) as f:
            geo = f.read()
        with open(os.path.join(work, "fault_box.geo"), "w") as f:
            f.write(geo + "Mesh.CharacteristicLengthMax = 0.1;\n")
    path = os.path.join(work, f"{name}_{case}_{acceleration}.toml")
    with open(path, "w") as f:
        f.write(text.format(meshes=os.path.join(common.ROOT, "meshes"), work=work, acceleration=acceleration,
                            fault=cases[case]))
    return path


def row_of(fault, acceleration, repetition, result):
    s = result["summary"]
    t = s["timings"]
    return {"fault": fault, "acceleration": acceleration, "repetition": repetition,
            "wall_s": float(s["wall_time_s"]), "process_wall_s": result["process_wall_s"],
            "unknowns": sum(s["dofs"].values()), "steps": s["steps"],
            "coupling_iterations": s["coupling_iterations"], "flow_solve_s": t["flow"]["solve"],
            "mechanics_solve_s": t["mechanics"]["solve"], "assembly_s": t["assembly"], "command": result["command"]}


SCENES = {"fault": "bench/conduit.py's scene on meshes/phan2d.geo (refine 1), 10 coupled steps",
          "closure": "bench/conduit.py's box, meshes/fault_box.geo at size 0.1, 4 coupled steps"}


def report(recorder, cases, accelerations):
    """The medians per case and the ratios of the second case to the first."""
    first, second = cases
    for acceleration in accelerations:
        m = {case: common.medians([r for r in recorder.rows if r["fault"] == case
                                   and r["acceleration"] == acceleration], [], ["wall_s", "coupling_iterations"])[0]
             for case in cases}
        a, b = m[first], m[second]
        print(f"acceleration {acceleration}: {second} {b['wall_s']:.2f} s ({b['coupling_iterations']:.0f} "
              f"iterations), {first} {a['wall_s']:.2f} s ({a['coupling_iterations']:.0f}): ratios "
              f"{b['wall_s'] / a['wall_s']:.3f} (time), {b['coupling_iterations'] / a['coupling_iterations']:.3f} "
              f"(iterations)")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--compare", choices=sorted(COMPARISONS), default="fault",
                   help="transparent against conduit fault (default), or a conduit without and with its closure")
    args, petsc = common.parse_arguments(p)
    name, _, cases, accelerations = COMPARISONS[args.compare]
    header = common.machine_header(args.binary)
    header["scene"] = SCENES[args.compare]
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, name, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for repetition in range(1, args.repeat + 1):
            for acceleration in accelerations:
                for case in cases:
                    out = work.run(f"{name}-{case}-{acceleration}-r{repetition}")
                    result = common.run_case([args.binary], scene(work.path, args.compare, case, acceleration),
                                             args.sets, petsc, out)
                    row = row_of(case, acceleration, repetition, result)
                    recorder.add(row)
                    print(f"  {case}, acceleration {acceleration} #{repetition}: {row['wall_s']:.2f} s, "
                          f"{row['coupling_iterations']} coupling iterations", flush=True)
    recorder.finish()
    report(recorder, list(cases), accelerations)
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
