"""Bad input gets one line naming the key or file and exit status 2: never
an abort, a PETSc trace or a silent NaN."""
import os
import subprocess
import tempfile

from support import BINARY, check, scene

DEFAULT = scene("default")
with open(DEFAULT) as f:
    TEXT = f.read()


def without(key):
    """The default scene with the line that sets `key` removed."""
    path = os.path.join(tempfile.mkdtemp(), "scene.toml")
    with open(path, "w") as f:
        f.write("\n".join(l for l in TEXT.splitlines() if not l.startswith(key + " ")))
    return path


def written(text):
    path = os.path.join(tempfile.mkdtemp(), "scene.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


CASES = [
    ("missing key", without("mu_f"), [], "flow.mu_f"),
    ("missing table", written(TEXT.replace("[time]", "[tiem]")), [], "time"),
    ("unknown key", DEFAULT, ["mechanics.Ee=1.0"], "mechanics.Ee"),
    ("unknown key in a boundary", DEFAULT, ["boundary.top.tracton=[0.0, 1.0]"], "boundary.top.tracton"),
    ("negative E", DEFAULT, ["mechanics.E=-1.0"], "mechanics.E"),
    ("nu = 0.5", DEFAULT, ["mechanics.nu=0.5"], "mechanics.nu"),
    ("nu > 0.5", DEFAULT, ["mechanics.nu=0.7"], "mechanics.nu"),
    ("negative permeability", DEFAULT, ["flow.permeability=-1e-13"], "flow.permeability"),
    ("zero Biot modulus", DEFAULT, ["flow.M=0.0"], "flow.M"),
    ("alpha > 1", DEFAULT, ["coupling.alpha=1.5"], "coupling.alpha"),
    ("dt = 0", DEFAULT, ["time.dt=0.0"], "time.dt"),
    ("dt < 0", DEFAULT, ["time.dt=-0.1"], "time.dt"),
    ("end not a multiple of dt", DEFAULT, ["time.dt=0.7"], "time.dt"),
    ("unknown boundary name", DEFAULT, ["boundary.middle.pressure=0.0"], "boundary.middle"),
    ("missing mesh file", DEFAULT, ["mesh.type=gmsh", "mesh.file=nope.msh"], "nope.msh"),
    ("non-axis foundation normal", DEFAULT, ["boundary.bottom.contact.normal=[0.6, -0.8]"],
     "boundary.bottom.contact.normal"),
    ("negative gap", DEFAULT, ["boundary.bottom.contact.gap=-0.1"], "boundary.bottom.contact.gap"),
    ("bad expression", DEFAULT, ["boundary.top.pressure='x +* 2'"], "boundary.top.pressure"),
    ("unknown scheme", DEFAULT, ["coupling.scheme=undrained"], "coupling.scheme"),
    ("unknown L", DEFAULT, ["coupling.L=optimal"], "coupling.L"),
    ("missing scene file", "no/such/scene.toml", [], "no/such/scene.toml"),
    ("invalid TOML", written("[mesh\ntype = 1\n"), [], "invalid TOML"),
]

for label, path, overrides, key in CASES:
    for command in ("check", "run"):
        args = [BINARY, command, path]
        for o in overrides:
            args += ["--set", o]
        out = tempfile.mkdtemp()
        p = subprocess.run(args + (["--out", out] if command == "run" else []),
                           capture_output=True, text=True, timeout=120)
        lines = p.stderr.strip().splitlines()
        check(p.returncode == 2, f"{label} ({command}): exit status {p.returncode} == 2")
        check(len(lines) == 1 and lines[0].startswith("biotcontact: error:") and key in lines[0],
              f"{label} ({command}): one line naming {key!r}: {p.stderr.strip()!r}")
        check("PETSC ERROR" not in p.stdout + p.stderr and "terminate" not in p.stderr,
              f"{label} ({command}): no PETSc trace or abort")

p = subprocess.run([BINARY, "check", DEFAULT], capture_output=True, text=True)
check(p.returncode == 0 and "ok" in p.stdout, "the shipped default scene passes check")
p = subprocess.run([BINARY, "frobnicate"], capture_output=True, text=True)
check(p.returncode == 2 and p.stderr.count("\n") == 1, "an unknown command is refused in one line")
