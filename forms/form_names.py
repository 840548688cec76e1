"""Writes the C++ table of the forms of biot.py: an X-macro over their names,
BIOTCONTACT_FORMS(X), which cpp/assembly/forms.h expands into the fields of
CompiledForms and forms.cpp into FFCx's form_biot_<cell>_<name> objects.

Usage (run by the build): form_names.py OUTPUT.h
"""
import sys

import ufl
from biot import build, form_names

names = form_names(build(ufl.Mesh(ufl.VectorElement("Lagrange", ufl.triangle, 1))))
lines = ["// Generated from forms/biot.py by forms/form_names.py at build time.",
         "#pragma once", "", "#define BIOTCONTACT_FORMS(X) \\"]
lines += [f"  X({name}) \\" for name in names]
lines += ["", ""]
text = "\n".join(lines)
# Written only when it changes: the sources that include it are not rebuilt
# for an edit of biot.py that adds no form.
try:
    with open(sys.argv[1]) as f:
        unchanged = f.read() == text
except FileNotFoundError:
    unchanged = False
if not unchanged:
    with open(sys.argv[1], "w") as f:
        f.write(text)
