"""Measurements quoted in docs/spatial-design.md, one function per scene.

    PYTHONPATH=python/ukflex/reference python -m spatial.report top|top_projected|bricard|bricard_pinv|flyball|slider_crank|exudyn

Prints plain text; nothing is written to disk.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from . import scenes
from .rotations import rot_A, omega_world
from .uk import simulate, reaction_uniqueness, joint_reactions, correct_initial_state, uk_rank


def top(t_end=10.0, rtol=1e-12, spin=30.0, project_every=None):
    m = scenes.heavy_top(spin=spin)
    q0, qd0 = m.initial_guess()

    def u_max(t, y):
        p, pd = y[3:7], y[10:14]
        return np.cross(omega_world(p, pd), rot_A(p)[:, 2])[2]
    u_max.direction = -1
    ts = np.linspace(0.0, t_end, 1001)
    tic = time.perf_counter()
    res = simulate(m, t_end, q0, qd0, rtol=rtol, atol=rtol * 1e-2, t_eval=ts,
                   events=None if project_every else u_max, project_every=project_every)
    wall = time.perf_counter() - tic
    E = np.array([m.energy(0, res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    L = np.array([m.angular_momentum(res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    e3 = np.array([m.bodies[0].rotation(res.q[:, i])[:, 2] for i in range(ts.size)])
    Lz, L3 = L[:, 2], np.einsum("ij,ij->i", L, e3)
    d = m.top_data
    T, roots = scenes.nutation_period(d["mass"], d["A"], d["C"], d["l"], d["theta0"], d["spin"])
    print(f"heavy top, spin {spin} rad/s, {t_end} s, DOP853 rtol {rtol}, projection every {project_every} s: "
          f"{res.nfev} rhs calls, {wall:.1f} s")
    print(f"  energy      {E[0]:.12f} J, max rel. change {np.abs(E - E[0]).max() / abs(E[0]):.2e}")
    print(f"  L_z         {Lz[0]:.12f}, max rel. change {np.abs(Lz - Lz[0]).max() / abs(Lz[0]):.2e}")
    print(f"  L.e3 = C w3 {L3[0]:.12f}, max rel. change {np.abs(L3 - L3[0]).max() / abs(L3[0]):.2e}")
    print(f"  |p|^2 - 1   max {max(abs(res.q[3:7, i] @ res.q[3:7, i] - 1) for i in range(ts.size)):.2e}")
    if not project_every:
        per = np.diff(res.extra["events"][0])
        print(f"  nutation: closed form T = {T:.12f} s (u1, u2, u3 = {roots}); measured {per.size} periods, "
              f"max |T_k - T| = {np.abs(per - T).max():.2e} s")


def bricard(t_end=10.0, rtol=1e-10, pinv_rtol=1e-8):
    m = scenes.bricard()
    q0, qd0 = m.initial_guess()
    rr = m.rank_report(0.0, q0)
    r, s = uk_rank(m, 0.0, q0)
    print(f"Bricard: n = {m.n}, rows = {m.m} (30 joint rows + 5 normalization), rank A = {rr['rank']}, "
          f"redundant = {rr['redundant']}, dof = {rr['dof']}")
    print(f"  smallest singular values of A: {rr['singular_values'][-3:]}; of D = A F^-T: {s[-3:]}")
    nd, uniq = reaction_uniqueness(m, 0.0, q0)
    print(f"  null(A^T) dimension {nd}; reaction components (Fx Fy Fz Tx Ty Tz) unique for every lam:")
    for k, v in uniq.items():
        print(f"    {k}: {v.astype(int)}")
    ts = np.linspace(0.0, t_end, 101)
    tic = time.perf_counter()
    res = simulate(m, t_end, q0, qd0, rtol=rtol, atol=rtol * 1e-2, t_eval=ts, pinv_rtol=pinv_rtol)
    wall = time.perf_counter() - tic
    E = np.array([m.energy(0, res.q[:, i], res.qd[:, i]) for i in range(ts.size)])
    phi = max(np.abs(m.phi(t, res.q[:, i])).max() for i, t in enumerate(ts))
    print(f"  {t_end} s, DOP853 rtol {rtol}, pinv rtol {pinv_rtol}: {res.nfev} rhs calls, {wall:.1f} s; "
          f"E0 = {E[0]:.6f} J, max |E - E0| = {np.abs(E - E0).max() if (E0 := E[0]) else 0:.2e} J, "
          f"max |Phi| = {phi:.2e}")
    P = [m.marker_position(m.joints[k].mi, res.q[:, -1]) for k in range(6)]
    print("  joint points at the end:", np.round(P, 6).tolist())
    lam_r = joint_reactions(m, t_end, res.q[:, -1], res.qd[:, -1], rtol=pinv_rtol)
    lam_d = joint_reactions(m, t_end, res.q[:, -1], res.qd[:, -1])
    print(f"  with the default pinv tolerance the largest reaction force there is {max(np.abs(F).max() for F, _ in lam_d.values()):.2e} N")
    print("  reactions at the end (force, torque on the first marker's body, about its point, world axes):")
    for k, (F, Tq) in lam_r.items():
        print(f"    {k}: F = {np.round(F, 6).tolist()}, T = {np.round(Tq, 6).tolist()}")


def bricard_pinv(t_end=0.2, rtol=1e-10):
    """Right-hand-side calls against the pseudoinverse's rank tolerance (A04, from rest)."""
    m = scenes.bricard()
    q0, qd0 = m.initial_guess()
    for pr in (None, 1e-12, 1e-10, 1e-8, 1e-6):
        tic = time.perf_counter()
        res = simulate(m, t_end, q0, qd0, rtol=rtol, atol=rtol * 1e-2, t_eval=[0.0, t_end], pinv_rtol=pr)
        E = [m.energy(0, res.q[:, i], res.qd[:, i]) for i in range(2)]
        print(f"{t_end} s, DOP853 rtol {rtol}, pinv rtol {pr}: {res.nfev} rhs calls, "
              f"{time.perf_counter() - tic:.1f} s, |E(T) - E0| = {abs(E[1] - E[0]):.1e} J, "
              f"|Phi(T)| = {np.abs(m.phi(t_end, res.q[:, -1])).max():.1e}")


def flyball(t_end=0.1):
    for pm in ("separate", "composite"):
        m = scenes.flyball_governor(point_masses=pm)
        q0, qd0 = m.initial_guess()
        tic = time.perf_counter()
        res = simulate(m, t_end, q0, qd0, method="Radau", rtol=1e-8, atol=1e-10, t_eval=[0.0, t_end])
        sl = m.bodies[1]
        print(f"flyball ({pm}): n = {m.n}, {t_end} s Radau rtol 1e-8: {res.nfev} rhs calls, "
              f"{time.perf_counter() - tic:.1f} s, slider z(T) = {sl.r(res.q[:, -1])[2]:.10f} m")


def slider_crank(t_end=5.0):
    m = scenes.slider_crank()
    q, qd = scenes.slider_crank_state(m)
    q, qd, rep = correct_initial_state(m, q, qd)
    ts = np.concatenate([np.linspace(0.0, 1.0, 11), np.arange(2.0, t_end + 0.5)])
    tic = time.perf_counter()
    res = simulate(m, t_end, q, qd, rtol=1e-11, atol=1e-13, t_eval=ts)
    print(f"spatial slider-crank, {t_end} s, DOP853 rtol 1e-11: {res.nfev} rhs calls, {time.perf_counter() - tic:.1f} s")
    for i, t in enumerate(ts):
        x = m.slider_body.r(res.q[:, i])[0]
        print(f"  t = {t:.1f}: slider x = {x:.9f} m, crank angle = {scenes.crank_angle(m, res.q[:, i]):+.9f} rad")
    k = int(np.argmin(np.abs(ts - 1.0)))
    R = joint_reactions(m, ts[k], res.q[:, k], res.qd[:, k])
    print("  reactions at 1 s (on the first marker's body, about its point, world axes):")
    for name, (F, Tq) in R.items():
        print(f"    {name}: F = {np.round(F, 6).tolist()}, T = {np.round(Tq, 6).tolist()}")


def exudyn():
    from .exudyn_peer import compare
    for name, m in (("double pendulum", scenes.double_pendulum()), ("heavy top (30 rad/s)", scenes.heavy_top(spin=30.0))):
        r = compare(m, t_end=0.5, steps=(1e-3, 5e-4, 2.5e-4, 1.25e-4))
        print(f"{name}, 0.5 s, Exudyn generalized-alpha (rho 1) vs the reference at rtol 1e-12:")
        for h, e, er in zip(r["steps"], r["position_error"], r["rotation_error"]):
            print(f"  h = {h:.3g} s: max position error {e:.2e} m, max rotation-matrix error {er:.2e}")
        print(f"  Richardson (last two steps): {r['richardson']:.2e}")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "top"
    {"top": top, "top_projected": lambda: top(project_every=0.5), "bricard": bricard, "bricard_pinv": bricard_pinv, "flyball": flyball,
     "slider_crank": slider_crank, "exudyn": exudyn}[what]()
