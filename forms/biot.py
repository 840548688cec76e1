"""The UFL forms of biotcontact, written once for both implementations.
The C++ solver compiles them with FFCx through `biot_triangle.py` and
`biot_tetrahedron.py`; the Python prototype calls `build` with dolfinx
spaces, functions and constants. "alg. ..." names a section of
docs/theory.md, "eq." an equation of the paper. `form_names` lists the
forms; the build generates the C++ table of compiled forms from it
(cpp/assembly/forms.h), so a form added here reaches C++ by its name.
Every load term is a form of its own, so that a scene assembles only what
it has (no gravity form without gravity, no coupling form without
mechanics). Boundary integrals use the facet marker 1; the solver marks
one boundary at a time with it."""

import ufl
from ufl import (div, dot, dx, grad, inner, sym, CellVolume, FacetNormal)

BOUNDARY = 1


def _ufl_space(domain, element):
    return ufl.FunctionSpace(domain, element)


def _ufl_constant(domain, shape=()):
    return ufl.Constant(domain, shape=shape)


def build(domain, space=_ufl_space, coefficient=ufl.Coefficient,
          constant=_ufl_constant):
    """Return a dict name -> UFL object (spaces, constants, coefficients, forms).

    `space(domain, element)`, `coefficient(space)` and
    `constant(domain, shape)` default to abstract UFL objects (for FFCx);
    the prototype passes dolfinx factories instead. The coefficients are
    created in one fixed order (UFL orders terms by it).
    """
    o = _spaces(domain, space)
    o.update(_constants(domain, constant))
    o.update(_materials(o, coefficient))
    o.update(_data(domain, o, coefficient, constant))
    terms = _Terms(domain, o)
    o.update(_mechanics_forms(o, terms))
    o.update(_flow_forms(o, terms))
    o.update(_monolithic_forms(o, terms))
    o.update(_diagnostic_forms(domain, o))
    return o


def form_names(objects):
    """The names of the forms among build()'s objects, in build order."""
    return [name for name, obj in objects.items() if isinstance(obj, ufl.Form)]


def _spaces(domain, space):
    """The spaces (alg. "Unknowns and spaces")."""
    cell = domain.ufl_cell()
    P1v = ufl.VectorElement("Lagrange", cell, 1)        # u in V_h
    RT = ufl.FiniteElement("RT", cell, 1)               # z in Z_h
    DG0 = ufl.FiniteElement("DG", cell, 0)              # p in Q_h
    return {
        "V": space(domain, P1v),
        "Q": space(domain, DG0),
        "W": space(domain, ufl.MixedElement([RT, DG0])),        # flow: (z, p)
        "X": space(domain, ufl.MixedElement([P1v, RT, DG0])),   # monolithic: (u, z, p)
        "Qv": space(domain, ufl.VectorElement("DG", cell, 0)),  # cell-averaged flux
        "R": space(domain, ufl.TensorElement("DG", cell, 0)),   # resistivity mu_f K^-1
        "D": space(domain, ufl.FiniteElement("Lagrange", cell, 1)),   # data: Q, p_D
        "D2": space(domain, ufl.FiniteElement("Lagrange", cell, 2)),  # closed-form references
        "D2v": space(domain, ufl.VectorElement("Lagrange", cell, 2)),
    }


def _constants(domain, constant):
    """The constants of a run (alg. "Parameters")."""
    d = domain.ufl_cell().geometric_dimension()
    names = ("dt",        # (fine) time step
             "q",         # flow steps per mechanics step
             "rho_f")
    c = {name: constant(domain) for name in names}
    c["gravity"] = constant(domain, (d,))
    return c


def _materials(o, coefficient):
    """The material coefficients, one value per cell (DG0), so that a scene's
    regions may each have their own (docs/theory.md, "Material regions");
    the fixed-stress L is cell-wise with them. The resistivity is in _data."""
    names = ("G",         # shear modulus
             "lmbda",     # Lame lambda
             "alpha",     # Biot coefficient
             "storage",   # S = 1/M + c_f phi0
             "L")         # fixed-stress stabilisation
    return {name: coefficient(o["Q"]) for name in names}


def _data(domain, o, coefficient, constant):
    """The coefficients the steps write into, and the constant `ones`."""
    d = domain.ufl_cell().geometric_dimension()
    V, Q, D = o["V"], o["Q"], o["D"]
    data = {"resistivity": coefficient(o["R"]),   # mu_f K^-1, cell-wise tensor
            "body_force": coefficient(V),         # f0
            "body_force_cells": coefficient(o["Qv"]),  # f0 cell by cell (regions with their own)
            "traction": coefficient(V),           # f2 on the marked boundary
            "ones": constant(domain, (d,)),
            "p_old": coefficient(Q),              # the pressure of the previous time (monolithic)
            "u_old": coefficient(V),              # the displacement of the previous time (monolithic)
            "source": coefficient(D),             # Q
            "p_boundary": coefficient(D)}         # p_D on the marked boundary (or a fault's faces)
    # The fields of the output and of the closed-form errors.
    data.update(u_out=coefficient(V), p_out=coefficient(Q),
                p_reference=coefficient(o["D2"]), u_reference=coefficient(o["D2v"]))
    return data


class _Terms:
    """Each term of the equations, written once as a function of its trial
    (or coefficient) and test functions; the split and monolithic forms are
    sums of these terms."""

    def __init__(self, domain, o):
        self.o = o
        self.n = FacetNormal(domain)

    def elastic(self, u, v):        # a(u, v) = 2G (eps u, eps v) + lambda (div u, div v)
        o = self.o
        return 2 * o["G"] * inner(_eps(u), _eps(v)) * dx + o["lmbda"] * div(u) * div(v) * dx

    def pressure_load(self, p, v):  # (alpha p, div v): the pore pressure on the skeleton
        return self.o["alpha"] * p * div(v) * dx

    def face_pressure(self, p, v):  # -<p n, v> on the marked faces: a fluid pressure pushing on a fracture face
        return -p * dot(v, self.n) * ufl.ds(BOUNDARY)

    def darcy(self, z, p, w):       # (mu_f K^-1 z, w) - (p, div w)
        return inner(dot(self.o["resistivity"], z), w) * dx - p * div(w) * dx

    def mass(self, z, p, th, s):    # -(div z, th) - (s/dt)(p, th): mass balance times -1
        return -div(z) * th * dx - s / self.o["dt"] * p * th * dx

    def body(self, v, f="body_force"):
        return inner(self.o[f], v) * dx

    def surface_traction(self, v):
        return inner(self.o["traction"], v) * ufl.ds(BOUNDARY)

    def boundary_pressure(self, w):  # -<p_D, w.n> on the marked boundary
        return -self.o["p_boundary"] * dot(w, self.n) * ufl.ds(BOUNDARY)

    def gravity(self, w):            # (rho_f g, w)
        return self.o["rho_f"] * inner(self.o["gravity"], w) * dx

    def source(self, th):
        return -self.o["source"] * th * dx


def _eps(w):
    return sym(grad(w))


def _mechanics_forms(o, terms):
    """Mechanics (alg. "Mechanics with frictionless Signorini contact")."""
    u, v = ufl.TrialFunction(o["V"]), ufl.TestFunction(o["V"])
    return {
        "a_elastic": terms.elastic(u, v),
        # The pressure load (alpha p, div v), and -<p n, v> on the faces the
        # pore pressure loads (a fracture; marked, or none), changes every
        # coupling iteration and is linear in p: its operator (V x Q,
        # Dirichlet rows zero) is assembled once and applied to p.
        "a_pressure_load": (terms.pressure_load(ufl.TrialFunction(o["Q"]), v)
                            + terms.face_pressure(ufl.TrialFunction(o["Q"]), v)),
        "L_body_force": terms.body(v),
        "L_body_force_cells": terms.body(v, "body_force_cells"),
        "L_traction": terms.surface_traction(v),
        # A fault's fluid pressure on its two faces (p_boundary, given).
        "L_face_pressure": terms.face_pressure(o["p_boundary"], v),
        # The lumped boundary measure of each node on Gamma_3, to turn the
        # nodal contact force into a contact pressure.
        "L_lumped_boundary": inner(o["ones"], v) * ufl.ds(BOUNDARY),
    }


def _flow_forms(o, terms):
    """Flow, mixed RT0 x P0 (alg. "Flow" and "Single-rate ... (a)").

    The mass balance is multiplied by -1 so that the matrix is symmetric:
      (mu_f K^-1 z, w) - (p, div w) - (div z, th) - ((S+L)/dt) (p, th).
    Right-hand side, alg. multirate (a) (q = 1 is the single-rate step):
      ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z, th)
        = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
          - ((alpha/q) div(u^n - u_K)/dt, th),
    times -1 like the matrix:
      -((S+L)/dt)(p^{n+1,m-1}, th) - (L/dt)(p^{n,m} - p^{n,m-1}, th)
        + (alpha/(q dt))(div(u^n - u_K), th) + loads.
    The three coupling terms change every iteration and are linear in the
    iterates: their operators (W x Q and W x V, no-flow rows zero) are
    assembled once per dt and applied to p^{n+1,m-1}, p^{n,m} - p^{n,m-1}
    and u^n - u_K.
    """
    (z, p), (w, th) = ufl.TrialFunctions(o["W"]), ufl.TestFunctions(o["W"])
    storage, L, dt, alpha, q = o["storage"], o["L"], o["dt"], o["alpha"], o["q"]
    p_trial, u_trial = ufl.TrialFunction(o["Q"]), ufl.TrialFunction(o["V"])
    return {
        "a_flow": terms.darcy(z, p, w) + terms.mass(z, p, th, storage + L),
        "a_flow_storage": -(storage + L) / dt * p_trial * th * dx,
        "a_flow_stabilisation": -L / dt * p_trial * th * dx,
        "a_flow_displacement": alpha / (q * dt) * div(u_trial) * th * dx,
        "L_flow_source": terms.source(th),
        "L_flow_pressure": terms.boundary_pressure(w),
        "L_flow_gravity": terms.gravity(w),
    }


def _monolithic_forms(o, terms):
    """Monolithic (alg. "Monolithic reference"): (u, z, p) together,
      a(u, v) - (alpha p, div v) + <p n, v>_faces + (mu_f K^-1 z, w) - (p, div w)
        - (div z, th) - (S/dt)(p, th) - (alpha/dt)(div u, th)
      = loads - (S/dt)(p_old, th) - (alpha/dt)(div u_old, th).
    """
    (u, z, p), (v, w, th) = ufl.TrialFunctions(o["X"]), ufl.TestFunctions(o["X"])
    storage, L, dt, alpha = o["storage"], o["L"], o["dt"], o["alpha"]

    def operator(s):  # the coupled operator with the pressure block -(s/dt)(p, th)
        return (terms.elastic(u, v) - terms.pressure_load(p, v) - terms.face_pressure(p, v) + terms.darcy(z, p, w)
                + terms.mass(z, p, th, s) - alpha / dt * div(u) * th * dx)
    return {
        "a_monolithic": operator(storage),
        # The fixed-stress preconditioner of the coupled system (White,
        # Castelletto and Tchelepi, 2016): the same operator with the
        # pressure block stabilised by L as in the split's flow step. One
        # block Gauss-Seidel sweep on it, flow first and then mechanics with
        # the new pressure, is one fixed-stress iteration from a zero guess
        # (docs/theory.md, "Solvers").
        "a_monolithic_preconditioner": operator(storage + L),
        "L_monolithic_history": (-storage / dt * o["p_old"] * th * dx
                                 - alpha / dt * div(o["u_old"]) * th * dx),
        "L_monolithic_body_force": terms.body(v),
        "L_monolithic_body_force_cells": terms.body(v, "body_force_cells"),
        "L_monolithic_traction": terms.surface_traction(v),
        "L_monolithic_face_pressure": terms.face_pressure(o["p_boundary"], v),
        "L_monolithic_source": terms.source(th),
        "L_monolithic_pressure": terms.boundary_pressure(w),
        "L_monolithic_gravity": terms.gravity(w),
    }


def _diagnostic_forms(domain, o):
    """The contraction quantities of Theorems 1 and 2 are both
      || c_u div(du) - c_p dp ||^2
    (Theorem 1: c_u = lambda, c_p = alpha; Theorem 2: c_u = alpha/(q L),
    c_p = 1, dp replaced by dp^{m} - dp^{m-1}). They are measured every
    iteration from two operators assembled once: the cell integrals of div u
    (Q x V) and the cell volumes. For P1 u and P0 p the integrand is
    constant on a cell, so with D du = |T| div du,
      ||c_u div du - c_p dp||^2 = sum_T (c_u (D du)_T - c_p |T| dp_T)^2 / |T|
    exactly (cpp/diagnostics/diagnostics.h). The P0 output fields are cell
    values, exact for the same reason: sigma_v = lambda div u - alpha p.
    The errors are against a closed form interpolated into P2.
    """
    th = ufl.TestFunction(o["Q"])
    u, p = o["u_out"], o["p_out"]
    p_reference, u_reference = o["p_reference"], o["u_reference"]
    return {
        "a_divergence": div(ufl.TrialFunction(o["V"])) * th * dx,
        "L_cell_volume": th * dx,
        "L_sigma_v": (o["lmbda"] * div(u) - o["alpha"] * p) / CellVolume(domain) * th * dx,
        "M_pressure_error": (p - p_reference) ** 2 * dx,
        "M_pressure_reference": p_reference ** 2 * dx,
        "M_displacement_error": inner(u - u_reference, u - u_reference) * dx,
        "M_displacement_reference": inner(u_reference, u_reference) * dx,
    }
