"""The contact path a run that solves the contact once takes by default
(issue 50, item 5; cpp/contact/contact.cpp, contact_path), on the C++ solver
and the prototype:
- Sneddon's pressurised crack (scenes/sneddon.toml, the mechanics alone,
  one step): its active set is right at once, and the whole system's first
  Newton step solves it: the default stays on the full path (one Newton
  step) and gives the condensed path's displacement to 1e-12;
- the Hertz contact (scenes/hertz.toml): its first full Newton step does
  not find the contact zone, and the default goes on condensed from the
  same start: the condensed path's fields to 1e-13, with one Newton step
  more than the condensed path alone;
- an explicit -mechanics_contact_condensed true keeps the condensed path."""
from support import check, max_difference, run_track, scene, summary

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
