"""The loads of a step (cpp/assembly/loads.h): the right-hand-side terms that
change with time only (body force, tractions, source, boundary pressures,
gravity), assembled into one vector per time and kept for the last few
times."""
from collections import deque

from dolfinx import fem

from .linear_algebra import add_vector
from .parameters import interpolate


class Loads:
    """The time-dependent right-hand side of a step, with its time cache.

    Each term is a linear form whose data coefficient is interpolated from
    the scene's expressions at t before it is assembled (a term without
    data, such as gravity, is assembled as it is). Terms are summed in the
    order they were added. The vector of a time is assembled once and kept
    for the last keep() times (a multirate iteration visits the q fine times
    of its window again); loads that do not depend on time are assembled once
    per run. The vectors are Functions of `space` (linear_algebra.py)."""

    def __init__(self, space, finish):
        """`finish(b, t)` completes an assembled vector (ghost accumulation,
        lifting and Dirichlet values at t), for the step's system."""
        self._space, self._finish = space, finish
        self._terms, self._markers = [], []
        self._time_dependent = False
        self._keep = 1
        self._vectors = deque()  # (t, vector), oldest first

    def add(self, form, data=None, expressions=()):
        """Adds the term `form`, whose coefficient `data` is interpolated from
        `expressions` (one per component) at each time; data may be None."""
        expressions = list(expressions)
        self.add_filled(form, data, lambda f, t: interpolate(f, expressions, t),
                        any(e.depends_on_time for e in expressions))

    def add_filled(self, form, data, fill, time_dependent):
        """Adds the term `form`, whose coefficient `data` is set by
        `fill(data, t)` at each time (when `time_dependent`, else once)."""
        self._time_dependent = self._time_dependent or time_dependent
        self._terms.append((form, data, fill))

    def add_boundary(self, domain, name, make, data, expressions):
        """Adds the term of a load on boundary `name`: `make(marker)` builds
        its form with the ds(1) integrals on that boundary's facets."""
        self.add_on_facets(domain.marker(name), make, data, expressions)

    def add_on_facets(self, marker, make, data, expressions):
        """Adds the term of a load on the facets `marker` marks: `make(marker)`
        builds its form."""
        self._markers.append(marker)
        self.add(make(marker), data, expressions)

    def depends_on_time(self, dependence):
        """Something else of the step's right-hand side depends on time (Dirichlet values)."""
        self._time_dependent = self._time_dependent or dependence

    def keep(self, times):
        """Keeps the vectors of the last `times` times (1 by default)."""
        self._keep = max(times, 1)

    def at(self, t):
        """The assembled loads at time t (a Function: read, do not change)."""
        for time, b in self._vectors:
            if time == t or not self._time_dependent:
                return b
        # The oldest vector is reused once keep() are held.
        if len(self._vectors) >= self._keep:
            _, b = self._vectors.popleft()
            b.x.array[:] = 0.0
        else:
            b = fem.Function(self._space)
        self._vectors.append((t, b))
        for form, data, fill in self._terms:
            if data is not None:
                fill(data, t)
            add_vector(b, form)
        self._finish(b, t)
        return b
