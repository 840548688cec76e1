"""The contact path a run that solves the contact once takes by default
(issue 50, item 5; cpp/contact/contact.cpp, contact_path), on the C++ solver
and the prototype:
- Sneddon's crack (scenes/sneddon.toml): right at the first full Newton
  step, the default stays full and gives the condensed displacement (1e-12);
- Hertz (scenes/hertz.toml): the first full step misses the contact zone, and
  the default goes on condensed from the same start: the condensed fields
  (1e-13) in one Newton step more;
- Phan's frictional crack (phan2d_coarse.geo): stick and slip settle in a
  second full Newton step, taken before condensing; the condensed slip (1e-10);
- an explicit -mechanics_contact_condensed true keeps the condensed path."""
from support import check, fault_fields, max_difference, run_track, scene, summary

CONDENSED = ("-mechanics_contact_condensed", "true")


def mechanics(out):
    return summary(out)["solvers"]["mechanics"]


for track in ("C++", "prototype"):
    default, _ = run_track(track, scene("sneddon"))
    condensed, _ = run_track(track, scene("sneddon"), options=CONDENSED)
    s, c = mechanics(default), mechanics(condensed)
    check("(full)" in s["method"] and s["newton_iterations"] == 1,
          f"sneddon ({track}): the default stays on the full path ({s['method']}, "
          f"{s['newton_iterations']} Newton step)")
    check("condensed" in c["method"], f"sneddon ({track}): -mechanics_contact_condensed true condenses ({c['method']})")
    d = max_difference(default, condensed, ["displacement"])["displacement"]
    check(d <= 1e-12, f"sneddon ({track}): the full path's displacement is the condensed one's to {d:.1e} (1e-12)")

    default, _ = run_track(track, scene("hertz"))
    condensed, _ = run_track(track, scene("hertz"), options=CONDENSED)
    s, c = mechanics(default), mechanics(condensed)
    check("after one full Newton step" in s["method"] and "after" not in c["method"]
          and s["newton_iterations"] == c["newton_iterations"] + 1,
          f"hertz ({track}): the default condenses after one full Newton step ({s['method']}; "
          f"{s['newton_iterations']} Newton steps, condensed alone {c['newton_iterations']})")
    d = max(max_difference(default, condensed, ["displacement", "contact_pressure"]).values())
    check(d <= 1e-13, f"hertz ({track}): the same fields as the condensed path to {d:.1e} (1e-13)")

    phan = ("mesh.file=phan2d_coarse.geo",)
    default, _ = run_track(track, scene("phan"), *phan)
    condensed, _ = run_track(track, scene("phan"), *phan, options=CONDENSED)
    s = mechanics(default)
    check(s["method"].startswith("SNES vinewtonrsls (full)") and s["newton_iterations"] == 2,
          f"phan ({track}): the default solves friction on the full path ({s['method']}, "
          f"{s['newton_iterations']} Newton steps)")
    slips = [fault_fields(out, ("slip",))[2][-1]["slip"] for out in (default, condensed)]
    d = abs(slips[0] - slips[1]).max() / abs(slips[1]).max()
    check(d <= 1e-10, f"phan ({track}): the condensed path's slip to {d:.1e} (1e-10)")
