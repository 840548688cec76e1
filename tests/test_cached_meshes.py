"""The mesh cache (BIOTCONTACT_MESH_CACHE, domain/mesh_cache.h), both tracks:
- a run meshes its .geo once into the cache and a second run reads it (the file
  not written again); both give the fields, iterations and contact sets of a
  run without the cache to the bit, also with mesh.refine = 1 on a curved
  boundary (the cache holds the refined mesh: refining a mesh read back would
  not move its new nodes onto the arc);
- the two tracks key and write the same file (the prototype's run adds none);
- the key sees mesh.size_factor and the text of a file the .geo includes; a
  .geo that names a file otherwise (a word `Merge` without a name in quotes) is
  not kept, and runs;
- a cache directory that cannot be made: exit 2, one line naming the variable."""
import os
import shutil
import subprocess
import tempfile

from support import BINARY, MPI_ENV, PROTOTYPE, ROOT, check, scene, written

TRACKS = {"C++": [BINARY], "prototype": PROTOTYPE}
SHORT = ["--set", "time.end=172800.0"]  # two days of fault_reactivation


def launch(track, command, scene_file, cache, *arguments):
    env = dict(MPI_ENV, BIOTCONTACT_MESH_CACHE=cache)
    return subprocess.run(TRACKS[track] + [command, scene_file, *arguments], capture_output=True, text=True,
                          env=env, cwd=ROOT, timeout=600)


def run(track, scene_file, cache, *arguments):
    out = tempfile.mkdtemp(prefix="run-")
    p = launch(track, "run", scene_file, cache, "--out", out, *arguments)
    check(p.returncode == 0, f"{track}: {os.path.basename(scene_file)} runs ({p.stderr.strip()[-300:]!r})")
    return out


def files(cache):
    """The cache's files and their modification times."""
    return {n: os.stat(os.path.join(cache, n)).st_mtime_ns for n in os.listdir(cache)} if os.path.isdir(cache) else {}


def same(a, b, label):
    c = subprocess.run(PROTOTYPE + ["compare", a, b, "--tolerance", "0"], capture_output=True, text=True, cwd=ROOT)
    check(c.returncode == 0, f"{label}: the same fields, iterations and contact sets to the bit"
          + ("" if c.returncode == 0 else f"\n{c.stdout[-300:]}"))


for track in TRACKS:
    for name, sets in (("fault_reactivation", SHORT), ("hertz", ["--set", "mesh.refine=1"])):
        cache = tempfile.mkdtemp(prefix="cache-")
        plain = run(track, scene(name), "", *sets)
        meshed = run(track, scene(name), cache, *sets)
        kept = files(cache)
        read = run(track, scene(name), cache, *sets)
        check(len(kept) == 1 and files(cache) == kept, f"{track}, {name}: one mesh kept, not written again by the "
              f"run that read it ({kept})")
        same(plain, meshed, f"{track}, {name}: the run that meshed into the cache and the run without")
        same(plain, read, f"{track}, {name}: the run that read the cache and the run without")

# One key and one file for both tracks.
cache = tempfile.mkdtemp(prefix="cache-")
run("C++", scene("fault_reactivation"), cache, *SHORT)
kept = files(cache)
run("prototype", scene("fault_reactivation"), cache, *SHORT)
check(len(kept) == 1 and files(cache) == kept, f"the prototype reads the C++ solver's mesh from the cache ({kept})")

# What the key sees: mesh.size_factor, a file the .geo includes.
for track in TRACKS:
    cache = tempfile.mkdtemp(prefix="cache-")
    folder = tempfile.mkdtemp(prefix="geo-")
    for geo in ("injection_fault3d.geo", "fault3d.geo"):
        shutil.copy(os.path.join(ROOT, "meshes", geo), folder)
    with open(scene("injection_fault3d")) as f:
        text = f.read().replace('file = "injection_fault3d.geo"', f'file = "{folder}/injection_fault3d.geo"')
    scene_file = written(text)
    counts = []
    for change in ("", "size factor", "included file"):
        if change == "included file":
            with open(os.path.join(folder, "fault3d.geo"), "a") as f:
                f.write("\n// an edit the key must see\n")
        p = launch(track, "check", scene_file, cache, *(["--set", "mesh.size_factor=1.5"] if change else []))
        check(p.returncode == 0, f"{track}: check ({p.stderr.strip()[-200:]!r})")
        counts.append(len(files(cache)))
    check(counts == [1, 2, 3], f"{track}: a new mesh kept for mesh.size_factor and for an edit of the included "
          f"file ({counts} files)")
    # A word that names a file gmsh would read, without a name in quotes.
    with open(os.path.join(ROOT, "meshes", "hertz.geo")) as f:
        unknown = written(f.read() + "\n// Merge nothing\n", "hertz.geo")
    with open(scene("hertz")) as f:
        hertz = written(f.read().replace('file = "hertz.geo"', f'file = "{unknown}"'))
    cache = tempfile.mkdtemp(prefix="cache-")
    p = launch(track, "check", hertz, cache)
    check(p.returncode == 0 and not files(cache), f"{track}: a .geo naming a file otherwise is meshed and not kept "
          f"({p.returncode}, {files(cache)})")
    p = launch(track, "check", scene("hertz"), "/proc/mesh_cache")
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 2 and len(lines) == 1 and lines[0].startswith("biotcontact: error: BIOTCONTACT_MESH_CACHE="
                                                                        "/proc/mesh_cache: cannot make the directory"),
          f"{track}: a cache directory that cannot be made: exit 2, one line ({p.stderr.strip()!r})")
