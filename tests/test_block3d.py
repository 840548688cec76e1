"""3D: the tetrahedral gmsh block (scenes/block3d.toml) with contact, on one
and two ranks: Signorini conditions at every node and time, Theorem 1's
bound, and the same iterations and fields on two ranks."""
from support import Foundation, check, check_signorini, iterations, max_difference, run, scene, summary

one, _ = run(scene("block3d"))
two, _ = run(scene("block3d"), ranks=2)
s = summary(one)
check(s["dofs"]["displacement"] > 0 and s["contact"]["active_nodes"] > 0,
      f"3D: {s['dofs']['displacement']} displacement DOFs, {s['contact']['active_nodes']} nodes in contact")
counts = check_signorini(one, 1.0e-4, Foundation(axis=2), label="3D ")
check(counts[-1] >= counts[1] > 0, f"3D: contact set {counts}")
check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
      f"3D: max ratio {s['max_contraction_ratio']:.3f} <= gamma {s['gamma']:.3f}")
check([r["iteration"] for r in iterations(one)] == [r["iteration"] for r in iterations(two)],
      "3D: identical coupling iterations on two ranks")
for name, d in max_difference(one, two, ("displacement", "pressure", "contact_pressure"), sort=True).items():
    check(d <= 1e-8, f"3D: {name} on two ranks, max relative difference {d:.1e} <= 1e-8")
