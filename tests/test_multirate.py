"""Multirate fixed stress (alg. "Multirate fixed-stress split") on the default
scene for q = 2, 4, 8, 16: it converges in every window, takes 48/q
mechanics steps, each coupling iteration costs q flow solves and one
mechanics solve, and Theorem 2's ratio stays <= gamma (as measured; a
violation would be a finding, see docs/theory.md, "Findings")."""
from support import check, run, scene, summary

single = summary(run(scene("default"))[0])
fine_steps = single["steps"]
for q in (2, 4, 8, 16):
    out, _ = run(scene("default"), "--set", "coupling.scheme=multirate", "--set", f"coupling.q={q}",
                 "--set", "coupling.max_iterations=2000")
    s = summary(out)
    check(s["converged"] and s["steps"] == fine_steps // q and s["fine_steps"] == fine_steps,
          f"q={q}: converged, {s['steps']} mechanics steps for {fine_steps} flow steps")
    check(s["flow_solves"] == q * s["mechanics_solves"] == q * s["coupling_iterations"],
          f"q={q}: {s['mechanics_solves']} mechanics solves, {s['flow_solves']} flow solves "
          f"(single rate: {single['mechanics_solves']} and {single['flow_solves']})")
    check(s["bound_violations"] == 0 and s["max_contraction_ratio"] <= s["gamma"] * (1 + 1e-6),
          f"q={q}: Theorem 2 ratio {s['max_contraction_ratio']:.4f} <= gamma {s['gamma']:.4f}")
    check(s["contact"]["active_nodes"] == single["contact"]["active_nodes"],
          f"q={q}: the same final contact set as single rate ({s['contact']['active_nodes']} nodes)")
