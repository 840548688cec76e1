#!/usr/bin/python3
"""The monolithic system with conduit faults solved by its factorisation and
by FGMRES preconditioned by the fixed-stress split, against the split, on
the shipped scenes with conduit faults and mechanics.

Variants: `split` is the scene's own coupling; `direct` and `iterative` are
coupling.scheme = "monolithic" with that solver.monolithic. No XDMF output.
Per run: wall time, coupling iterations (the monolithic step's iterations
on the apertures: its solves), Newton steps of the contact VI, Krylov
iterations, set-ups. Writes bench/results/monolithic_conduits.csv.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

NAME = "monolithic_conduits"
# `opening`: fault_reactivation's frictional fault made a conduit (residual
# aperture 1e-4 m) fed by a well of 1e-3 m^2/s for four days: the opening
# spreads from the well, the apertures change at every coupling iteration
# (docs/theory.md, "Flow in a fault"). `phan_loaded`: Phan's crack (mu 0.6)
# made a conduit (1e-5 m) in an impermeable rock, a well of 2e-7 m^2/s at
# its middle, the 100 MPa loaded at once in the first of three steps of
# 0.1 s (docs/theory.md, "Friction"). `phan_cohesive`: the same with a
# cohesion of 30 MPa to 2 s: p_f passes the normal stress along the whole
# crack at 1.2 s (test_cohesive_opening's scene on the fine mesh;
# docs/theory.md, "The contact law").
OPENING = ["well.injector.position=[0.0, 0.0]", 'well.injector.fault="fault"', "well.injector.rate=1.0e-3",
           "fault.fault.pore_pressure_load=false", 'fault.fault.flow="conduit"',
           "fault.fault.residual_aperture=1.0e-4", "time.end=345600.0", "coupling.tolerance=1e-10"]
PHAN_LOADED = ["flow.M=1.0e10", "flow.c_f=1.0e-9", "flow.mu_f=1.0e-3", "flow.permeability=1.0e-25",
               "flow.initial_pressure=0.0", "coupling.alpha=1.0", "coupling.tolerance=1e-10", "time.end=0.3",
               "time.dt=0.1", "fault.crack.friction=0.6", 'fault.crack.flow="conduit"',
               "fault.crack.residual_aperture=1.0e-5", 'well.inj.fault="crack"', "well.inj.position=[0.0, 0.0]",
               "well.inj.rate=2.0e-7"]
PHAN_COHESIVE = [s for s in PHAN_LOADED if not s.startswith("time.end")] + ["time.end=2.0",
                                                                            "fault.crack.cohesion=3.0e7"]
SCENES = {"network2d": ("scenes/network2d.toml", []), "network3d": ("scenes/network3d.toml", []),
          "injection_fault3d": ("scenes/injection_fault3d.toml", []),
          "opening": ("scenes/fault_reactivation.toml", OPENING), "phan_loaded": ("scenes/phan.toml", PHAN_LOADED),
          "phan_cohesive": ("scenes/phan.toml", PHAN_COHESIVE)}
VARIANT_SETS = {"split": [],
                "direct": ["coupling.scheme=monolithic", "solver.monolithic=direct"],
                "iterative": ["coupling.scheme=monolithic", "solver.monolithic=iterative"]}
COLUMNS = ["scene", "variant", "repetition", "unknowns", "wall_s", "coupling_iterations", "newton_steps",
           "krylov_iterations", "setups", "command"]


def row_from_run(scene, variant, repetition, result):
    s = result["summary"]
    solvers = s["solvers"]
    return {"scene": scene, "variant": variant, "repetition": repetition, "unknowns": sum(s["dofs"].values()),
            # The monolithic step's iterations on the apertures are its solves.
            "wall_s": float(s["wall_time_s"]),
            "coupling_iterations": s["coupling_iterations"] or solvers.get("monolithic", {}).get("solves", 0),
            "newton_steps": sum(x.get("newton_iterations", 0) for x in solvers.values()),
            "krylov_iterations": sum(x["linear_iterations"] for x in solvers.values()),
            "setups": sum(x["preconditioner_setups"] for x in solvers.values()), "command": result["command"]}


def parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    common.add_arguments(p, NAME)
    p.add_argument("--scenes", default=",".join(SCENES), help=f"comma-separated subset of {','.join(SCENES)}")
    p.add_argument("--variants", default="split,direct,iterative", help="comma-separated subset of "
                   "split,direct,iterative")
    return p


def main():
    args, petsc = common.parse_arguments(parser())
    scenes = [s.strip() for s in args.scenes.split(",") if s.strip()]
    if not scenes or any(s not in SCENES for s in scenes):
        raise common.BenchError(f"--scenes: choose from {', '.join(SCENES)}")
    variants = common.parse_variants(args.variants, tuple(VARIANT_SETS))
    recorder = common.start_recorder(args, petsc, NAME, COLUMNS, " ".join(SCENES[s][0] for s in scenes))
    with common.WorkDir(args.work_dir, args.keep_runs) as work:
        for name in scenes:
            path, sets = SCENES[name]
            for variant in variants:
                for repetition in range(1, args.repeat + 1):
                    label = f"{name}-{variant}-r{repetition}"
                    result = common.run_case([args.binary], os.path.join(common.ROOT, path),
                                             sets + VARIANT_SETS[variant] + ["output.xdmf=false"] + args.sets,
                                             petsc, work.run(label))
                    row = row_from_run(name, variant, repetition, result)
                    recorder.add(row)
                    print(f"  {label}: {row['wall_s']:.2f} s, {row['coupling_iterations']} coupling iterations, "
                          f"{row['newton_steps']} Newton steps, {row['krylov_iterations']} Krylov iterations",
                          flush=True)
    recorder.finish()
    return 0


if __name__ == "__main__":
    sys.exit(common.main_wrapper(main))
