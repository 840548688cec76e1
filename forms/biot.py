"""The UFL forms of biotcontact, written once for both implementations.

The C++ solver compiles them with FFCx through `biot_triangle.py` and
`biot_tetrahedron.py` (one compilation per cell type); the Python prototype
calls `build` with dolfinx spaces, functions and constants. Equation numbers
refer to ../shared/docs/algorithm.md ("alg.") and to the paper ("eq.").

Every load term is a form of its own so that a scene assembles only what it
has: no gravity form without gravity, no coupling form without mechanics.
Boundary integrals use the facet marker 1; the solver marks one boundary at a
time with it (a boundary may carry its own traction or pressure).
"""

import types

import ufl
from ufl import (div, dot, dx, grad, inner, sym, CellVolume, FacetNormal)

BOUNDARY = 1


def _ufl_space(domain, element):
    return ufl.FunctionSpace(domain, element)


def _ufl_constant(domain, shape=()):
    return ufl.Constant(domain, shape=shape)


def build(domain, space=_ufl_space, coefficient=ufl.Coefficient,
          constant=_ufl_constant):
    """Return a dict name -> UFL object (forms, coefficients, constants).

    `space(domain, element)`, `coefficient(space)` and
    `constant(domain, shape)` default to abstract UFL objects (for FFCx);
    the prototype passes dolfinx factories instead.
    """
    cell = domain.ufl_cell()
    d = cell.geometric_dimension()

    # Spaces (alg. "Unknowns and spaces").
    P1v = ufl.VectorElement("Lagrange", cell, 1)        # u in V_h
    RT = ufl.FiniteElement("RT", cell, 1)               # z in Z_h
    DG0 = ufl.FiniteElement("DG", cell, 0)              # p in Q_h
    DG0v = ufl.VectorElement("DG", cell, 0)             # cell-averaged flux
    DG0t = ufl.TensorElement("DG", cell, 0)             # resistivity mu_f K^-1
    P1 = ufl.FiniteElement("Lagrange", cell, 1)         # data: Q, p_D
    P2 = ufl.FiniteElement("Lagrange", cell, 2)         # closed-form references
    P2v = ufl.VectorElement("Lagrange", cell, 2)

    V = space(domain, P1v)
    Q = space(domain, DG0)
    W = space(domain, ufl.MixedElement([RT, DG0]))      # flow: (z, p)
    X = space(domain, ufl.MixedElement([P1v, RT, DG0])) # monolithic: (u, z, p)
    Qv = space(domain, DG0v)
    R = space(domain, DG0t)
    D = space(domain, P1)
    D2 = space(domain, P2)
    D2v = space(domain, P2v)

    # Material constants (alg. "Parameters").
    G = constant(domain)             # shear modulus
    lmbda = constant(domain)         # Lame lambda
    alpha = constant(domain)         # Biot coefficient
    storage = constant(domain)       # S = 1/M + c_f phi0
    L = constant(domain)             # fixed-stress stabilisation
    dt = constant(domain)            # (fine) time step
    q = constant(domain)             # flow steps per mechanics step
    rho_f = constant(domain)
    gravity = constant(domain, (d,))

    resistivity = coefficient(R)     # mu_f K^-1, cell-wise tensor

    def eps(w):
        return sym(grad(w))

    # Each term of the equations is written once, as a function of its trial
    # (or coefficient) and test functions; the split and monolithic forms
    # below are sums of these terms.
    def elastic(u, v):        # a(u, v) = 2G (eps u, eps v) + lambda (div u, div v)
        return 2 * G * inner(eps(u), eps(v)) * dx + lmbda * div(u) * div(v) * dx

    def pressure_load(p, v):  # (alpha p, div v): the pore pressure on the skeleton
        return alpha * p * div(v) * dx

    def darcy(z, p, w):       # (mu_f K^-1 z, w) - (p, div w)
        return inner(dot(resistivity, z), w) * dx - p * div(w) * dx

    def mass(z, p, th, s):    # -(div z, th) - (s/dt)(p, th): mass balance times -1
        return -div(z) * th * dx - s / dt * p * th * dx

    def body(v):
        return inner(body_force, v) * dx

    def surface_traction(v):
        return inner(traction, v) * ufl.ds(BOUNDARY)

    def boundary_pressure(w):  # -<p_D, w.n> on the marked boundary
        return -p_boundary * dot(w, n) * ufl.ds(BOUNDARY)

    def gravity_term(w):      # (rho_f g, w)
        return rho_f * inner(gravity, w) * dx

    def source_term(th):
        return -source * th * dx

    # ---- Mechanics (alg. "Mechanics with frictionless Signorini contact") --
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    body_force = coefficient(V)            # f0
    traction = coefficient(V)              # f2 on the marked boundary
    ones = constant(domain, (d,))

    a_elastic = elastic(u, v)
    # The pressure load (alpha p, div v) changes every coupling iteration and
    # is linear in p: its operator (V x Q, Dirichlet rows zero) is assembled
    # once and applied to p.
    p_trial = ufl.TrialFunction(Q)
    a_pressure_load = pressure_load(p_trial, v)
    L_body_force = body(v)
    L_traction = surface_traction(v)
    # lumped boundary measure of each node on Gamma_3, to turn the nodal
    # contact force into a contact pressure
    L_lumped_boundary = inner(ones, v) * ufl.ds(BOUNDARY)

    # ---- Flow, mixed RT0 x P0 (alg. "Flow" and "Single-rate ... (a)") ------
    # The mass balance is multiplied by -1 so that the matrix is symmetric:
    #   (mu_f K^-1 z, w) - (p, div w) - (div z, th) - ((S+L)/dt) (p, th)
    (z, pf) = ufl.TrialFunctions(W)
    (w, th) = ufl.TestFunctions(W)
    a_flow = darcy(z, pf, w) + mass(z, pf, th, storage + L)

    # Right-hand side, alg. multirate (a) (q = 1 is the single-rate step):
    #   ((S+L)(p^{n+1,m} - p^{n+1,m-1})/dt, th) + (div z, th)
    #     = (Q(t_m), th) + (L (p^{n,m} - p^{n,m-1})/dt, th)
    #       - ((alpha/q) div(u^n - u_K)/dt, th)
    p_previous = coefficient(Q)            # the pressure of the previous time (monolithic)
    u_window = coefficient(V)              # the displacement of the previous time (monolithic)
    source = coefficient(D)                # Q
    p_boundary = coefficient(D)            # p_D on the marked boundary
    n = FacetNormal(domain)

    # Times -1 like the matrix, the right-hand side is
    #   -((S+L)/dt)(p^{n+1,m-1}, th) - (L/dt)(p^{n,m} - p^{n,m-1}, th)
    #     + (alpha/(q dt))(div(u^n - u_K), th) + loads.
    # The three coupling terms change every iteration and are linear in the
    # iterates: their operators (W x Q and W x V, no-flow rows zero) are
    # assembled once per dt and applied to p^{n+1,m-1}, p^{n,m} - p^{n,m-1}
    # and u^n - u_K.
    u_trial = ufl.TrialFunction(V)
    a_flow_storage = -(storage + L) / dt * p_trial * th * dx
    a_flow_stabilisation = -L / dt * p_trial * th * dx
    a_flow_displacement = alpha / (q * dt) * div(u_trial) * th * dx
    L_flow_source = source_term(th)
    L_flow_pressure = boundary_pressure(w)
    L_flow_gravity = gravity_term(w)

    # ---- Monolithic (alg. "Monolithic reference"): (u, z, p) together ------
    #   a(u, v) - (alpha p, div v) + (mu_f K^-1 z, w) - (p, div w)
    #     - (div z, th) - (S/dt)(p, th) - (alpha/dt)(div u, th)
    #   = loads - (S/dt)(p_old, th) - (alpha/dt)(div u_old, th)
    (um, zm, pm) = ufl.TrialFunctions(X)
    (vm, wm, thm) = ufl.TestFunctions(X)
    a_monolithic = (elastic(um, vm) - pressure_load(pm, vm) + darcy(zm, pm, wm)
                    + mass(zm, pm, thm, storage) - alpha / dt * div(um) * thm * dx)
    # The fixed-stress preconditioner of the coupled system (White,
    # Castelletto and Tchelepi, 2016): the same operator with the pressure
    # block stabilised by L as in the split's flow step, -((S+L)/dt)(p, th).
    # One block Gauss-Seidel sweep on it, flow first and then mechanics with
    # the new pressure, is one fixed-stress iteration from a zero guess
    # (cpp/solvers/solver.h, the monolithic Krylov method).
    a_monolithic_preconditioner = (elastic(um, vm) - pressure_load(pm, vm) + darcy(zm, pm, wm)
                                   + mass(zm, pm, thm, storage + L) - alpha / dt * div(um) * thm * dx)
    L_monolithic_history = (-storage / dt * p_previous * thm * dx
                            - alpha / dt * div(u_window) * thm * dx)
    L_monolithic_body_force = body(vm)
    L_monolithic_traction = surface_traction(vm)
    L_monolithic_source = source_term(thm)
    L_monolithic_pressure = boundary_pressure(wm)
    L_monolithic_gravity = gravity_term(wm)

    # ---- Diagnostics -------------------------------------------------------
    # The contraction quantities of Theorems 1 and 2 are both
    #   || c_u div(du) - c_p dp ||^2
    # (Theorem 1: c_u = lambda, c_p = alpha; Theorem 2: c_u = alpha/(q L),
    #  c_p = 1, dp replaced by dp^{m} - dp^{m-1}).
    # They are measured every iteration from two operators assembled once:
    # the cell integrals of div u (Q x V) and the cell volumes. For P1 u and
    # P0 p the integrand is constant on a cell, so with D du = |T| div du,
    #   ||c_u div du - c_p dp||^2 = sum_T (c_u (D du)_T - c_p |T| dp_T)^2 / |T|
    # exactly (diagnostics.h).
    th0 = ufl.TestFunction(Q)
    a_divergence = div(u_trial) * th0 * dx
    L_cell_volume = th0 * dx

    # Cell values of P0 output fields (the integrands are constant on a cell
    # for P1 u and P0 p, so this is exact): sigma_v = lambda div u - alpha p.
    u_out = coefficient(V)
    p_out = coefficient(Q)
    L_sigma_v = (lmbda * div(u_out) - alpha * p_out) / CellVolume(domain) * th0 * dx

    # Errors against a closed form interpolated into P2.
    p_reference = coefficient(D2)
    u_reference = coefficient(D2v)
    M_pressure_error = (p_out - p_reference) ** 2 * dx
    M_pressure_reference = p_reference ** 2 * dx
    M_displacement_error = inner(u_out - u_reference, u_out - u_reference) * dx
    M_displacement_reference = inner(u_reference, u_reference) * dx

    names = dict(locals())
    return {k: obj for k, obj in names.items()
            if not k.startswith("_") and not isinstance(obj, types.FunctionType)
            and k not in ("space", "coefficient", "constant", "domain", "cell", "d", "names")}


# Forms compiled for C++, in this order (see cpp/assembly/forms.h).
FORM_NAMES = [
    "a_elastic", "a_pressure_load", "L_body_force", "L_traction", "L_lumped_boundary",
    "a_flow", "a_flow_storage", "a_flow_stabilisation", "a_flow_displacement", "L_flow_source",
    "L_flow_pressure", "L_flow_gravity",
    "a_divergence", "L_cell_volume", "L_sigma_v",
    "M_pressure_error", "M_pressure_reference",
    "M_displacement_error", "M_displacement_reference",
    "a_monolithic", "a_monolithic_preconditioner", "L_monolithic_history", "L_monolithic_body_force",
    "L_monolithic_traction",
    "L_monolithic_source", "L_monolithic_pressure", "L_monolithic_gravity",
]
