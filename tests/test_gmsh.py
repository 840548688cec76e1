"""A gmsh geometry with named physical groups: the default scene on
meshes/cantilever.geo runs on one and two ranks alike, mesh.size_factor
scales its sizes (the prototype meshes it alike; a .geo's own factor
stays, the scene's multiplying it), and a boundary name the file does not
have is refused naming the groups it has."""
import os
import re
import subprocess
import tempfile

import numpy as np
from support import BINARY, ROOT, Fields, check, iterations, run, run_track, scene, summary, written

with open(scene("default")) as f:
    text = f.read()
mesh = f'[mesh]\ntype = "gmsh"\nfile = "{os.path.join(ROOT, "meshes", "cantilever.geo")}"\n'
text = re.sub(r"\[mesh\]\n(.*\n)*?(?=\n\[)", mesh, text)
path = os.path.join(tempfile.mkdtemp(), "gmsh.toml")
with open(path, "w") as f:
    f.write(text)

one, _ = run(path)
two, _ = run(path, ranks=2)
s = summary(one)
check(s["contact"]["active_nodes"] > 0, f"contact closes on the gmsh mesh ({s['contact']['active_nodes']} nodes)")
check([r["iteration"] for r in iterations(one)] == [r["iteration"] for r in iterations(two)],
      "one and two ranks: identical coupling iterations")
a, b = Fields(one), Fields(two)
t = a.times("displacement")[-1]
x, y = a.sorted_values("displacement", t), b.sorted_values("displacement", t)
check(np.abs(x - y).max() <= 1e-8 * np.abs(x).max(), "one and two ranks: same final displacement")

# mesh.size_factor: every size of the .geo halved, so about 4x the
# triangles; the prototype's gmsh meshes it alike (its fields the C++ ones').
short = "time.end=1.0"
finer = {track: Fields(run_track(track, path, short, "mesh.size_factor=0.5")[0]) for track in ("C++", "prototype")}
cells = [len(f.topology) for f in (a, finer["C++"], finer["prototype"])]
check(3.0 <= cells[1] / cells[0] <= 5.0 and cells[2] == cells[1],
      f"mesh.size_factor = 0.5: {cells[0]} -> {cells[1]} triangles (prototype: {cells[2]})")
t = 1.0
x, y = (finer[k].sorted_values("displacement", t) for k in ("C++", "prototype"))
check(np.abs(x - y).max() <= 1e-8 * np.abs(x).max(),
      f"mesh.size_factor = 0.5: the prototype's displacement the C++ one's ({np.abs(x - y).max():.2e} m)")

# A .geo's own Mesh.MeshSizeFactor stays, the scene's multiplying it.
with open(os.path.join(ROOT, "meshes", "cantilever.geo")) as f:
    geo = f.read() + "Mesh.MeshSizeFactor = 0.5;\n"
own = os.path.join(tempfile.mkdtemp(), "cantilever_half.geo")
with open(own, "w") as f:
    f.write(geo)
halved = text.replace(os.path.join(ROOT, "meshes", "cantilever.geo"), own)
for track, factor, expected in (("C++", 1.0, cells[1]), ("C++", 2.0, cells[0]), ("prototype", 2.0, cells[0])):
    out, _ = run_track(track, written(halved), short, f"mesh.size_factor={factor}")
    n = len(Fields(out).topology)
    check(n == expected, f"{track}: a .geo's own size factor 0.5 times mesh.size_factor = {factor}: {n} triangles "
          f"(expected {expected})")

for command in (["check", path], ["run", path, "--out", tempfile.mkdtemp()]):
    p = subprocess.run([BINARY, *command, "--set", "boundary.middle.pressure=0.0"], capture_output=True, text=True)
    check(p.returncode == 2 and "boundary.middle" in p.stderr and "bottom" in p.stderr and p.stderr.count("\n") == 1,
          f"{command[0]}: unknown physical group refused: {p.stderr.strip()!r}")
