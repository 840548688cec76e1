"""One-way coupling (`[mechanics] pore_pressure` and `alpha`, no [flow]): a
given pore pressure loads the skeleton with the coupled mechanics' term
(alpha p, div v), p in P0 at each step's time. Both tracks, 2D and 3D: a
uniform depletion p = dp t in a homogeneous block, free on rollers (tr eps
= alpha p / K_dr, K_dr = lambda + 2G/d) or laterally confined (tr eps =
alpha p / (lambda + 2G)): the displacement, every cell's volumetric strain
and sigma_v = lambda div u - alpha p to 1e-10 of their largest (P1 holds
the homogeneous strain exactly); the prototype = C++ (1e-10), also for a
pressure varying in space. A contact face with pore_pressure_load = true
takes the given pressure: elastic_contact with a uniform p0 is the face
loaded by the traction p0, its contact pressure 1e6 t - p0."""
import numpy as np

from support import Fields, TRACKS, check, max_difference, run_track, scene, written

G, LAMBDA, ALPHA, DP = 1.0e9, 2.0e9, 0.8, -2.0e6
MECHANICS = f"""[mechanics]
G = {G}
lambda = {LAMBDA}
alpha = {ALPHA}
pore_pressure = "PRESSURE"
[time]
end = 1.0
dt = 0.5
"""
MESHES = {2: '[mesh]\ntype = "rectangle"\nupper = [2.0, 1.0]\ncells = [4, 2]\n',
          3: '[mesh]\ntype = "box"\nupper = [2.0, 1.0, 1.5]\ncells = [2, 2, 2]\n'}
# The rollers of each case: boundary -> the component held at 0.
ROLLERS = {("free", 2): {"left": "x", "bottom": "y"},
           ("free", 3): {"left": "x", "front": "y", "bottom": "z"},
           ("uniaxial", 2): {"left": "x", "right": "x", "bottom": "y"},
           ("uniaxial", 3): {"left": "x", "right": "x", "front": "y", "back": "y", "bottom": "z"}}


def block(case, d, pressure=f"{DP}*t"):
    """The scene of a case: the block, the rollers, the given pressure."""
    rollers = "".join(f"[boundary.{name}]\ndisplacement = {{ {axis} = 0.0 }}\n"
                      for name, axis in ROLLERS[case, d].items())
    return written(MESHES[d] + MECHANICS.replace("PRESSURE", pressure) + rollers)


def strain(case, d, p):
    """The closed form's strain (eps_xx, eps_yy[, eps_zz]) at pore pressure p."""
    if case == "free":
        return np.full(d, ALPHA * p / (2 * G + d * LAMBDA))
    return np.array([0.0] * (d - 1) + [ALPHA * p / (LAMBDA + 2 * G)])


def cell_divergence(fields, t):
    """The divergence of the P1 displacement in every cell: the trace of the
    gradient that maps the cell's edge vectors to the differences of u."""
    d = fields.topology.shape[1] - 1
    x = fields.nodes[fields.topology][:, :, :d]
    u = fields.at("displacement", t)[fields.topology][:, :, :d]
    gradient = np.linalg.solve(x[:, 1:] - x[:, :1], u[:, 1:] - u[:, :1])  # rows d/dx_k of u
    return np.trace(gradient, axis1=1, axis2=2)


def check_closed_form(out, case, d, track):
    fields = Fields(out)
    k_dr = LAMBDA + 2 * G / d
    u_scale = max(np.abs(fields.at("displacement", t)).max() for t in fields.times("displacement"))
    for t in fields.times("displacement")[1:]:
        p = DP * t
        eps = strain(case, d, p)
        exact = fields.nodes[:, :d] * eps
        u_error = np.abs(fields.at("displacement", t)[:, :d] - exact).max() / u_scale
        volumetric = eps.sum()
        if case == "free":
            assert np.isclose(volumetric, ALPHA * p / k_dr, rtol=1e-14)  # the closed form, as stated above
        div_error = np.abs(cell_divergence(fields, t) - volumetric).max() / abs(volumetric)
        sigma_v = LAMBDA * volumetric - ALPHA * p
        sigma_error = np.abs(fields.at("sigma_v", t)[:, 0] - sigma_v).max() / abs(sigma_v)
        check(max(u_error, div_error, sigma_error) < 1e-10,
              f"{track}, {case} {d}D, t = {t:g}: tr(eps) = {volumetric:.6e} = alpha dp "
              f"{'/ K_dr' if case == 'free' else '/ (lambda + 2G)'} (displacement {u_error:.1e}, cell divergence "
              f"{div_error:.1e}, sigma_v {sigma_error:.1e})")


for case, d in ROLLERS:
    path = block(case, d)
    runs = {track: run_track(track, path)[0] for track in TRACKS}
    for track, out in runs.items():
        check_closed_form(out, case, d, track)
    worst = max_difference(runs["C++"], runs["prototype"], ["displacement", "sigma_v"], sort=True)
    check(max(worst.values()) < 1e-10, f"{case} {d}D: the prototype gives the C++ fields "
          f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")

for d in (2, 3):
    path = block("free", d, f"{DP}*t*(1 + x*y/4)")
    runs = {track: run_track(track, path)[0] for track in TRACKS}
    worst = max_difference(runs["C++"], runs["prototype"], ["displacement", "sigma_v"], sort=True)
    check(max(worst.values()) < 1e-10, f"a pore pressure varying in space, {d}D: the prototype gives the C++ "
          f"fields ({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")

# The contact face of elastic_contact, loaded by the given pore pressure p0
# or by the traction p0 (n = (0, -1): -p0 n = (0, p0)).
P0 = 1.0e5  # Pa: below the top load at the first step (2.5e5 Pa), so the block stays on the foundation
with open(scene("elastic_contact")) as f:
    ELASTIC = f.read().replace("nu = 0.3\n", f"nu = 0.3\nalpha = {ALPHA}\npore_pressure = {P0}\n")
CONTACT = "contact = { gap = 0.0, normal = [0.0, -1.0] }"
assert ELASTIC.count(CONTACT) == 1 and f"pore_pressure = {P0}" in ELASTIC, "elastic_contact changed: update this test"
by_pore = written(ELASTIC.replace(CONTACT, CONTACT + "\npore_pressure_load = true"))
by_traction = written(ELASTIC.replace(CONTACT, CONTACT + f"\ntraction = [0.0, {P0}]"))
NAMES = ["displacement", "contact_pressure", "contact_active"]
faces = {}
for track in TRACKS:
    pore, traction = run_track(track, by_pore)[0], run_track(track, by_traction)[0]
    worst = max_difference(pore, traction, NAMES)
    check(max(worst.values()) < 1e-10, f"{track}: the given pore pressure p0 on the contact face acts as the "
          f"traction p0 ({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
    fields = Fields(pore)
    base = np.isclose(fields.nodes[:, 1], 0.0)
    for t in fields.times("contact_pressure")[1:]:
        p_c = fields.at("contact_pressure", t)[base, 0]
        check(np.abs(p_c - (1e6 * t - P0)).max() < 1e-10 * 1e6 * t,
              f"{track}, t = {t:g}: the contact pressure is 1e6 t - p0 = {1e6 * t - P0:g} Pa "
              f"(error {np.abs(p_c - (1e6 * t - P0)).max():.1e})")
    faces[track] = pore
worst = max_difference(faces["C++"], faces["prototype"], NAMES)
check(max(worst.values()) < 1e-10, f"the loaded face: the prototype gives the C++ fields "
      f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
