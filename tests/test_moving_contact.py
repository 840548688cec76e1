"""A contact set that moves at constant size (both tracks): a poroelastic
slab on a rigid foundation under an uplift bump that steps one node spacing
every 0.25 s, one base node opening and one closing at each jump while the
count stays 28. Adaptive steps take every step with a change as a contact
break; q = "auto" computes windows over a jump again with q = 1, and no
window of q > 1 spans a change node by node (ActiveSet), where a
comparison of counts would see none. An uplift patch moving smoothly checks
that the split's coupling tolerance, tied to the step, lets adaptive steps
follow sharp load edges (the monolithic solve's steps, none forced).
Numbers: docs/verification.md, "What each test verifies"."""
from support import TRACKS, Fields, check, run_track, set_changes, summary, windows, written

JUMP, NODE = 0.25, 0.25  # the bump's period and step (the mesh's node spacing)
centre = "(" + " : ".join(f"t <= {JUMP * (k + 1)} ? {2.5 + NODE * k}" for k in range(8)) + " : 4.5)"
bump = f"(abs(x - {centre}) < 1 ? 6e3 * cos(pi * (x - {centre}) / 2)^2 : 0)"
SCENE = written(f"""
[scene]
name = "moving_contact"
description = "A slab on a rigid foundation under an uplift bump stepping along its top"
[mesh]
type = "rectangle"
lower = [0.0, 0.0]
upper = [10.0, 1.0]
cells = [40, 4]
[mechanics]
E = 1.0e9
nu = 0.2
[flow]
M = 1.0e11
c_f = 4.4e-10
phi0 = 0.2
mu_f = 1.0e-3
permeability = 1.0e-13
[coupling]
alpha = 1.0
scheme = "fixed-stress"
L = "kdr"
tolerance = 1e-8
max_iterations = 1000
[time]
end = 2.0
dt = {JUMP}
[boundary.left]
displacement = {{ x = 0.0 }}
[boundary.right]
displacement = {{ x = 0.0 }}
[boundary.top]
traction = [0.0, "-2e3 + {bump}"]
pressure = 0.0
[boundary.bottom]
contact = {{ gap = 0.0, normal = [0.0, -1.0] }}
""")


def contact_sets(out):
    """The contact_active field (node by node) at every written time."""
    run = Fields(out)
    return [run.at("contact_active", t).ravel() > 0.5 for t in run.times("contact_active")]


def changes(sets):
    """Steps whose contact set differs from the one before, node by node,
    and steps whose count of active nodes does."""
    pairs = list(zip(sets, sets[1:]))
    return sum((a != b).any() for a, b in pairs), sum(a.sum() != b.sum() for a, b in pairs)


ADAPTIVE = ["time.scheme=bdf2", "time.adaptive.tolerance=1e-2", "time.dt=0.01"]
AUTO = ["coupling.scheme=multirate", "coupling.q=auto", "coupling.q_tolerance=0.1", f"time.dt={JUMP / 8}"]
results = {}
for track in TRACKS:
    fixed, _ = run_track(track, SCENE)
    sets = contact_sets(fixed)
    check([s.sum() for s in sets[1:]] == [28] * 8 and all((a != b).sum() == 2 for a, b in zip(sets[1:], sets[2:])),
          f"{track}: fixed steps of {JUMP}: 28 nodes touch after the first step, and at every jump one node "
          f"opens and one closes ({[int(s.sum()) for s in sets]})")

    adaptive, _ = run_track(track, SCENE, *ADAPTIVE)
    a = summary(adaptive)["adaptive"]
    by_node, by_count = changes(contact_sets(adaptive))
    check(a["contact_breaks"] == by_node == 8 and by_count == 1 and a["forced_steps"] == 0,
          f"{track}: adaptive steps: {a['contact_breaks']} contact breaks, one per step whose set changed node by "
          f"node ({by_node}; the count changed in {by_count}), none forced ({summary(adaptive)['steps']} steps)")

    auto, _ = run_track(track, SCENE, *AUTO)
    w = summary(auto)["window_steps"]
    history = windows(auto, JUMP / 8)
    spanned = set_changes(auto, JUMP / 8, history)
    check(w["q_rejections"] > 0 and w["largest_q"] > 1 and all(n == 28 for _, n in history),
          f"{track}: q = auto: {w['q_rejections']} windows computed again with q = 1 for a change of the contact "
          f"set at an unchanged count (28 at every window's end), windows up to q = {w['largest_q']}")
    check(not spanned, f"{track}: q = auto: no window of q > 1 spans a change of the contact set, node by node "
          f"(windows that do: {spanned}; q per window: {[q for q, _ in history]})")
    results[track] = (summary(adaptive)["steps"], [a[k] for k in ("rejected_steps", "contact_breaks")],
                      summary(auto)["steps"], w)

check(results["C++"] == results["prototype"],
      f"prototype = C++: adaptive steps and breaks, q = auto windows ({results['C++']})")

SHARP = written(open(SCENE).read().replace(f'"-2e3 + {bump}"', '"-2e3 + 4e3 * (abs(x - 2.5 - t) < 1 ? 1 : 0)"'))
SHARP_SETTINGS = ["time.end=0.35", "time.scheme=bdf2", "time.adaptive.tolerance=1e-4", "time.dt=0.001"]
monolithic, _ = run_track("C++", SHARP, *SHARP_SETTINGS, "coupling.scheme=monolithic")
steps = summary(monolithic)["steps"]
split = {}
for track in TRACKS:
    out, _ = run_track(track, SHARP, *SHARP_SETTINGS)
    s = summary(out)
    split[track] = (s["steps"], s["coupling_iterations"], s["adaptive"]["rejected_steps"])
    check(s["adaptive"]["forced_steps"] == 0 and abs(s["steps"] - steps) <= 0.02 * steps,
          f"{track}: sharp moving patch, adaptive split: {s['steps']} steps ({s['adaptive']['rejected_steps']} rejected, "
          f"none forced, smallest {s['adaptive']['smallest_step']:.2e}) against the monolithic solve's {steps}")
check(split["C++"] == split["prototype"], f"prototype = C++ on the sharp patch: steps, iterations, rejections "
      f"{split['C++']}")
