"""Material regions (issue 22, items 1 and 2), both tracks: `[region.NAME]`
replaces material values in a gmsh physical group or where `where` holds;
every form, and the fixed-stress L, takes them cell by cell. Two regions
with the scene's values give the homogeneous run (1e-12, the same
iterations); physical groups and `where` give the same run; a layered
column settles by sum q h_i / (lambda_i + 2 G_i) (1e-9); a closed box fed
by a well with two regions keeps its fluid content equal to the injected
volume (split and monolithic); no contraction ratio above the cells'
largest gamma; the summary lists the regions; prototype = C++ (1e-12)."""
import subprocess
import tempfile

import numpy as np

from support import (PROTOTYPE, ROOT, TRACKS, Fields, check, fluid_content, iterations, max_difference, poroelastic_column,
                     run_track, scene, summary, written)

FIELDS = ["pressure", "displacement", "sigma_v", "contact_pressure"]
SAME = """[region.upper]
where = "y > 0.5"
E = 1.0e9
[region.lower]
where = "y < 0.5"
nu = 0.2
alpha = 1.0
permeability = 1.0e-13
M = 1.0e11
"""


def with_regions(text, regions):
    """A scene text with region tables added before its first boundary."""
    head, tail = text.split("[boundary.", 1)
    return head + regions + "\n[boundary." + tail


def same_run(a, b, label, fields=FIELDS):
    """The same coupling iterations and fields to 1e-12."""
    ia, ib = ([row["step"] for row in iterations(out)] for out in (a, b))
    check(ia == ib, f"{label}: the same coupling iterations at every step ({len(ia)} and {len(ib)})")
    worst = max(max_difference(a, b, fields).values())
    check(worst <= 1e-12, f"{label}: the same fields (largest difference {worst:.1e})")


with open(scene("default")) as f:
    DEFAULT = f.read()
regional = written(with_regions(DEFAULT, SAME))
runs = {}
for track in TRACKS:
    for scheme in ("fixed-stress", "monolithic"):
        sets = ("time.end=2.4", f"coupling.scheme={scheme}")
        alone, _ = run_track(track, scene("default"), *sets)
        split, _ = run_track(track, regional, *sets)
        same_run(alone, split, f"{track}, {scheme}: two regions of the scene's own values")
        regions = summary(split)["regions"]
        check(regions["upper"]["cells"] == regions["lower"]["cells"] == 320 and regions["no region"]["cells"] == 0,
              f"{track}, {scheme}: the summary lists the regions with their cells ({regions})")
        runs[track, scheme] = split

# Rollers on the sides of a column, its base held vertically.
ROLLERS = """[boundary.left]
displacement = { x = 0.0 }
[boundary.right]
displacement = { x = 0.0 }
[boundary.bottom]
displacement = { y = 0.0 }
"""

# The layered column: gmsh groups and `where` select the same cells.
COLUMN = """[scene]
name = "layers"
description = "a layered column consolidating under a load"
[mesh]
{mesh}
[mechanics]
G = 2.0e9
lambda = 1.0e9
[flow]
M = 1.0e10
mu_f = 1.0e-3
permeability = 1.0e-12
[coupling]
alpha = 1.0
tolerance = 1e-12
max_iterations = 500
[time]
end = 2.0e4
dt = 1.0e3
{rollers}[boundary.top]
traction = [0.0, -{load}]
pressure = 0.0
{regions}"""
LOAD = 1.0e6
LAYERS = {"underburden": (0.0, 3.0, 4.0e9, 3.0e9), "reservoir": (3.0, 6.0, 5.0e8, 2.0e8),
          "caprock": (6.0, 10.0, 8.0e9, 6.0e9)}  # name: (bottom, top, G, lambda)


def layer_tables(where):
    text = ""
    for name, (bottom, top, G, lmbda) in LAYERS.items():
        text += f"[region.{name}]\nG = {G}\nlambda = {lmbda}\npermeability = {1e-12 if name != 'reservoir' else 1e-13}\n"
        if where:
            text += f'where = "y > {bottom} && y < {top}"\n'
    return text


def column(mesh, where):
    """The layered column on `mesh`, its layers the gmsh groups or (`where`) expressions."""
    return written(COLUMN.format(mesh=mesh, load=LOAD, regions=layer_tables(where), rollers=ROLLERS))


GMSH = f'type = "gmsh"\nfile = "{ROOT}/meshes/layers.geo"'
RECTANGLE = 'type = "rectangle"\nupper = [1.0, 10.0]\ncells = [2, 30]'
settlement = sum(LOAD * (top - bottom) / (lmbda + 2 * G) for bottom, top, G, lmbda in LAYERS.values())
for track in TRACKS:
    groups, _ = run_track(track, column(GMSH, False))
    selected, _ = run_track(track, column(GMSH, True))
    same_run(groups, selected, f"{track}: gmsh groups and where select the same layers", FIELDS[:3])
    cells = summary(groups)["regions"]
    check(all(cells[name]["cells"] > 0 for name in LAYERS) and cells["no region"]["cells"] == 0,
          f"{track}: every cell of the gmsh column in its layer ({cells})")
    for label, out in (("gmsh", groups), ("rectangle", run_track(track, column(RECTANGLE, True))[0])):
        fields = Fields(out)
        t = fields.times("displacement")[-1]
        top = np.isclose(fields.nodes[:, 1], 10.0)
        u = -fields.at("displacement", t)[top, 1]
        error = np.max(np.abs(u - settlement)) / settlement
        check(error < 1e-9, f"{track}, {label}: the consolidated settlement {u.mean():.6e} m is sum q m_v,i h_i "
              f"= {settlement:.6e} m (relative error {error:.1e})")

# A closed poroelastic box fed by a well, two materials.
S = 1.0e-9
BOX = f"""[scene]
name = "box"
description = "a closed poroelastic box fed by a well"
[mesh]
type = "rectangle"
upper = [2.0, 10.0]
cells = [4, 20]
[flow]
M = {1 / S}
mu_f = 1.0e-3
permeability = 1.0e-12
{poroelastic_column("bottom")}
[time]
end = 3.0e3
dt = 1.0e3
[well.injector]
position = [1.0, 3.0]
rate = 2.0e-6
[region.upper]
where = "y > 5"
M = {1 / (4 * S)}
alpha = 0.5
permeability = 1.0e-14
G = 3.0e9
"""
box = written(BOX)
for track in TRACKS:
    for scheme in ("fixed-stress", "monolithic"):
        out, _ = run_track(track, box, f"coupling.scheme={scheme}")
        fields = Fields(out)
        upper = fields.cells[:, 1] > 5
        storage, alpha = np.where(upper, 4 * S, S), np.where(upper, 0.5, 0.8)
        worst = max(abs(np.sum(fluid_content(fields, t, storage, alpha)) - 2.0e-6 * t) / (2.0e-6 * t)
                    for t in fields.times("pressure")[1:])
        check(worst < 1e-10, f"{track}, {scheme}: the fluid content of the two materials equals the injected "
              f"volume at every step (largest relative difference {worst:.1e})")
        runs[track, "box " + scheme] = out

# Local conservation (RT0 x P0): the mass balance holds in every cell, since
# the indicator of each cell is a test function of the pressure space. The
# prototype's run of the box, its flux divergence per cell from the RT0 flux.
out = tempfile.mkdtemp(prefix="local-")
prototype_run = subprocess.run(["/usr/bin/python3", "-c", f"""
import sys, ufl
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc
from dolfinx import fem
sys.path.insert(0, {ROOT!r})
PETSc.Log.begin()  # as the prototype's command line does: its summary reads the log
from python_prototype.scene.scene import read_scene
from python_prototype.simulation import Simulation
sim = Simulation(read_scene({box!r}), sys.argv[1], MPI.COMM_WORLD)
assert sim.run() == 0
Q, mesh = sim.F["Q"], sim.domain.mesh
divergence = fem.assemble_vector(fem.form(ufl.div(ufl.split(sim.scheme.steps()[0].w)[0]) * ufl.TestFunction(Q) * ufl.dx)).array
cells = np.arange(mesh.topology.index_map(2).size_local)
rows = np.asarray(mesh.topology.original_cell_index)[cells]
values = np.empty(len(cells))
values[rows] = divergence[[Q.dofmap.cell_dofs(c)[0] for c in cells]]
np.save(sys.argv[1] + "/divergence.npy", values)
""", out], capture_output=True, text=True, cwd=ROOT, timeout=600)
check(prototype_run.returncode == 0, "prototype: the box run in process"
      + ("" if prototype_run.returncode == 0 else f" ({prototype_run.stderr[-300:]})"))
fields = Fields(out)
times = fields.times("pressure")
upper = fields.cells[:, 1] > 5
storage, alpha = np.where(upper, 4 * S, S), np.where(upper, 0.5, 0.8)
change = fluid_content(fields, times[-1], storage, alpha) - fluid_content(fields, times[-2], storage, alpha)
touching = np.any(np.linalg.norm(fields.nodes[fields.topology] - [1.0, 3.0], axis=2) < 1e-12, axis=1)
source = np.where(touching, 2.0e-6 / touching.sum(), 0.0)
dt = times[-1] - times[-2]
residual = np.abs(change + dt * np.load(out + "/divergence.npy") - dt * source) / (2.0e-6 * dt)
check(residual.max() < 1e-10, f"prototype: the mass balance holds in each of the {len(residual)} cells "
      f"(largest residual {residual.max():.1e} of the injected volume of the step)")
c = subprocess.run(PROTOTYPE + ["compare", runs["C++", "box fixed-stress"], out, "--tolerance", "1e-12"],
                   capture_output=True, text=True, cwd=ROOT)
check(c.returncode == 0, "C++ gives the fields of that run to 1e-12: its cells balance alike")

# Body forces of their own: a region with the scene's body force gives the
# run with that force alone (cell by cell instead of at the nodes); a column
# of two densities under its own weight settles by
#   s = (1/(lambda + 2G)) int_0^H sigma(y) dy,
# the weight above each depth over the confined modulus. The problem is one
# dimensional and the density jumps at a mesh line: P1 is exact at the
# nodes (as linear elements in 1D), on every mesh.
GRAVITY = "body_force = [0.0, -2.0e4]\n"
with_force = DEFAULT.replace("nu = 0.2\n", "nu = 0.2\n" + GRAVITY, 1)
for track in TRACKS:
    alone, _ = run_track(track, written(with_force), "time.end=2.4")
    cellwise, _ = run_track(track, written(with_regions(with_force, '[region.upper]\nwhere = "y > 0.5"\n' + GRAVITY)),
                            "time.end=2.4")
    same_run(alone, cellwise, f"{track}: a region's own body force equal to the scene's")
WEIGHT = """[scene]
name = "weight"
description = "a column of two densities under its own weight"
[mesh]
type = "rectangle"
upper = [1.0, 10.0]
cells = [1, {rows}]
[mechanics]
G = 1.0e9
lambda = 1.0e9
body_force = [0.0, -2.0e4]
[time]
end = 1.0
dt = 1.0
{rollers}[region.upper]
where = "y > 5"
body_force = [0.0, -3.0e4]
"""
settlement = (3.0e4 * 12.5 + 5 * 3.0e4 * 5 + 2.0e4 * 12.5) / 3.0e9
for track in TRACKS:
    errors = []
    for rows in (10, 20, 40):
        fields = Fields(run_track(track, written(WEIGHT.format(rows=rows, rollers=ROLLERS)))[0])
        top = np.isclose(fields.nodes[:, 1], 10.0)
        errors.append(np.max(np.abs(-fields.at("displacement", 1.0)[top, 1] - settlement)) / settlement)
    check(max(errors) < 1e-12, f"{track}: the settlement under two densities is the closed form "
          f"(errors {', '.join(f'{e:.1e}' for e in errors)} at 10, 20, 40 rows)")

# Contrasting regions: Theorem 1 with the cell-wise coefficients.
CONTRAST = """[region.stiff]
where = "x > 5"
E = 2.0e10
nu = 0.3
alpha = 0.6
M = 1.0e10
permeability = 1.0e-15
"""
for track in TRACKS:
    out, _ = run_track(track, written(with_regions(DEFAULT, CONTRAST)), "time.end=2.4")
    s = summary(out)
    gammas = {name: region["gamma"] for name, region in s["regions"].items()}
    check(s["gamma"] == max(gammas.values()) and s["resolved_ratios"] > 0,
          f"{track}: gamma is the largest of the regions' ({gammas})")
    check(s["bound_violations"] == 0, f"{track}: no resolved ratio above the largest gamma "
          f"(largest ratio {s['max_contraction_ratio']:.3f}, gamma {s['gamma']:.3f}, "
          f"{s['resolved_ratios']} ratios)")
    runs[track, "contrast"] = out

# Two ranks: the regions of gmsh groups reach every rank (rank 0 reads the
# file), and `where` is evaluated on each rank's cells; the contact sets and
# fields of one rank. Output rows are in input order on any partition.
gmsh_column = column(GMSH, False)
contrast = written(with_regions(DEFAULT, CONTRAST))
for track in TRACKS:
    for label, scene_file, end in (("gmsh column", gmsh_column, "5.0e3"), ("contrasting regions", contrast, "2.4")):
        one, _ = run_track(track, scene_file, f"time.end={end}")
        two, _ = run_track(track, scene_file, f"time.end={end}", ranks=2)
        names = ["pressure", "displacement"] + (["contact_active"] if "contrast" in label else [])
        worst = max_difference(one, two, names)
        check(max(worst.values()) < 1e-8, f"{track}, {label}: 2 ranks give the fields and contact sets of one "
              f"({', '.join(f'{k} {v:.1e}' for k, v in worst.items())})")
        check(summary(one)["regions"] == summary(two)["regions"], f"{track}, {label}: the same regions on 2 ranks")

for key in ("fixed-stress", "monolithic", "box fixed-stress", "box monolithic", "contrast"):
    c = subprocess.run(PROTOTYPE + ["compare", runs["C++", key], runs["prototype", key], "--tolerance", "1e-12"],
                       capture_output=True, text=True, cwd=ROOT)
    check(c.returncode == 0, f"{key}: the prototype gives the C++ fields to 1e-12 {c.stdout[-300:]}")
