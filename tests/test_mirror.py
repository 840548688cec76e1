"""The prototype mirrors the C++ solver file for file: every module of cpp/
(a header, a source or both) has a Python module of the same folder and name
in python_prototype/, and every Python module a C++ twin, except the few
listed below with the reason. The folders follow the data flow (scene ->
domain -> assembly -> solvers and contact -> steps -> coupling -> output and
diagnostics) on both tracks: docs/layout.md."""
import os

from support import ROOT, check

# Modules with no twin, and why.
CPP_ONLY = {}
PROTOTYPE_ONLY = {
    "output/compare": "compares the two tracks' outputs; C++ has nothing to compare with",
}
# The entry points: the same role under each language's name.
ENTRY = {"main": "__main__"}
FOLDERS = ["scene", "domain", "assembly", "solvers", "contact", "steps", "coupling", "output", "diagnostics"]


def modules(top, suffixes):
    found = set()
    for folder, _, files in os.walk(top):
        for f in files:
            stem, suffix = os.path.splitext(f)
            if suffix in suffixes and stem != "__init__":
                found.add(os.path.relpath(os.path.join(folder, stem), top))
    return found


cpp = {ENTRY.get(m, m) for m in modules(os.path.join(ROOT, "cpp"), {".h", ".cpp"})}
prototype = modules(os.path.join(ROOT, "python_prototype"), {".py"})

for folder in FOLDERS:
    check(os.path.isdir(os.path.join(ROOT, "cpp", folder))
          and os.path.isdir(os.path.join(ROOT, "python_prototype", folder)), f"{folder}/ on both tracks")
missing = sorted(cpp - prototype - set(CPP_ONLY))
check(not missing, f"every C++ module has a Python twin (missing: {missing})")
extra = sorted(prototype - cpp - set(PROTOTYPE_ONLY))
check(not extra, f"every Python module has a C++ twin (missing: {extra})")
stale = sorted((set(CPP_ONLY) - cpp) | (set(PROTOTYPE_ONLY) - prototype) | (set(CPP_ONLY) & prototype)
               | (set(PROTOTYPE_ONLY) & cpp))
check(not stale, f"the lists of modules without a twin are current (stale: {stale})")
outside = sorted(m for m in cpp | prototype if os.path.dirname(m) not in FOLDERS + [""])
check(not outside, f"every module lies in a folder of the data flow (outside: {outside})")
