#!/usr/bin/python3
"""Mandel's problem: pressure error against wall time, h and dt refined
together, for the monolithic solve and the fixed-stress split.

scenes/mandel.toml with time.end=50 at cells [40,4] dt 25, [80,8] dt 12.5,
[160,16] dt 6.25 and [320,32] dt 3.125 (dt = 1000/nx for any --cells).
The error is the cell-area weighted relative l2 error of the P0 pressure at
the cell centres at the final time, against python_prototype/diagnostics/
closed_form.py's Mandel, read from solution.h5 (the wall time includes the
output); the closed form reads the scene file: --set must not change it.
Writes bench/results/mandel.csv, one row per run and repetition.
"""
import argparse
import math
import os
import sys
import tomllib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

sys.path.insert(0, common.ROOT)
from python_prototype.output.time_series import read_time_series  # noqa: E402

sys.path.insert(0, common.ROOT)
from python_prototype.diagnostics.closed_form import Mandel, Medium  # noqa: E402

NAME = "mandel"
SCENE = "scenes/mandel.toml"
END = 50.0
CELLS = [(40, 4), (80, 8), (160, 16), (320, 32)]
VARIANTS = {"monolithic": ["coupling.scheme=monolithic"], "fixed-stress": ["coupling.scheme=fixed-stress"]}
COLUMNS = ["variant", "cells", "dt", "repetition", "wall_s", "process_wall_s", "pressure_error",
           "summary_pressure_error", "unknowns", "steps", "coupling_iterations", "peak_rss_mb", "command"]


def time_step(cells):
    """dt for a mesh: 25 s at 40 cells across, halved with h."""
    return 1000.0 / cells[0]


def closed_form(scene_path):
    """The Mandel closed form with the scene's parameters."""
    with open(scene_path, "rb") as f:
        s = tomllib.load(f)
    mesh, mech, flow = s["mesh"], s["mechanics"], s["flow"]
    storage = 1.0 / flow.get("M", math.inf) + flow.get("c_f", 0.0) * flow.get("phi0", 0.0)
    medium = Medium(G=mech["G"], lmbda=mech["lambda"], alpha=s["coupling"]["alpha"], storage=storage,
                    mobility=flow["permeability"] / flow["mu_f"])
    return Mandel(a=mesh["upper"][0] - mesh["lower"][0], b=mesh["upper"][1] - mesh["lower"][1], medium=medium,
                  F=s["reference"]["force"])


def final_pressure(directory):
    """(time, P0 pressure values, cell centres, cell areas) at the last
    output time of a run (triangles)."""
    nodes, triangles, series = read_time_series(directory)
    if "pressure" not in series:
        raise common.BenchError(f"{directory}/solution.xdmf: no pressure output")
    t = max(series["pressure"])
    pressure = series["pressure"][t][1].reshape(-1)
    v = nodes[triangles][:, :, :2]
    areas = 0.5 * np.abs(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]))
    return t, pressure, v.mean(axis=1), areas


def pressure_error(directory, mandel):
    """sqrt(sum_T |T| (p_h - p(x_T))^2 / sum_T |T| p(x_T)^2) at the final time."""
    t, p_h, centres, areas = final_pressure(directory)
    exact = mandel.pressure(centres[:, 0], t)
    return math.sqrt(float(np.sum(areas * (p_h - exact) ** 2)) / float(np.sum(areas * exact ** 2)))


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--cells", help='restrict to these meshes, e.g. "[40,4],[80,8]"; dt = 1000/nx')
    p.add_argument("--variants", default=",".join(VARIANTS), help=f"comma-separated subset of {','.join(VARIANTS)}")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    variants = common.parse_variants(args.variants, VARIANTS)
    cells = common.parse_cells(args.cells) if args.cells else CELLS
    scene = os.path.join(common.ROOT, SCENE)
    mandel = closed_form(scene)
    header = common.machine_header(args.binary)
    header["scene"] = SCENE
    header["fixed_sets"] = " ".join([f"time.end={END:g}", "time.dt=1000/nx"] + args.sets)
    header["petsc_options"] = " ".join(petsc)
    header["error"] = "cell-area weighted relative l2 error of the P0 pressure at cell centres, final time"
    common.print_header(header)
    recorder = common.Recorder(args.out_dir, NAME, COLUMNS, header, args.update)
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for variant in variants:
            for mesh in cells:
                dt = time_step(mesh)
                for repetition in range(1, args.repeat + 1):
                    sets = ([f"mesh.cells={common.cells_text(mesh)}", f"time.dt={dt:g}", f"time.end={END:g}"]
                            + VARIANTS[variant] + args.sets)
                    out = work.run(f"{variant}-{mesh[0]}x{mesh[1]}-r{repetition}")
                    result = common.run_case([args.binary], scene, sets, petsc, out)
                    s = result["summary"]
                    row = {"variant": variant, "cells": common.cells_text(mesh), "dt": dt, "repetition": repetition,
                           "wall_s": float(s["wall_time_s"]), "process_wall_s": result["process_wall_s"],
                           "pressure_error": pressure_error(out, mandel),
                           "summary_pressure_error": (s.get("errors") or {}).get("pressure_rel_l2"),
                           "unknowns": sum(s["dofs"].values()), "steps": s["steps"],
                           "coupling_iterations": s["coupling_iterations"], "peak_rss_mb": result["peak_rss_mb"],
                           "command": result["command"]}
                    recorder.add(row)
                    print(f"  {variant} {row['cells']} dt {dt:g} #{repetition}: {row['wall_s']:.2f} s, "
                          f"pressure error {row['pressure_error']:.3e}", flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
