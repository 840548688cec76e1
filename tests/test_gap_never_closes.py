"""A gap that never closes gives the same result as no contact (to 1e-10
relative to each field's largest value over the run): the SNESVI solve with
inactive bounds reduces to the linear solve."""
import os
import tempfile

import numpy as np
from support import Fields, check, iterations, run, scene, summary

with open(scene("default")) as f:
    text = f.read()
no_contact = os.path.join(tempfile.mkdtemp(), "no_contact.toml")
with open(no_contact, "w") as f:
    f.write("\n".join(line for line in text.splitlines() if not line.startswith("contact =")))

far, _ = run(scene("default"), "--set", "boundary.bottom.contact.gap=1.0")
free, _ = run(no_contact)
check(summary(far)["contact"]["active_nodes"] == 0, "the gap of 1 m never closes")
check("contact" not in summary(free), "the scene without contact has no contact solver")
check([r["iteration"] for r in iterations(far)] == [r["iteration"] for r in iterations(free)],
      "identical coupling iterations in every step")
a, b = Fields(far), Fields(free)
for name in ("displacement", "pressure", "flux"):
    scale = max(np.abs(b.at(name, t)).max() for t in b.times(name))
    worst = max(np.abs(a.at(name, t) - b.at(name, t)).max() for t in b.times(name)) / scale
    check(worst <= 1e-10, f"{name}: max relative difference {worst:.2e} <= 1e-10")
