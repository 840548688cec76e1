"""Anderson acceleration of the fixed-stress iteration (cpp/coupling/anderson.h, which
explains the method): x^{n+1} = G(x_n) - sum_j c_j (G(x_j) - G(x_{j-1})) with c
the least-squares combination of the last residual differences, in a norm
weighting each block of the state (p^1, ..., p^q, u) by its inverse size."""
import numpy as np
from mpi4py import MPI


def _cholesky_solve(H, r):
    """H c = r by Cholesky; None when a pivot falls below 1e-12 of the
    largest diagonal entry (nearly dependent differences)."""
    m = len(r)
    H, c = H.copy(), r.copy()
    largest = max(H[i, i] for i in range(m))
    for j in range(m):
        for k in range(j):
            H[j, j] -= H[j, k] * H[j, k]
        if not H[j, j] > 1e-12 * largest:
            return None
        H[j, j] = np.sqrt(H[j, j])
        for i in range(j + 1, m):
            for k in range(j):
                H[i, j] -= H[i, k] * H[j, k]
            H[i, j] /= H[j, j]
    for i in range(m):
        for k in range(i):
            c[i] -= H[i, k] * c[k]
        c[i] /= H[i, i]
    for i in reversed(range(m)):
        for k in range(i + 1, m):
            c[i] -= H[k, i] * c[k]
        c[i] /= H[i, i]
    return c


# After this many restarts (each a change of the map: the split restarts at
# each change of the contact set, in each window anew) Anderson gives up,
# and the caller goes on with the plain iteration: an extrapolation that
# keeps changing the map, measured opening and closing a fault's pairs in
# turn through an injection's opening.
ANDERSON_RESTARTS = 8


class AndersonAcceleration:
    def __init__(self, comm, depth, owned, weights):
        self.comm, self.depth, self.owned, self.weights = comm, depth, owned, weights
        self.restarts = 0
        self._forget()

    def restart(self):
        """Forgets the history (a new contact active set: another map).
        Whether to go on: False after more than ANDERSON_RESTARTS restarts."""
        self._forget()
        self.restarts += 1
        return self.restarts <= ANDERSON_RESTARTS

    def _forget(self):
        # the last residual and map value, the last `depth` differences of
        # consecutive ones (oldest first) and the Gram matrix of the residual
        # differences, updated by one row per iteration
        self.f, self.g, self.dF, self.dG, self.gram = None, None, [], [], []

    def _dot(self, a, b):
        local = sum(w * w * float(np.dot(x[:n], y[:n])) for x, y, n, w in zip(a, b, self.owned, self.weights))
        return self.comm.allreduce(local, op=MPI.SUM)

    def next(self, x, g):
        """The next iterate from x and g = G(x) (a new list of arrays)."""
        f = [gk - xk for gk, xk in zip(g, x)]
        if self.f is not None:
            if len(self.dF) == self.depth:
                self.dF.pop(0)
                self.dG.pop(0)
                self.gram = [row[1:] for row in self.gram[1:]]
            self.dF.append([a - b for a, b in zip(f, self.f)])
            self.dG.append([a - b for a, b in zip(g, self.g)])
            row = [self._dot(d, self.dF[-1]) for d in self.dF]
            for i in range(len(self.dF) - 1):
                self.gram[i].append(row[i])
            self.gram.append(row)
        self.f, self.g = f, [gk.copy() for gk in g]
        available = len(self.dF)
        projections = np.array([self._dot(d, f) for d in self.dF])
        c, m = None, available
        while m > 0:  # the oldest differences are dropped while nearly dependent
            first = available - m
            H = np.array([row[first:] for row in self.gram[first:]])
            c = _cholesky_solve(H, projections[first:])
            if c is not None:
                break
            m -= 1
        result = [gk.copy() for gk in g]
        for i in range(m):
            for k, d in enumerate(self.dG[available - m + i]):
                result[k] -= c[i] * d
        return result
