"""Coordinate partitioning (Wehage and Haug 1982) for the spatial model: a second route to the
accelerations that never regularizes the singular mass matrix.

* :func:`partition` -- Gaussian elimination with complete pivoting of ``A`` (LU with row and
  column pivoting) picks ``r = rank A`` pivot columns (the dependent coordinates ``u``) and
  ``r`` pivot rows (an independent set of constraint rows; redundant rows, as in Bricard's
  mechanism, are dropped); the other coordinates ``v`` are independent.
* :func:`cp_accelerations` -- ``qdd = B qdd_v + c`` with ``B = [-A_u^-1 A_v; I]``,
  ``c = [A_u^-1 b; 0]`` (rows of the pivot set), and the reduced equations
  ``(B^T M B) qdd_v = B^T (Q - M c)`` with the **true, singular** ``M``: ``B^T M B`` is positive
  definite because ``null(M) = span{p_i}`` meets ``null(A)`` only in 0 (the normalization rows).
* :class:`CPIntegrator` / :func:`simulate_cp` -- integrate ``[q_v, qd_v]`` only; dependent positions
  by Newton-Raphson on ``Phi(t, q_u, q_v) = 0``, dependent velocities from
  ``A_u qd_u = -A_v qd_v - Phi_t``; a new partition when ``cond(A_u)`` grows tenfold.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from .uk import SpatialResult

__all__ = ["partition", "cp_accelerations", "simulate_cp", "Partition"]


class Partition:
    def __init__(self, dep, ind, rows, cond):
        self.dep = np.asarray(dep, int)
        self.ind = np.asarray(ind, int)
        self.rows = np.asarray(rows, int)
        self.cond = float(cond)

    def __repr__(self):
        return f"Partition(dep={self.dep.tolist()}, rows={len(self.rows)}, cond={self.cond:.3g})"


def partition(A, rtol=1e-10):
    """Complete-pivoting Gaussian elimination of ``A`` (m, n)."""
    m, n = A.shape
    U = np.array(A, dtype=float)
    rows = np.arange(m)
    cols = np.arange(n)
    amax = np.abs(U).max() if U.size else 0.0
    r = 0
    for k in range(min(m, n)):
        sub = np.abs(U[k:, k:])
        i, j = np.unravel_index(np.argmax(sub), sub.shape)
        if sub[i, j] <= rtol * amax:
            break
        i += k
        j += k
        U[[k, i]] = U[[i, k]]
        rows[[k, i]] = rows[[i, k]]
        U[:, [k, j]] = U[:, [j, k]]
        cols[[k, j]] = cols[[j, k]]
        f = U[k + 1:, k] / U[k, k]
        U[k + 1:, k:] -= np.outer(f, U[k, k:])
        r += 1
    dep = np.sort(cols[:r])
    ind = np.sort(cols[r:])
    prow = np.sort(rows[:r])
    cond = np.linalg.cond(A[np.ix_(prow, dep)]) if r else 1.0
    return Partition(dep, ind, prow, cond)


def cp_accelerations(M, Q, A, b, part):
    """Accelerations of the reduced equations (full ``qdd``, shape (n,))."""
    n = M.shape[0]
    Au = A[np.ix_(part.rows, part.dep)]
    Av = A[np.ix_(part.rows, part.ind)]
    B = np.zeros((n, part.ind.size))
    B[part.dep] = -np.linalg.solve(Au, Av)
    B[part.ind] = np.eye(part.ind.size)
    c = np.zeros(n)
    c[part.dep] = np.linalg.solve(Au, b[part.rows])
    qv = np.linalg.solve(B.T @ M @ B, B.T @ (Q - M @ c))
    return B @ qv + c


class CPIntegrator:
    def __init__(self, model, part, q_guess, newton_tol=1e-13, maxit=25):
        self.model, self.p = model, part
        self.q = np.array(q_guess, float)
        self.tol, self.maxit = newton_tol, maxit
        self.nfev = 0

    def recover(self, t, qv, qdv):
        m, p = self.model, self.p
        q = self.q.copy()
        q[p.ind] = qv
        zero = np.zeros(m.n)
        for _ in range(self.maxit):
            Phi, A, phi_t, _ = m.constraint_terms(t, q, zero)
            Phi = Phi[p.rows]
            if np.abs(Phi).max() <= self.tol * (1.0 + np.abs(q[p.dep]).max()):
                break
            q[p.dep] -= np.linalg.solve(A[np.ix_(p.rows, p.dep)], Phi)
        else:
            raise RuntimeError(f"CP: Newton did not converge at t={t:.6g} (|Phi|={np.abs(Phi).max():.3e})")
        self.q = q
        qd = np.zeros(m.n)
        qd[p.ind] = qdv
        rhs = -phi_t[p.rows] - A[np.ix_(p.rows, p.ind)] @ qdv
        qd[p.dep] = np.linalg.solve(A[np.ix_(p.rows, p.dep)], rhs)
        return q, qd, A

    def rhs(self, t, y):
        k = self.p.ind.size
        q, qd, _ = self.recover(t, y[:k], y[k:])
        T = self.model.terms(t, q, qd)
        qdd = cp_accelerations(T["M"], T["Q"], T["A"], T["b"], self.p)
        self.nfev += 1
        return np.concatenate([qd[self.p.ind], qdd[self.p.ind]])

    def kappa(self, t, y):
        k = self.p.ind.size
        q, _, A = self.recover(t, y[:k], y[k:])
        return np.linalg.cond(A[np.ix_(self.p.rows, self.p.dep)])


def simulate_cp(model, t_end, q0, qd0, t0=0.0, method="DOP853", rtol=1e-10, atol=1e-12,
                t_eval=None, repartition_factor=10.0, max_repartitions=50):
    """Coordinate partitioning run from a consistent ``(q0, qd0)``; the full state is returned."""
    tic = time.perf_counter()
    t, q, qd = t0, np.array(q0, float), np.array(qd0, float)
    ts, qs, qds = [], [], []
    nrep, nfev = 0, 0
    while True:
        part = partition(model.A(t, q))
        cpi = CPIntegrator(model, part, q)
        k0 = part.cond

        def ev(tt, y, cpi=cpi, k0=k0):
            return repartition_factor * k0 - cpi.kappa(tt, y)
        ev.terminal = True
        te = None if t_eval is None else t_eval[t_eval >= t]
        y0 = np.concatenate([q[part.ind], qd[part.ind]])
        sol = solve_ivp(cpi.rhs, (t, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=te,
                        events=ev, dense_output=False)
        nfev += cpi.nfev
        k = part.ind.size
        for i in range(sol.t.size):
            qq, qqd, _ = cpi.recover(sol.t[i], sol.y[:k, i], sol.y[k:, i])
            ts.append(sol.t[i])
            qs.append(qq)
            qds.append(qqd)
        if sol.status == 1 and nrep < max_repartitions:
            t = sol.t_events[0][0]
            q, qd, _ = cpi.recover(t, sol.y_events[0][0][:k], sol.y_events[0][0][k:])
            nrep += 1
            continue
        break
    res = SpatialResult(np.array(ts), np.array(qs).T, np.array(qds).T, nfev, sol.status, sol.message)
    res.extra["repartitions"] = nrep
    res.wall_time = time.perf_counter() - tic
    return res
