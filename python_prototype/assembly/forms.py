"""The UFL forms of forms/biot.py bound to dolfinx objects, and the derived
parameters that set their constants (cpp/assembly/forms.cpp, cpp/assembly/parameters.cpp).

The forms are never written here: `biot.build` receives dolfinx factories
and returns dolfinx spaces, Functions and Constants inside its UFL forms.
The C++ solver binds coefficients by name; here the Functions build()
created *are* the coefficients, so a step writes its data into them.
"""
import os
import sys

import numpy as np
import ufl
from dolfinx import fem


FORMS_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "forms")
if FORMS_DIR not in sys.path:
    sys.path.insert(0, FORMS_DIR)
import biot  # noqa: E402  (forms/biot.py, shared with the C++ build)


class Forms:
    """build()'s objects by UFL name, and their compilation by dolfinx."""

    def __init__(self, mesh):
        self.mesh = mesh
        self.objects = biot.build(
            mesh, space=lambda domain, element: fem.FunctionSpace(mesh, element),
            coefficient=fem.Function,
            constant=lambda domain, shape=(): fem.Constant(mesh, np.zeros(shape)))

    def __getitem__(self, name):
        return self.objects[name]

    def compile(self, name, marker=None):
        """The dolfinx form of build()[name]; with a marker (facet tags with
        value 1) its ds(1) integrals run over the facets it tags."""
        form = self.objects[name]
        if marker is not None:
            form = ufl.Form([itg.reconstruct(subdomain_data=marker)
                             if itg.integral_type() == "exterior_facet" else itg
                             for itg in form.integrals()])
        return fem.form(form)
