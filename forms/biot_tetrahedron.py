# FFCx entry point for tetrahedrons: the forms themselves are in biot.py.
import ufl
from biot import FORM_NAMES, build

globals().update(build(ufl.Mesh(ufl.VectorElement("Lagrange", ufl.tetrahedron, 1))))
forms = [globals()[name] for name in FORM_NAMES]
