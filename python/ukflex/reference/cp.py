"""Coordinate partitioning after Wehage and Haug (1982), driven by scipy's solve_ivp.

Two modes:

``partition="once"`` (Wehage-Haug proper)
    The coordinates are split into dependent ``q_D`` and independent ``q_I`` by a
    column-pivoted QR factorization of ``A = Phi_q`` (``scipy.linalg.qr(pivoting=True)``): the
    first ``r = rank(A)`` pivot columns are the best-conditioned dependent block ``A_D``. Only
    ``y = [q_I, qd_I]`` is integrated. At every call of the right-hand side the dependent
    positions are recovered by Newton-Raphson on ``Phi(t, q) = 0`` (``q_I`` fixed), the
    dependent velocities from ``A qd = -Phi_t`` and the independent accelerations from the
    reduced equations ``(B^T M B) qdd_I = B^T (Q - M c)`` with ``qdd = B qdd_I + c``,
    ``B = [I; -A_D^-1 A_I]``, ``c = [0; A_D^-1 b]``.

    **Repartition criterion**: a terminal event watches ``kappa = cond_2(A_D)`` along the
    accepted solution; when ``kappa > repartition_factor * kappa_0`` (``kappa_0`` = condition
    number of the dependent block right after the last partitioning, default factor 10) the
    integration stops there, the full state is recovered, ``A`` is re-partitioned by a new
    pivoted QR at that state and a new integration is started from it (a fresh start of the
    integrator: step size and BDF history are rebuilt). The number of repartitions is
    reported. The ratio criterion is scale invariant (elastic and rigid columns of ``A`` have
    very different magnitudes, so an absolute threshold on ``kappa`` would be arbitrary). A
    failure of the Newton recovery ends the run with ``status = -1``.

``partition="every_call"`` (the paper's Matlab implementation, Table 1)
    The full state ``y = [q, qd]`` is integrated and ``A`` is re-partitioned (pivoted QR) at
    every acceleration call; accelerations come from the same reduced equations. There is no
    position/velocity recovery, so like UK the constraints drift. The number of calls at
    which the chosen dependent set changed is reported as ``repartitions``.

Rows: if ``A`` is rank deficient (redundant constraints) an independent set of ``r`` rows is
chosen by a pivoted QR of ``A_D^T``.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla
from scipy.integrate import solve_ivp

from ._blas import single_blas_thread
from .uk import SimulationResult, _as_model, correct_initial_state, fd_jacobian

__all__ = ["simulate_cp", "choose_partition", "CPPartition", "CPSystem", "reduced_accelerations", "NewtonFailure",
           "SingularDependentBlock"]


class NewtonFailure(RuntimeError):
    pass


class SingularDependentBlock(RuntimeError):
    """The dependent block ``A_D`` of the partition is singular: coordinate partitioning cannot
    express the dependent coordinates through the independent ones (a kinematic singularity,
    or redundant rows the rank decision did not catch). Raised instead of returning garbage."""


def _solve_dependent(AD, rhs, t, part, what):
    try:
        x = np.linalg.solve(AD, rhs)
    except np.linalg.LinAlgError as exc:
        raise SingularDependentBlock(
            f"coordinate partitioning broke down at t={t:.6g} while solving for {what}: the dependent "
            f"block A_D (rows {part.rows.tolist()}, coordinates {part.dep.tolist()}) is singular ({exc}); "
            "the mechanism is at a kinematic singularity or has redundant constraints") from exc
    # growth |A_D| |x| / |rhs| is a cheap lower bound of cond(A_D): above 1e12 fewer than ~4
    # significant digits of x survive, i.e. the partition is numerically singular
    scale = np.abs(rhs).max() if np.size(rhs) else 0.0
    growth = np.abs(AD).max() * np.abs(x).max() / scale if scale > 0 else 0.0
    if not np.all(np.isfinite(x)) or growth > _SINGULAR_GROWTH:
        raise SingularDependentBlock(
            f"coordinate partitioning broke down at t={t:.6g} while solving for {what}: the dependent "
            f"block A_D (rows {part.rows.tolist()}, coordinates {part.dep.tolist()}) is numerically singular "
            f"(cond = {np.linalg.cond(AD):.3e}); the mechanism is at a kinematic singularity of this "
            "partition (repartition) or has redundant constraints")
    return x


_SINGULAR_GROWTH = 1e12


class CPPartition:
    """A choice of dependent coordinates ``dep`` (and constraint rows ``rows``)."""

    def __init__(self, dep, ind, rows, cond):
        self.dep = np.asarray(dep, dtype=int)
        self.ind = np.asarray(ind, dtype=int)
        self.rows = np.asarray(rows, dtype=int)
        self.cond = float(cond)

    def __repr__(self):
        return f"CPPartition(dep={self.dep.tolist()}, ind={self.ind.tolist()}, cond={self.cond:.3g})"


def choose_partition(A, rank_rtol=1e-10):
    """Column-pivoted QR of A: the first rank(A) pivot columns are the dependent coordinates."""
    m, n = A.shape
    if m == 0:
        return CPPartition([], np.arange(n), [], 1.0)
    _, R, piv = sla.qr(A, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    r = int(np.sum(d > rank_rtol * d[0])) if d.size and d[0] > 0 else 0
    dep = np.sort(piv[:r])
    ind = np.sort(piv[r:])
    if r < m:
        _, _, prow = sla.qr(A[:, dep].T, mode="economic", pivoting=True)
        rows = np.sort(prow[:r])
    else:
        rows = np.arange(m)
    cond = np.linalg.cond(A[np.ix_(rows, dep)]) if r else 1.0
    return CPPartition(dep, ind, rows, cond)


class CPSystem:
    """State recovery and reduced accelerations for a fixed partition (one call of the
    ``partition="once"`` right-hand side of :func:`simulate_cp` is :meth:`recover` then
    :meth:`accelerations`).

    Parameters
    ----------
    model : ReferenceModel
    part : CPPartition
    q_guess : array of shape (n,)
        Start of the first Newton iteration; afterwards the last recovered ``q``.
    newton_tol, newton_maxit
        Newton-Raphson tolerance on ``|Phi|`` (relative to ``1 + |q_D|``) and iteration limit.

    Methods
    -------
    recover(t, qI, qdI) -> (q, qd, A_D)
        Full ``q`` (Newton on ``Phi = 0`` with ``q_I`` fixed) and ``qd`` (from
        ``A qd = -Phi_t``), each shape (n,), and the dependent block of ``A``.
    accelerations(t, q, qd) -> (qdd_I, qdd)
        The reduced equations (:func:`reduced_accelerations`).
    """

    def __init__(self, model, part, q_guess, newton_tol=1e-12, newton_maxit=25):
        self.model = model
        self.p = part
        self.q = np.array(q_guess, dtype=float)      # last recovered full q (Newton start)
        self.tol = newton_tol
        self.maxit = newton_maxit

    def recover(self, t, qI, qdI):
        m, p = self.model, self.p
        q = self.q.copy()
        q[p.ind] = qI
        dep, rows = p.dep, p.rows
        for it in range(self.maxit + 1):
            Phi, A = m.phi_A(t, q)
            if dep.size == 0:
                break
            r = Phi[rows]
            AD = A[np.ix_(rows, dep)]
            if np.abs(r).max() <= self.tol * (1.0 + np.abs(q[dep]).max()):
                break
            if it == self.maxit:
                raise NewtonFailure(f"Newton-Raphson on Phi=0 did not converge at t={t:.6g} "
                                    f"(|Phi|={np.abs(r).max():.3e})")
            q[dep] -= _solve_dependent(AD, r, t, p, "the dependent positions (Newton)")
        self.q = q
        qd = np.zeros(m.n)
        qd[p.ind] = qdI
        if dep.size:
            rhs = -(A[np.ix_(rows, p.ind)] @ qdI + m.phi_t(t)[rows])
            qd[dep] = _solve_dependent(AD, rhs, t, p, "the dependent velocities")
        else:
            AD = np.zeros((0, 0))
        return q, qd, AD

    def accelerations(self, t, q, qd):
        return reduced_accelerations(self.model, self.p, t, q, qd)


def reduced_accelerations(model, p, t, q, qd):
    """Independent accelerations from the reduced equations and the full qdd."""
    M, Q, A, b = model.terms(t, q, qd)
    n = q.size
    Ar, br = A[p.rows], b[p.rows]
    AD = Ar[:, p.dep]
    AI = Ar[:, p.ind]
    Bm = np.zeros((n, p.ind.size))
    Bm[p.ind, np.arange(p.ind.size)] = 1.0
    c = np.zeros(n)
    if p.dep.size:
        X = _solve_dependent(AD, np.column_stack([AI, br]), t, p, "the reduced equations")
        Bm[p.dep] = -X[:, :-1]
        c[p.dep] = X[:, -1]
    Mh = Bm.T @ M @ Bm
    Qh = Bm.T @ (Q - M @ c)
    qddI = np.linalg.solve(Mh, Qh)
    return qddI, Bm @ qddI + c


def _segment_times(t_eval, t_start, t_stop, first):
    if t_eval is None:
        return None
    te = np.asarray(t_eval, dtype=float)
    sel = (te >= t_start) & (te <= t_stop) if first else (te > t_start) & (te <= t_stop)
    return te[sel]


def simulate_cp(description_or_model, t_end, method="BDF", rtol=1e-6, atol=1e-9, t_eval=None,
                partition="once", q0=None, qd0=None, t0=0.0, repartition_factor=10.0,
                max_repartitions=1000, newton_tol=1e-12, **solve_ivp_kwargs):
    """Coordinate-partitioning simulation (see the module docstring).

    Returns a :class:`SimulationResult` with the full ``q``, ``qd`` (n, nt), ``repartitions``,
    ``nfev`` (right-hand-side calls, including those of finite-difference Jacobians),
    ``wall_time``, ``accel_time`` (time spent inside the right-hand side: state recovery,
    partitioning where applicable, and acceleration evaluation) and in ``extra`` the list of
    partitions ``(t, dependent indices, cond)``.
    """
    model = _as_model(description_or_model)
    if q0 is None or qd0 is None:
        qc, qdc = correct_initial_state(model, q0, qd0, t0=t0)
        q0 = qc if q0 is None else q0
        qd0 = qdc if qd0 is None else qd0
    q0 = np.asarray(q0, dtype=float)
    qd0 = np.asarray(qd0, dtype=float)
    if partition == "once":
        with single_blas_thread():
            return _simulate_once(model, t0, t_end, q0, qd0, method, rtol, atol, t_eval,
                                  repartition_factor, max_repartitions, newton_tol,
                                  solve_ivp_kwargs)
    if partition in ("every_call", "every-call", "every"):
        with single_blas_thread():
            return _simulate_every_call(model, t0, t_end, q0, qd0, method, rtol, atol, t_eval,
                                        solve_ivp_kwargs)
    raise ValueError(f"partition must be 'once' or 'every_call', not {partition!r}")


def _simulate_once(model, t0, t_end, q0, qd0, method, rtol, atol, t_eval, factor, max_rep,
                   newton_tol, kw):
    n = model.n
    acc_time = [0.0]
    nfev = [0]
    t_start = time.perf_counter()
    ts, qs, qds = [], [], []
    history = []
    repartitions = 0
    tcur, qcur, qdcur = t0, q0.copy(), qd0.copy()
    status, message = 0, ""
    first = True
    while True:
        part = choose_partition(model.A(qcur))
        history.append((tcur, part.dep.tolist(), part.cond))
        sysm = CPSystem(model, part, qcur, newton_tol=newton_tol)
        nI = part.ind.size
        limit = factor * part.cond
        # relative tolerances on the independent states only
        def rhs(t, y):
            tic = time.perf_counter()
            q, qd, _ = sysm.recover(t, y[:nI], y[nI:])
            qddI, _ = sysm.accelerations(t, q, qd)
            acc_time[0] += time.perf_counter() - tic
            nfev[0] += 1
            return np.concatenate([y[nI:], qddI])

        ev_sys = CPSystem(model, part, qcur, newton_tol=newton_tol)

        def cond_event(t, y):
            _, _, AD = ev_sys.recover(t, y[:nI], y[nI:])
            return np.log(np.linalg.cond(AD) / limit) if AD.size else -1.0
        cond_event.terminal = True
        cond_event.direction = 1.0

        y0 = np.concatenate([qcur[part.ind], qdcur[part.ind]])
        kws = dict(kw)
        if method in ("BDF", "Radau") and "jac" not in kws:
            kws["jac"] = fd_jacobian(rhs, atol)
        try:
            sol = solve_ivp(rhs, (tcur, t_end), y0, method=method, rtol=rtol, atol=atol,
                            events=cond_event if part.dep.size else None, dense_output=True,
                            **kws)
        except NewtonFailure as exc:        # cannot restart from an unknown state: give up
            status, message = -1, str(exc)
            break
        # reconstruct the full state along the accepted steps (Newton warm-started step by
        # step: the branch of the dependent coordinates is followed continuously)
        rec = CPSystem(model, part, qcur, newton_tol=newton_tol)
        step_t = sol.t
        full_q, full_qd = [], []
        for k, tk in enumerate(step_t):
            q, qd, _ = rec.recover(tk, sol.y[:nI, k], sol.y[nI:, k])
            full_q.append(q)
            full_qd.append(qd)
        t_stop = step_t[-1]
        if sol.status == 1 and sol.t_events and sol.t_events[0].size:
            te = sol.t_events[0][0]
            # solve_ivp ends a terminated run with (te, y(te)): that is our last step
            qe, qde = full_q[-1], full_qd[-1]
            t_stop = te
        # outputs of this segment
        if t_eval is None:
            sel = slice(0 if first else 1, None)
            ts.extend(step_t[sel])
            qs.extend(full_q[sel])
            qds.extend(full_qd[sel])
        else:
            for tk in _segment_times(t_eval, tcur, t_stop, first):
                kk = max(np.searchsorted(step_t, tk, side="right") - 1, 0)
                rec.q = full_q[kk].copy()
                yk = sol.sol(tk)
                q, qd, _ = rec.recover(tk, yk[:nI], yk[nI:])
                ts.append(tk)
                qs.append(q)
                qds.append(qd)
        first = False
        if sol.status == 1 and sol.t_events and sol.t_events[0].size and te < t_end:
            if repartitions >= max_rep:
                status, message = -1, "too many repartitions"
                break
            repartitions += 1
            tcur, qcur, qdcur = te, qe, qde      # (te is the last output of this segment)
            continue
        status, message = sol.status, sol.message
        break
    wall = time.perf_counter() - t_start
    return SimulationResult(t=np.asarray(ts), q=np.array(qs).T.reshape(n, -1),
                            qd=np.array(qds).T.reshape(n, -1), status=status, message=message,
                            nfev=nfev[0], wall_time=wall, accel_time=acc_time[0],
                            repartitions=repartitions, success=status >= 0,
                            formulation="cp-once", extra={"partitions": history})


def _simulate_every_call(model, t0, t_end, q0, qd0, method, rtol, atol, t_eval, kw):
    n = model.n
    acc_time = [0.0]
    nfev = [0]
    changes = [0]
    last = [None]

    def rhs(t, y):
        tic = time.perf_counter()
        q, qd = y[:n], y[n:]
        part = choose_partition(model.A(q))
        if last[0] is not None and not np.array_equal(last[0], part.dep):
            changes[0] += 1
        last[0] = part.dep
        _, qdd = reduced_accelerations(model, part, t, q, qd)
        acc_time[0] += time.perf_counter() - tic
        nfev[0] += 1
        return np.concatenate([qd, qdd])

    if method in ("BDF", "Radau") and "jac" not in kw:
        kw = dict(kw, jac=fd_jacobian(rhs, atol))
    tic = time.perf_counter()
    sol = solve_ivp(rhs, (t0, t_end), np.concatenate([q0, qd0]), method=method, rtol=rtol,
                    atol=atol, t_eval=t_eval, **kw)
    wall = time.perf_counter() - tic
    return SimulationResult(t=sol.t, q=sol.y[:n], qd=sol.y[n:], status=sol.status,
                            message=sol.message, nfev=nfev[0], wall_time=wall,
                            accel_time=acc_time[0], repartitions=changes[0],
                            success=sol.success, formulation="cp-every-call")
