"""Each scene allocates only the physics it has: a pure Darcy scene has no
displacement unknowns, a pure elastic contact scene no flow unknowns, a
scene without contact no contact solver. Each is checked against physics."""
import numpy as np
from support import Fields, check, run, scene, summary

# Pure Darcy: at steady state p is linear and the flux k/mu_f * dp/length.
out, _ = run(scene("darcy"))
s = summary(out)
fields = Fields(out)
check(set(s["dofs"]) == {"pressure", "flux"} and s["mechanics_solves"] == 0,
      "darcy: no displacement unknowns, no mechanics solve")
check(set(fields.series) == {"pressure", "flux"}, "darcy: only pressure and flux are written")
t = fields.times("pressure")[-1]
p_exact = 1e5 * (1 - fields.cells[:, 0] / 10.0)
p_err = np.abs(fields.at("pressure", t)[:, 0] - p_exact).max() / 1e5
z_err = np.abs(fields.at("flux", t)[:, 0] - 1e-12 / 1e-3 * 1e5 / 10.0).max() / (1e-9 * 1e4)
check(p_err < 1e-3, f"darcy: steady pressure linear (max error {p_err:.1e} of the drop)")
check(z_err < 1e-3, f"darcy: flux = k/mu_f dp/L (max error {z_err:.1e})")
check("mechanics" in s["left_out"], "darcy: the log says mechanics was left out")

# Pure elastic contact: no flow unknowns; the foundation carries the load.
out, _ = run(scene("elastic_contact"))
s = summary(out)
fields = Fields(out)
check(set(s["dofs"]) == {"displacement"} and s["flow_solves"] == 0, "elastic contact: no flow unknowns")
check("pressure" not in fields.series and "flux" not in fields.series, "elastic contact: no flow fields written")
check(s["contact"]["active_nodes"] == s["contact"]["contact_nodes"] == 9 and s["contact"]["min_contact_pressure"] >= -1e-8 * s["contact"]["max_contact_pressure"],
      f"elastic contact: {s['contact']['active_nodes']} active nodes, contact pressure >= 0")
check("flow" in s["left_out"], "elastic contact: the log says flow was left out")
c = s["contact"]
check(abs(c["max_contact_pressure"] - 1e6) <= 1e-8 * 1e6 and abs(c["min_contact_pressure"] - 1e6) <= 1e-8 * 1e6,
      f"elastic contact: contact pressure = traction 1e6 at every node ({c['min_contact_pressure']:.9e} .. {c['max_contact_pressure']:.9e})")
