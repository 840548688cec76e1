"""biotcontact, Python prototype: the C++ solver (../cpp) restated with
dolfinx's Python interface, module for module, as an executable
specification. Same scenes, forms (../forms/biot.py), schemes and outputs.

    /usr/bin/python3 -m python_prototype run SCENE.toml --out DIR [--set key=value ...] [PETSc options]
    /usr/bin/python3 -m python_prototype check SCENE.toml [--set ...]
    /usr/bin/python3 -m python_prototype compare DIR_A DIR_B [--tolerance 1e-8]

Reading order, the folders of the data flow (as in cpp/): scene/ ->
domain/ -> assembly/ (forms, parameters, boundary conditions, loads) ->
solvers/ and contact/ -> steps/ (flow, mechanics, monolithic) -> coupling/
(fixed_stress, single_solve) -> simulation.py (the story of a run) ->
output/ and diagnostics/; diagnostics/compare.py checks two runs against
each other.
"""
