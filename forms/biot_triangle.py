# FFCx entry point for triangles: the forms themselves are in biot.py.
import ufl
from biot import FORM_NAMES, build

globals().update(build(ufl.Mesh(ufl.VectorElement("Lagrange", ufl.triangle, 1))))
forms = [globals()[name] for name in FORM_NAMES]
