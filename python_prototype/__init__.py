"""biotcontact, Python prototype: the C++ solver (../cpp) restated with
dolfinx's Python interface, module for module, as an executable
specification: the same scenes, forms (../forms/biot.py), schemes, outputs.
    /usr/bin/python3 -m python_prototype run SCENE.toml --out DIR [--set key=value ...] [PETSc options]
    /usr/bin/python3 -m python_prototype check SCENE.toml [--set ...]
    /usr/bin/python3 -m python_prototype compare DIR_A DIR_B [--tolerance 1e-8]
Reading order, the layers of the data flow (as in cpp/; each module:
docs/layout.md, "Folder by folder"): scene/ -> domain/ -> assembly/ ->
solvers/ -> contact/ -> steps/ -> diagnostics/ -> coupling/ -> output/ ->
simulation.py (the story of a run); output/compare.py compares two runs."""
