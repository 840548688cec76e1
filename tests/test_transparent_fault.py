"""Flow across a transparent fault (issue 37), on the C++ solver and the
prototype: a crack of half-length 1 inclined at 30 degrees inside the square
[-2, 2]^2 (an unstructured gmsh mesh), the flow driven from the left side
(p = 1) to the right (p = 0), so it crosses the crack. "transparent" ties
the two faces' RT0 fluxes (z- = -(c+/c-) z+, assembly/tied_dofs: the unsplit
mesh's flux space), so the flow equals the run without the fault to 1e-12, on
1 and 2 ranks; "sealing" (no-flow faces) must change it. Coupled (the
frictionless crack slides under the top load), the split equals the monolithic
solve to the coupling tolerance with the flux tied in both, an iterative solve
the direct one, and the prototype the C++ solver."""
from support import INCLINED_CRACK_GEO as GEO, check, max_difference, run_track, written

FLOW = """[mesh]
type = "gmsh"
file = "crack.geo"
dimension = 2
[flow]
M = 16.0
mu_f = 1.0
permeability = 1.5
initial_pressure = 0.0
[time]
end = 0.2
dt = 0.05
[boundary.left]
pressure = 1.0
{left}
[boundary.right]
pressure = 0.0
{right}
"""
MECHANICS = """[mechanics]
G = 3.0
lambda = 2.0
[coupling]
alpha = 0.6
L = "paper"
tolerance = 1e-12
scheme = "{scheme}"
[boundary.bottom]
displacement = {{ x = 0.0, y = 0.0 }}
[boundary.top]
traction = [0.0, -1.0]
"""
FAULT = """[fault.crack]
normal = [-0.5, 0.8660254037844386]
"""
FLOW_FIELDS = ["pressure", "flux"]
COUPLED_FIELDS = ["pressure", "flux", "displacement"]


def scene(fault="", scheme=None, extra=""):
    roller = "displacement = { x = 0.0 }" if scheme else ""
    text = FLOW.format(left=roller, right=roller) + (MECHANICS.format(scheme=scheme) if scheme else "")
    path = written(text + fault + extra)
    with open(path.replace("scene.toml", "crack.geo"), "w") as f:
        f.write(GEO)
    return path


runs = {}
for track in ("C++", "prototype"):
    none, _ = run_track(track, scene())
    transparent, _ = run_track(track, scene(FAULT))
    sealing, _ = run_track(track, scene(FAULT + 'flow = "sealing"\n'))
    same = max_difference(transparent, none, FLOW_FIELDS)
    check(max(same.values()) <= 1e-12, f"{track}: the transparent fault's flow equals the unsplit mesh's: {same} "
          "(limit 1e-12)")
    sealed = max_difference(sealing, none, FLOW_FIELDS)
    check(sealed["pressure"] >= 1e-2, f"{track}: a sealing fault changes the flow: pressure by {sealed['pressure']:.3g}")
    split, _ = run_track(track, scene(FAULT, "fixed-stress"))
    monolithic, _ = run_track(track, scene(FAULT, "monolithic"))
    coupled = max_difference(split, monolithic, COUPLED_FIELDS)
    check(max(coupled.values()) <= 1e-9, f"{track}: with the flux tied across the fault the split equals the "
          f"monolithic solve: {coupled} (coupling tolerance 1e-12)")
    runs[track] = (transparent, split, monolithic)

two, _ = run_track("C++", scene(FAULT), ranks=2)
ranks = max_difference(runs["C++"][0], two, FLOW_FIELDS, sort=True)
check(max(ranks.values()) <= 1e-12, f"C++: 2 ranks equal 1 rank: {ranks} (limit 1e-12)")
iterative, _ = run_track("C++", scene(FAULT, "monolithic", '[solver]\nmonolithic = "iterative"\n'))
solvers = max_difference(runs["C++"][2], iterative, COUPLED_FIELDS)
check(max(solvers.values()) <= 1e-8, f"C++: the iterative monolithic solve equals the direct one: {solvers} "
      "(limit 1e-8, the Krylov tolerance)")
for k, name in enumerate(("flow", "fixed-stress", "monolithic")):
    fields = FLOW_FIELDS if k == 0 else COUPLED_FIELDS
    tracks = max_difference(runs["C++"][k], runs["prototype"][k], fields)
    check(max(tracks.values()) <= 1e-10, f"{name}: the prototype equals the C++ solver: {tracks} (limit 1e-10)")
