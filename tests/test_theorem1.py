"""Theorem 1 measured: with L = alpha^2/lambda the ratio of successive
||delta sigma_v|| stays <= gamma in every resolved iteration after the first,
with contact active (default scene) and without it (Terzaghi)."""
import csv
import os

from support import check, run, scene, summary

for name, extra in (("default", []), ("terzaghi", [])):
    out, _ = run(scene(name), *extra)
    s = summary(out)
    check(s["L_choice"] == "paper", f"{name}: L = alpha^2/lambda")
    check(s["resolved_ratios"] > 100, f"{name}: {s['resolved_ratios']} ratios measured")
    check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
          f"{name}: max ratio {s['max_contraction_ratio']:.4f} <= gamma {s['gamma']:.4f}")
    if name == "default":
        check(s["contact"]["active_nodes"] > 0, "default: contact is active")
    with open(os.path.join(out, "iterations.csv")) as f:
        rows = list(csv.DictReader(f))
    first = [r for r in rows if r["iteration"] == "1"]
    check(all(r["ratio"] == "" for r in first), f"{name}: no ratio is logged for a first iteration")
