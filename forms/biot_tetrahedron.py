# FFCx entry point for tetrahedrons: the forms themselves are in biot.py.
import ufl
from biot import build, form_names

objects = build(ufl.Mesh(ufl.VectorElement("Lagrange", ufl.tetrahedron, 1)))
globals().update(objects)  # FFCx names each form by its variable here
forms = [objects[name] for name in form_names(objects)]
