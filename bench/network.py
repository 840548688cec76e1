#!/usr/bin/python3
"""What a fracture network costs in a coupled run (issue 52): a poroelastic
1 km x 500 m reservoir cut by a network of frictional fractures (drawn by
tools/network_geo.py --draw COUNT --seed SEED: X and T junctions, one in
five sealing, the others conduits), a well injecting into the first, under
in-situ stress; against the same scene with that one fracture alone, its
mesh refined to the network's number of unknowns. Per run the wall time of
the run over its steps (the split's coupled steps, set-up included), on 1
and 2 ranks. Writes bench/results/network.csv, one row per run and repetition, and prints
the medians and the ratio network / single fault per rank count.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
import common  # noqa: E402
import network_geo  # noqa: E402

NAME = "network"
COLUMNS = ["case", "ranks", "repetition", "wall_s", "step_s", "process_wall_s", "unknowns", "faults", "pairs",
           "steps", "coupling_iterations", "newton_iterations", "peak_rss_mb", "command"]
BOX, H = (0.0, 0.0, 1000.0, 500.0), 10.0
SCENE = """[scene]
name = "{name}"
[mesh]
type = "gmsh"
file = "{geo}"
dimension = 2
[mechanics]
E = 20.0e9
nu = 0.25
initial_equilibrium = true
[flow]
M = 1.0e10
mu_f = 1.0e-3
permeability = 1.0e-16
initial_pressure = 0.0
[coupling]
alpha = 0.8
scheme = "fixed-stress"
[time]
end = 345600.0
dt = 86400.0
[well.injector]
fault = "f01"
position = [{x!r}, {y!r}]
rate = 2.0e-5
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.bottom]
displacement = {{ y = 0.0 }}
[boundary.right]
traction = [-2.0e7, 0.0]
pressure = 0.0
[boundary.top]
traction = [0.0, -4.0e7]
"""


def well_position(network):
    """The middle of f01's longest piece between its crossings."""
    a, b = (np.array(v) for v in np.reshape(network["fractures"]["f01"], (2, 2)))
    cuts = network_geo.split_points(network["box"], network["fractures"])[0]["f01"]
    s0, s1 = max(zip(cuts, cuts[1:]), key=lambda c: c[1] - c[0])
    return a + 0.5 * (s0 + s1) * (b - a)


def write_scene(work, name, network):
    """The scene of `network` (fractures f01, ...), its .geo beside it."""
    geo = os.path.join(work, name + ".geo")
    network_geo.write_geo(network, geo)
    x, y = well_position(network)
    text = SCENE.format(name=name, geo=geo, x=float(x), y=float(y))
    for k, fault in enumerate(network["fractures"]):
        law = 'flow = "sealing"' if k % 5 == 4 else 'flow = "conduit"\nresidual_aperture = 2.0e-4'
        text += f"[fault.{fault}]\nfriction = 0.6\n{law}\n"
    path = os.path.join(work, name + ".toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def row_of(case, ranks, repetition, result):
    s = result["summary"]
    return {"case": case, "ranks": ranks, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
            "step_s": float(s["wall_time_s"]) / s["steps"], "process_wall_s": result["process_wall_s"],
            "unknowns": sum(s["dofs"].values()), "faults": len(s["contact"].get("faults", {})) or 1,
            "pairs": s["contact"]["contact_nodes"], "steps": s["steps"],
            "coupling_iterations": s["coupling_iterations"], "newton_iterations": s["newton_iterations"],
            "peak_rss_mb": result["peak_rss_mb"], "command": result["command"]}


def scenes(work, args, petsc):
    """The network's scene and the single fracture's, its mesh size chosen
    from a first run so that both have about the same unknowns."""
    network = network_geo.draw(args.faults, args.seed, BOX, H)
    single = dict(network, fractures={"f01": network["fractures"]["f01"]})
    paths = {"network": write_scene(work.path, "network", network)}
    unknowns = {}
    for case, net in (("network", network), ("single", single)):
        path = paths.get(case) or write_scene(work.path, case, net)
        result = common.run_case([args.binary], path, args.sets + ["time.end=86400.0"], petsc, work.run("size-" + case))
        unknowns[case] = sum(result["summary"]["dofs"].values())
    single["h"] = H * (unknowns["single"] / unknowns["network"]) ** 0.5
    paths["single"] = write_scene(work.path, "single", single)
    return paths


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--faults", type=int, default=50, help="fractures in the network (default 50)")
    p.add_argument("--seed", type=int, default=1, help="the network generator's seed (default 1)")
    p.add_argument("--ranks", default="1,2", help="comma-separated rank counts")
    args, petsc = common.parse_arguments(p)
    ranks = [int(r) for r in args.ranks.split(",")]
    recorder = common.start_recorder(args, petsc, NAME, COLUMNS,
                                     f"bench/network.py: {args.faults} fractures (seed {args.seed}) against one")
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        paths = scenes(work, args, petsc)
        for repetition in range(1, args.repeat + 1):
            for n in ranks:
                for case, path in paths.items():
                    out = work.run(f"{case}-{n}-r{repetition}")
                    row = row_of(case, n, repetition,
                                 common.run_case(common.on_ranks(args.binary, n), path, args.sets, petsc, out))
                    recorder.add(row)
                    print(f"  {case}, {n} rank(s) #{repetition}: {row['step_s']:.2f} s per step, "
                          f"{row['unknowns']} unknowns", flush=True)
    recorder.finish()
    for n in ranks:
        m = {case: common.medians([r for r in recorder.rows if r["case"] == case and r["ranks"] == n], [],
                                  ["step_s", "unknowns"])[0] for case in paths}
        print(f"{n} rank(s): network {m['network']['step_s']:.3f} s per step ({m['network']['unknowns']:.0f} "
              f"unknowns), single fault {m['single']['step_s']:.3f} s ({m['single']['unknowns']:.0f}): "
              f"ratio {m['network']['step_s'] / m['single']['step_s']:.2f}")


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
