"""Theorems 1 and 2 measured on three contact scenes with different gamma
(the default scene, alpha = 0.8, and a compressible M = 1e9): with
L = alpha^2/lambda the ratio of successive ||delta sigma|| stays <= gamma in
every resolved iteration after the first (Theorem 1, single rate), and the
multirate quantity of Theorem 2 (q = 4) is asserted as found: no violation."""
import csv
import os

from support import check, run, scene, summary

SCENES = {"default": [], "alpha=0.8": ["--set", "coupling.alpha=0.8"], "M=1e9": ["--set", "flow.M=1e9"]}
gammas = set()
for name, extra in SCENES.items():
    out, _ = run(scene("default"), *extra)
    s = summary(out)
    gammas.add(round(s["gamma"], 6))
    check(s["L_choice"] == "paper", f"{name}: L = alpha^2/lambda")
    check(s["resolved_ratios"] > 100, f"{name}: {s['resolved_ratios']} ratios measured")
    check(s["contact"]["active_nodes"] > 0, f"{name}: contact is active")
    check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
          f"{name}: Theorem 1, max ratio {s['max_contraction_ratio']:.4f} <= gamma {s['gamma']:.4f}")
    with open(os.path.join(out, "iterations.csv")) as f:
        rows = list(csv.DictReader(f))
    check(all(r["ratio"] == "" for r in rows if r["iteration"] == "1"), f"{name}: no ratio for a first iteration")

    out, _ = run(scene("default"), *extra, "--set", "coupling.scheme=multirate", "--set", "coupling.q=4",
                 "--set", "coupling.max_iterations=2000")
    s = summary(out)
    check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
          f"{name}: Theorem 2 (q = 4), max ratio {s['max_contraction_ratio']:.4f} <= gamma {s['gamma']:.4f}")
check(len(gammas) == 3, f"three different gamma: {sorted(gammas)}")

out, _ = run(scene("terzaghi"))
s = summary(out)
check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
      f"terzaghi (no contact): max ratio {s['max_contraction_ratio']:.4f} <= gamma {s['gamma']:.4f}")
