#!/usr/bin/python3
"""What friction costs: the same scene with and without friction, one
mechanics step each, and the elastic solve of the same mesh without the
fault (no split, no contact).
- 2D: Phan et al.'s crack (meshes/phan2d.geo, refined once: about 1e5
  unknowns) under a uniaxial compression of 100 MPa, Coulomb mu = tan 30
  degrees against frictionless;
- 3D: a penny-shaped crack (meshes/sneddon3d.geo with the sizes near the
  disc halved: about 5e5 unknowns) pressed by 50 MPa and sheared by
  20 MPa through the cube's top, mu = 0.3 against frictionless.
Writes bench/results/friction.csv (a row per run and repetition) and prints
the medians, the ratio frictional / frictionless and the Newton steps."""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "friction"
COLUMNS = ["dim", "law", "repetition", "wall_s", "process_wall_s", "unknowns", "contact_dofs", "newton_iterations",
           "mechanics_solve_s", "schur_s", "setup_s", "max_slip", "command"]
SCENES = {2: """[mesh]
type = "gmsh"
file = "{meshes}/phan2d.geo"
dimension = 2
refine = 1
[mechanics]
E = 25.0e9
nu = 0.25
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.top]
traction = [0.0, -1.0e8]
{fault}""", 3: """[mesh]
type = "gmsh"
file = "{work}/sneddon3d_fine.geo"
dimension = 3
[mechanics]
E = 25.0e9
nu = 0.25
[time]
end = 1.0
dt = 1.0
[boundary.bottom]
displacement = {{ x = 0.0, y = 0.0, z = 0.0 }}
[boundary.top]
traction = [2.0e7, 0.0, -5.0e7]
{fault}"""}
FAULTS = {2: "[fault.crack]\nnormal = [-0.9396926207859083, 0.3420201433256687]\n",
          3: "[fault.crack]\nnormal = [0.0, 0.0, 1.0]\n"}
# "elastic": the same mesh without the fault (its crack not split, no
# contact), the reference for the frictionless step.
LAWS = {2: {"frictionless": "", "coulomb": "friction = 0.5773502691896257", "elastic": None},
        3: {"frictionless": "", "coulomb": "friction = 0.3", "elastic": None}}


# meshes/sneddon3d.geo's sizes near the disc (its Field[2]) halved: 0.02 m
# on it, 0.05 m at 0.5 m (times 0.7 gave 2.8e5 unknowns).
FINER = {"Field[2].SizeMin = 0.04;": "Field[2].SizeMin = 0.02;",
         "Field[2].SizeMax = 0.1;": "Field[2].SizeMax = 0.05;",
         "Field[3].SizeMin = 0.1;": "Field[3].SizeMin = 0.05;"}


def scene(work, dim, law):
    with open(os.path.join(common.ROOT, "meshes", "sneddon3d.geo")) as f:
        geo = f.read()
    for old, new in FINER.items():
        geo = geo.replace(old, new)
    with open(os.path.join(work, "sneddon3d_fine.geo"), "w") as f:
        f.write(geo)
    path = os.path.join(work, f"friction{dim}d_{law}.toml")
    with open(path, "w") as f:
        law_text = LAWS[dim][law]
        fault = "" if law_text is None else FAULTS[dim] + law_text + "\n"
        f.write(SCENES[dim].format(meshes=os.path.join(common.ROOT, "meshes"), work=work, fault=fault))
    return path


def row_of(dim, law, repetition, result):
    s = result["summary"]
    t, mechanics = s["timings"]["mechanics"], s["solvers"]["mechanics"]
    method = mechanics["method"]
    contact_dofs = int(method.split("condensed on ")[1].split()[0]) if "condensed on" in method else 0
    return {"dim": dim, "law": law, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
            "process_wall_s": result["process_wall_s"], "unknowns": sum(s["dofs"].values()),
            "contact_dofs": contact_dofs, "newton_iterations": mechanics.get("newton_iterations", 0),
            "mechanics_solve_s": t["solve"], "schur_s": t["schur_complement"], "setup_s": t["setup"],
            "max_slip": s["contact"]["faults"]["crack"]["max_slip"] if "contact" in s else 0.0,
            "command": result["command"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--dims", default="2,3", help="comma-separated subset of 2,3")
    args, petsc = common.parse_arguments(p)
    dims = [int(d) for d in args.dims.split(",")]
    header = common.machine_header(args.binary)
    header["scene"] = "bench/friction.py's scenes on meshes/phan2d.geo (refine 1) and meshes/sneddon3d.geo (sizes near the disc halved)"
    header["fixed_sets"] = " ".join(args.sets)
    header["petsc_options"] = " ".join(petsc)
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for dim in dims:
            for repetition in range(1, args.repeat + 1):
                for law in LAWS[dim]:
                    out = work.run(f"friction{dim}d-{law}-r{repetition}")
                    result = common.run_case([args.binary], scene(work.path, dim, law), args.sets, petsc, out)
                    row = row_of(dim, law, repetition, result)
                    recorder.add(row)
                    print(f"  {dim}D {law} #{repetition}: {row['wall_s']:.2f} s, {row['newton_iterations']} Newton "
                          f"steps on {row['contact_dofs']} contact DOFs", flush=True)
    recorder.finish()
    fields = ["wall_s", "newton_iterations", "mechanics_solve_s", "schur_s", "setup_s"]
    for dim in dims:
        m = {law: common.medians([r for r in recorder.rows if r["dim"] == dim and r["law"] == law], [], fields)[0]
             for law in LAWS[dim]}
        print(f"{dim}D: frictional {m['coulomb']['wall_s']:.2f} s ({m['coulomb']['newton_iterations']:.0f} Newton "
              f"steps), frictionless {m['frictionless']['wall_s']:.2f} s "
              f"({m['frictionless']['newton_iterations']:.0f}): ratio "
              f"{m['coulomb']['wall_s'] / m['frictionless']['wall_s']:.2f}; the elastic solve without the fault "
              f"{m['elastic']['wall_s']:.2f} s: frictionless / elastic "
              f"{m['frictionless']['wall_s'] / m['elastic']['wall_s']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
