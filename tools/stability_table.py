#!/usr/bin/python3
"""The stiff and extreme cases of issue 5, run with the fixed-stress split
(single rate and multirate) and the monolithic solver, and those of a fault
(issue 53: scenes/fault_reactivation.toml varied); writes docs/stability.md.
Also imported by tests/test_stability.py, which runs the first table's
cases (the same overrides) and asserts what theory and physics guarantee.

    /usr/bin/python3 tools/stability_table.py [--binary build/biotcontact] [--faults-only]
"""
import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from support import Fields  # noqa: E402

TERZAGHI = "scenes/terzaghi.toml"
DEFAULT = "scenes/default.toml"
# Terzaghi runs to t = 0.2 (20 steps) unless a case says otherwise; its
# physical pressure range is [0, p0] with p0 the undrained pressure
# alpha m_v q/(S + alpha^2 m_v) (no Mandel-Cryer effect in 1D).
SHORT = ["time.end=0.2"]
CASES = [
    ("reference (Terzaghi)", TERZAGHI, SHORT),
    ("incompressible constituents: M = inf, c_f = 0 (S = 0, gamma = 1)", TERZAGHI, SHORT + ["flow.M=inf"]),
    ("soft skeleton: lambda = 1e-6 G, L = paper", TERZAGHI, SHORT + ["mechanics.lambda=3e-6"]),
    ("soft skeleton: lambda = 1e-6 G, L = kdr", TERZAGHI, SHORT + ["mechanics.lambda=3e-6", "coupling.L=kdr"]),
    ("nearly incompressible skeleton: nu = 0.4999", TERZAGHI, SHORT + ["mechanics.lambda=14997.0"]),
    ("very low permeability k/mu = 1e-20, dt = 1e-3", TERZAGHI,
     ["time.end=0.02", "time.dt=1e-3", "flow.permeability=1.5e-20"]),
    ("permeability contrast 1e8 between layers", TERZAGHI,
     SHORT + ["flow.permeability='y < 5 ? 1.5e-8 : 1.5'", "reference.solution=none"]),
    ("dt far above the diffusion time (dt = 100 h^2/c)", TERZAGHI, ["time.end=2e4", "time.dt=1e3"]),
    ("dt far below the diffusion time (dt = 1e-6 h^2/c)", TERZAGHI, ["time.end=1e-4", "time.dt=5e-6"]),
    ("decoupled: alpha = 1e-6", TERZAGHI, SHORT + ["coupling.alpha=1e-6"]),
    ("alpha = 1", TERZAGHI, SHORT + ["coupling.alpha=1.0"]),
    ("contact: zero gap (Terzaghi on a contact base)", "scenes/terzaghi_contact.toml", SHORT),
    ("contact: gap never reached", DEFAULT, ["boundary.bottom.contact.gap=1.0"]),
    ("contact: load reverses at t = 4.8, contact opens", DEFAULT,
     ["boundary.top.traction=[0.0, '-1e3*(t < 4.9 ? 1 : -1)']"]),
    ("contact: front moves within a coupling loop (default scene)", DEFAULT, []),
    ("SI magnitudes (default scene)", DEFAULT, []),
    ("the same in scaled units (stress / 1e9)", DEFAULT,
     ["mechanics.E=1.0", "flow.M=100.0", "flow.c_f=0.44", "flow.permeability=1e-4",
      "boundary.top.traction=[0.0, -1e-6]"]),
]
# The splits are the paper's iteration (coupling.acceleration = "none"; the
# default "auto" hands a stagnating window to Anderson's method).
PAPER = "coupling.acceleration=none"
SCHEMES = [("fixed-stress", ["coupling.scheme=fixed-stress", PAPER]),
           ("multirate q=4", ["coupling.scheme=multirate", "coupling.q=4", PAPER]),
           ("multirate q=64", ["coupling.scheme=multirate", "coupling.q=64", "time.end=12.8", PAPER]),
           ("monolithic", ["coupling.scheme=monolithic"])]


# The fault cases: scenes/fault_reactivation.toml (a frictional fault, mu
# 0.6, loaded by the pore pressure beside it; a well injects beside it for
# 30 days), varied. CONDUIT makes the fault a conduit with its own p_f.
# A case's third entry, where the run fails, is the remedy tried next.
FAULT = "scenes/fault_reactivation.toml"
CONDUIT = ["fault.fault.flow=conduit", "fault.fault.residual_aperture=1e-4", "fault.fault.pore_pressure_load=false"]
SPLIT = ["coupling.scheme=fixed-stress", "coupling.acceleration=anderson"]  # the remedy where monolithic fails
ALONG = "(0.5 * x + 0.8660254 * y)"     # the distance along the fault from its centre
ACROSS = "(-0.8660254 * x + 0.5 * y)"   # the distance across it, > 0 on its + side
FAULT_CASES = [
    ("fault reference (fault_reactivation)", [], []),
    ("nearly incompressible rock: nu = 0.4999", ["mechanics.nu=0.4999"], []),
    ("rock E 1e6 times stiffer on the fault's + side", [f"region.stiff.where='{ACROSS} > 0'", "region.stiff.E=2e16"],
     []),
    ("soft fault zone: E = 1e5 Pa within 20 m of the fault",
     [f"region.zone.where='abs({ACROSS}) < 20 && abs({ALONG}) < 620'", "region.zone.E=1e5"], []),
    ("soft fault zone: E = 1e8 Pa within 20 m of the fault",
     [f"region.zone.where='abs({ACROSS}) < 20 && abs({ALONG}) < 620'", "region.zone.E=1e8"], []),
    ("frictionless fault", ["fault.fault.friction=0.0"], []),
    ("friction 0.01", ["fault.fault.friction=0.01"], []),
    ("friction 1", ["fault.fault.friction=1.0"], []),
    ("friction 10", ["fault.fault.friction=10.0"], []),
    ("cohesion 1e6 Pa (friction 0.6)", ["fault.fault.cohesion=1e6"], []),
    ("cohesion 1e9 Pa (friction 0.6)", ["fault.fault.cohesion=1e9"], []),
    ("cohesion only: 3e7 Pa, friction 0", ["fault.fault.friction=0.0", "fault.fault.cohesion=3e7"], []),
    ("dt = 1e-6 s (10 steps)", ["time.dt=1e-6", "time.end=1e-5"], ["coupling.scheme=monolithic"]),
    ("dt = 1e9 s (5 steps)", ["time.dt=1e9", "time.end=5e9"], []),
    ("conduit fault, w_r = 1e-4 m", CONDUIT, []),
    ("conduit fault, w_r = 1e-9 m", CONDUIT + ["fault.fault.residual_aperture=1e-9"], SPLIT),
    ("conduit fault, w_r = 1e-1 m", CONDUIT + ["fault.fault.residual_aperture=1e-1"], SPLIT),
    ("conduit fault, k_n = 1e-30 m^2", CONDUIT + ["fault.fault.normal_permeability=1e-30"], []),
    ("conduit fault, k_n = 1e-20 m^2", CONDUIT + ["fault.fault.normal_permeability=1e-20"], []),
    ("conduit fault, its own k_f = 1e-6 m^2", CONDUIT + ["fault.fault.permeability=1e-6"], []),
]
WELL_RATE = 1.0e-3  # m^2/s, the scene's well.injector.rate
FAULT_SCHEMES = [("fixed-stress", ["coupling.scheme=fixed-stress", PAPER]),
                 ("fixed-stress, Anderson", ["coupling.scheme=fixed-stress", "coupling.acceleration=anderson"]),
                 ("multirate q=5", ["coupling.scheme=multirate", "coupling.q=5", PAPER]),
                 ("monolithic", ["coupling.scheme=monolithic"])]


def schemes_for(scene):
    """q = 64 (the large-q case) runs on the default scene only."""
    return [s for s in SCHEMES if s[0] != "multirate q=64" or scene == DEFAULT]


def run_case(binary, scene, overrides, scheme_overrides):
    out = tempfile.mkdtemp(prefix="stability-")
    cmd = [binary, "run", os.path.join(ROOT, scene), "--out", out, "--set", "coupling.max_iterations=3000"]
    for o in overrides + scheme_overrides:
        cmd += ["--set", o]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    result = {"exit": p.returncode, "stderr": p.stderr.strip(), "out": out}
    path = os.path.join(out, "summary.json")
    if os.path.exists(path):
        with open(path) as f:
            result["summary"] = json.load(f)
        fields = Fields(out)
        pressures = [fields.at("pressure", t) for t in fields.times("pressure")[1:]]
        result["p_min"] = min(float(p.min()) for p in pressures) if pressures else 0.0
        result["p_max"] = max(float(p.max()) for p in pressures) if pressures else 0.0
        with open(os.path.join(out, "iterations.csv")) as f:
            rows = [line.split(",") for line in f.read().splitlines()[1:]]
        per_step = {}
        for r in rows:
            per_step.setdefault(r[0], []).append(int(r[8]))
        result["active_changes_within_step"] = sum(1 for v in per_step.values() if len(set(v)) > 1)
        result["iterations"] = [int(r[2]) for r in rows]
    return result


def undrained_pressure(summary, overrides):
    """p0 of the Terzaghi scene with the case's overrides."""
    values = {"lambda": 2.0, "G": 3.0, "M": 16.0, "alpha": 0.6, "load": 1.0}
    for o in overrides:
        key, value = o.split("=", 1)
        name = key.split(".")[-1]
        if name in values:
            values[name] = float(value)
    m_v = 1 / (values["lambda"] + 2 * values["G"])
    S = 1 / values["M"]
    a = values["alpha"]
    return a * m_v * values["load"] / (S + a * a * m_v)


def row(label, scheme, r, p_scale):
    if "summary" not in r:
        return f"| {label} | {scheme} | failed: {r['stderr'][-120:]} |||||||"
    s = r["summary"]
    steps = max(s["steps"], 1)
    its = s["coupling_iterations"]
    iters = "-" if s["scheme"] == "monolithic" else f"{its / steps:.1f} / {s['max_iterations_per_step']}"
    ratio = "-" if s["scheme"] == "monolithic" or not s["resolved_ratios"] else \
        f"{s['max_contraction_ratio']:.3f} / {s['gamma']:.4f} ({s['bound_violations']} above)"
    conv = "yes" if s["converged"] else "NO: " + r["stderr"].split(";")[0][-80:]
    rng = f"{r['p_min'] / p_scale:+.2e} .. {r['p_max'] / p_scale:.4f}" if p_scale else \
        f"{r['p_min']:.3e} .. {r['p_max']:.3e}"
    contact = s.get("contact", {}).get("active_nodes", "-")
    return (f"| {label} | {scheme} | {iters} | {ratio} | {conv} | {rng} | {contact} "
            f"| {r.get('active_changes_within_step', 0)} | {s['wall_time_s']:.1f} |")


FAULT_HEADER = """## Faults

`scenes/fault_reactivation.toml` (a frictional fault, mu 0.6, loaded by
the pore pressure beside it, a well injecting beside it for 30 days)
varied, with each scheme (the overrides in the script). The fault's state
at the end is the length closed, stuck and slipping (m of the 1190 m
fault); a conduit fault's volume imbalance is |injected + exchanged -
stored - outflow| over the volume the well injected. A failed run gives
its one line (exit 2: refused; exit 3: the run stopped, its finished steps
kept); where a remedy is listed, the row after it is the run with it.
"""


def fault_header():
    """The fault section's text, and where and when its rows were made
    (--faults-only regenerates them alone)."""
    return (FAULT_HEADER + f"These rows: {platform.node()} ({os.cpu_count()} cores, {cpu_model()}), "
            f"{datetime.date.today()}.\n\n")


def cpu_model():
    with open("/proc/cpuinfo") as f:
        return next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), "unknown cpu")


def fault_volume_imbalance(s):
    """The conduit fault's |injected + exchanged - stored - outflow| over the
    volume the scene's well injected by the end (its rate times the time),
    or None without a conduit."""
    v = s.get("fault_volumes", {}).get("fault")
    if v is None:
        return None
    return abs(v["injected"] + v["exchanged"] - v["stored"] - v["outflow"]) / (WELL_RATE * s["last_completed_time"])


def fault_row(label, scheme, r):
    """One fault case's row: how it ended, its iterations, the fault's state
    at the end and, with a conduit, its volume balance."""
    if "summary" not in r or r["summary"]["status"] != "completed":
        reason = r["stderr"].splitlines()[-1] if r["stderr"] else "no summary"
        reason = re.sub(r" \(log: [^)]*\)", "", reason)  # the run's temporary directory
        return f"| {label} | {scheme} | exit {r['exit']}: {reason.removeprefix('biotcontact: error: ')} |||||"
    s = r["summary"]
    steps = max(s["steps"], 1)
    iters = "-" if s["scheme"] == "monolithic" else \
        f"{s['coupling_iterations'] / steps:.1f} / {s['max_iterations_per_step']}"
    f = s["contact"]["faults"]["fault"]
    state = f"{f['closed']:.0f} / {f['stuck']:.0f} / {f['slipping']:.0f}"
    balance = fault_volume_imbalance(s)
    balance = "-" if balance is None else f"{balance:.1e}"
    return (f"| {label} | {scheme} | exit {r['exit']}, converged: {'yes' if s['converged'] else 'NO'} | {iters} "
            f"| {state} | {f['max_slip']:.3e} / {f['max_opening']:.3e} | {balance} | {s['wall_time_s']:.1f} |")


def fault_table(binary):
    lines = ["| case | scheme | end | iterations per step (mean / max) | fault closed / stuck / slipping (m, end) "
             "| max slip / opening (m) | conduit's volume imbalance / well's volume | wall s |",
             "|---|---|---|---|---|---|---|---|"]
    for label, overrides, remedy in FAULT_CASES:
        failed = False
        for scheme, scheme_overrides in FAULT_SCHEMES:
            r = run_case(binary, FAULT, overrides, scheme_overrides)
            failed = failed or r["exit"] != 0
            lines.append(fault_row(label, scheme, r))
            print(lines[-1], flush=True)
        if failed and remedy:
            lines.append(fault_row(label, "remedy: " + ", ".join(remedy), run_case(binary, FAULT, overrides, remedy)))
            print(lines[-1], flush=True)
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--binary", default=os.path.join(ROOT, "build", "biotcontact"))
    parser.add_argument("--faults-only", action="store_true",
                        help="run the fault cases only and rewrite only their section of docs/stability.md")
    args = parser.parse_args()
    path = os.path.join(ROOT, "docs", "stability.md")
    if args.faults_only:
        with open(path) as f:
            text = f.read()
        # the cases run before the file is opened for writing: an interrupted
        # run leaves it as it was
        table = "\n".join(fault_table(args.binary))
        with open(path, "w") as f:
            f.write(text[:text.index("## Faults")] + fault_header() + table + "\n")
        return
    lines = ["| case | scheme | iterations per step (mean / max) | max ratio / gamma | converged "
             "| pressure range (/p0 for Terzaghi, Pa otherwise) | active nodes (end) "
             "| steps whose active set changed within the loop | wall s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for label, scene, overrides in CASES:
        for scheme, scheme_overrides in schemes_for(scene):
            r = run_case(args.binary, scene, overrides, scheme_overrides)
            p0 = undrained_pressure(r.get("summary"), overrides) if "terzaghi" in scene else None
            lines.append(row(label, scheme, r, p0))
            print(lines[-1], flush=True)
    text = ("# Stiff and extreme cases\n\n"
            f"Generated by `/usr/bin/python3 tools/stability_table.py` on {platform.node()} "
            f"({os.cpu_count()} cores), {datetime.date.today()}; the overrides of each case are in the "
            "script. Terzaghi cases run to t = 0.2 unless stated; their pressure range is divided by the "
            "undrained pressure p0, so the physical range is 0 .. 1 (negative values are the known "
            "early-time undershoot of P1-RT0-P0). Ratios are Theorem 1's (single rate) or Theorem 2's "
            "(multirate), resolved ones only.\n\n" + "\n".join(lines) + "\n\n" + fault_header()
            + "\n".join(fault_table(args.binary)) + "\n")
    with open(path, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
