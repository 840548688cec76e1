#!/usr/bin/python3
"""What an inclined foundation costs: the default scene on a gmsh mesh of
the cantilever, in its own frame (the foundation normal a coordinate axis:
no change of variables) and rotated by 30 degrees (every contact node
transformed, tools/rotate_mesh.py), on the direct and the iterative path.

The two frames solve the same problem (tests/test_rotation_invariance.py:
the same contact sets and iterations, fields to round-off), so the ratio of
their wall times is the cost of the change of variables. Writes
bench/results/inclined.csv, one row per run and repetition.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

sys.path.insert(0, common.ROOT)
from tools.rotate_mesh import mesh, on_mesh, rotate_msh, rotate_scene, rotation  # noqa: E402

NAME = "inclined"
PATHS = {"direct": ["solver.flow=direct", "solver.mechanics=direct"],
         "iterative": ["solver.flow=iterative", "solver.mechanics=iterative"]}
COLUMNS = ["frame", "path", "repetition", "wall_s", "process_wall_s", "unknowns", "coupling_iterations",
           "active_nodes", "mechanics_s", "mechanics_other_s", "command"]


def scenes(work, clscale):
    """(axis frame, rotated frame) scene files on the cantilever's mesh."""
    R = rotation(30.0, 2)
    base, turned = os.path.join(work, "base.msh"), os.path.join(work, "rotated.msh")
    mesh(os.path.join(common.ROOT, "meshes", "cantilever.geo"), 2, base, clscale)
    rotate_msh(base, turned, R)
    with open(os.path.join(common.ROOT, "scenes", "default.toml")) as f:
        text = f.read()
    files = []
    for frame, msh in (("axis", base), ("rotated", turned)):
        scene = on_mesh(text, msh)
        path = os.path.join(work, frame + ".toml")
        with open(path, "w") as f:
            f.write(rotate_scene(scene, R) if frame == "rotated" else scene)
        files.append((frame, path))
    return files


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--clscale", type=float, default=0.25, help="gmsh's element size factor (default 0.25)")
    p.add_argument("--paths", default=",".join(PATHS), help=f"comma-separated subset of {','.join(PATHS)}")
    args, petsc = common.parse_arguments(p)
    paths = common.parse_variants(args.paths, PATHS)
    recorder = common.start_recorder(
        args, petsc, NAME, COLUMNS,
        f"scenes/default.toml on meshes/cantilever.geo (clscale {args.clscale:g}), axis and rotated 30 deg")
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        files = scenes(work.path, args.clscale)
        for path in paths:
            for repetition in range(1, args.repeat + 1):
                for frame, scene in files:  # interleaved: the machine's drift hits both frames alike
                    out = work.run(f"{frame}-{path}-r{repetition}")
                    result = common.run_case([args.binary], scene, PATHS[path] + args.sets, petsc, out)
                    s = result["summary"]
                    timings = s["timings"]
                    row = {"frame": frame, "path": path, "repetition": repetition, "wall_s": float(s["wall_time_s"]),
                           "process_wall_s": result["process_wall_s"], "unknowns": sum(s["dofs"].values()),
                           "coupling_iterations": s["coupling_iterations"],
                           "active_nodes": s["contact"]["active_nodes"],
                           "mechanics_s": timings["mechanics"]["total"],
                           "mechanics_other_s": timings["mechanics"]["other"],
                           "command": result["command"]}
                    recorder.add(row)
                    print(f"  {frame} {path} #{repetition}: {row['wall_s']:.2f} s, "
                          f"{row['coupling_iterations']} iterations", flush=True)
    recorder.finish()
    for path in paths:
        wall = {frame: common.medians([r for r in recorder.rows if r["frame"] == frame and r["path"] == path],
                                      [], ["wall_s"])[0]["wall_s"] for frame, _ in files}
        print(f"{path}: axis {wall['axis']:.2f} s, rotated {wall['rotated']:.2f} s, ratio "
              f"{wall['rotated'] / wall['axis']:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
