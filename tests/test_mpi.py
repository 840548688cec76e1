"""mpirun -n 2 gives the same coupling iterations and, within 1e-8 relative,
the same fields as one rank (default contact scene)."""
import numpy as np
from support import Fields, check, iterations, run, scene, summary

one, _ = run(scene("default"))
two, _ = run(scene("default"), ranks=2)
check(summary(two)["mpi_ranks"] == 2, "the second run used two ranks")
check([r["iteration"] for r in iterations(one)] == [r["iteration"] for r in iterations(two)],
      "identical coupling iterations in every step")
check(summary(one)["contact"]["active_nodes"] == summary(two)["contact"]["active_nodes"],
      "identical final active set size")
a, b = Fields(one), Fields(two)
for name in ("displacement", "pressure", "flux", "contact_pressure"):
    worst = 0.0
    for t in a.times(name):
        x, y = a.sorted_values(name, t), b.sorted_values(name, t)
        worst = max(worst, np.abs(x - y).max() / max(np.abs(x).max(), 1e-300))
    check(worst <= 1e-8, f"{name}: max relative difference {worst:.2e} <= 1e-8")
