"""The discrete time derivative of the flow's accumulation term, the fluid
content S p + alpha div u (alg. "Flow", docs/theory.md "Time schemes"):
backward Euler (first order), or the variable-step BDF2 (second order),
  d/dt y(t_{n+1}) ~ (c0 y_{n+1} - c1 y_n + c2 y_{n-1}) / dt_n,
  w = dt_n / dt_{n-1}, c0 = (1 + 2w)/(1 + w), c1 = 1 + w, c2 = w^2/(1 + w),
exact for quadratics in t. Since c0 - c1 + c2 = 0 it is backward Euler on
the effective step dt_n / c0 from the history value
  y* = (c1 y_n - c2 y_{n-1}) / c0,
so the forms keep their backward-Euler shape (cpp/time/time_scheme.h).
"""
from dataclasses import dataclass

from ..scene.input import TimeScheme


@dataclass(frozen=True)
class TimeDerivative:
    """The coefficients (c0, c1, c2) of one step's time derivative."""
    c0: float = 1.0
    c1: float = 1.0
    c2: float = 0.0  # backward Euler by default

    def effective_step(self, dt):
        """The step the backward-Euler forms are assembled with: dt / c0."""
        return dt / self.c0

    def second_order(self):
        return self.c2 != 0

    def coefficients(self):
        """(c0, c1, c2), as a conduit fault's FineStep takes them."""
        return (self.c0, self.c1, self.c2)


def time_derivative(scheme, dt, dt_previous):
    """The derivative of a step of length dt after one of dt_previous under
    time.scheme: BDF2 when the scheme is "bdf2" and there is a previous step
    (dt_previous > 0), backward Euler otherwise (the first step, which starts
    BDF2)."""
    if scheme != TimeScheme.bdf2 or not dt_previous > 0:
        return TimeDerivative()
    w = dt / dt_previous
    return TimeDerivative((1 + 2 * w) / (1 + w), 1 + w, w * w / (1 + w))


def history_value(d, y, y_before):
    """y* = (c1 y_n - c2 y_{n-1}) / c0 (a copy of y_n for backward Euler)."""
    if not d.second_order():
        return y.copy()
    return (d.c1 * y - d.c2 * y_before) / d.c0
