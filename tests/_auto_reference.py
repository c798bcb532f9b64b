"""The former Python analysis of ``method="auto"`` (before it moved into the core,
``rust/integrate/choice/``), kept only as the reference the core's decisions are checked against
(``tests/test_choice.py``); the rule is described in ``ukflex.run.choice`` and docs/integrators.md."""

from __future__ import annotations

import math
from typing import Any, Dict, Optional

import numpy as np

from ukflex import _core
from ukflex.run.choice import MethodChoice, elastic_shares  # unchanged by the move

#: the chooser's constants (one place): amplitude budget per rtol and its cap, fewest steps per run
PHASE_PER_RTOL = 20.0
PHASE_CAP = 1.0
MIN_STEPS = 20
#: RADAU5M on a resolved mode: amplitude loss per step ``RADAU_DECAY (omega h)^6`` (|R(i y)| of
#: Radau IIA: 1.3e-10 at y = 0.1, 1.3e-4 at y = 1; the phase lag is 2.3e-5 y^6)
RADAU_DECAY = 1.3e-4
#: ... its largest step in radians of omega_c (reached at loose rtol: ~1e-3). Newton's failures
#: at such steps on ANCF couplers (109 of 337 attempts at 0.5) cost little since a fixed step
#: that Newton could not take stays short for a few steps
RADAU_MAX_STEP_OMEGA = 1.0
#: RADAU5M's Newton tolerance (its ``rtol`` with a fixed step) per rtol: 1e-4 at the default rtol,
#: as the former rule set it (measured on five built-in scenes at auto's step: Newton at 1e-4
#: instead of 1e-6 keeps every error within 10 %, 20-30 % less time)
NEWTON_PER_RTOL = 100.0
#: ... and at most this (the former rule's value at rtol 1e-3 .. 1e-5)
NEWTON_MAX_RTOL = 1e-3
#: ... and at most this on a scene with a geometrically exact beam (changed on purpose with the
#: core's co-rotated Newton matrices, issue 31: Newton's norm weighs corrections against each
#: coordinate's move in the step, which for the beam's node bodies is mostly rigid motion)
NEWTON_MAX_RTOL_BEAM = 1e-4
#: a beam3 scene's Newton below NEWTON_BEAM_FULL_RTOL: at most NEWTON_MAX_RTOL_BEAM (rtol /
#: NEWTON_BEAM_FULL_RTOL)^NEWTON_BEAM_EXPONENT; changed with the core's rule, issue 26
#: (right-angle cantilever: at 100 rtol auto's error stopped following rtol; docs/integrators.md)
NEWTON_BEAM_FULL_RTOL, NEWTON_BEAM_EXPONENT = 1e-6, 4.0 / 3.0
#: DOPRI5's average h omega_max on stiff flexible scenes, and a RADAU5M step's cost in DOPRI5
#: steps (nonlinear FFRF coupler N = 4: 17 us against 6 UK calls of ~1.7 us)
EXPLICIT_STEP_OMEGA = 0.5
RADAU_COST_RATIO = 1.6
#: DOPRI5's stability interval on the negative real axis, ``h |lambda| <= 3.3`` (its step control
#: settles at 3.15 on A05's fastest overdamped decay, 8.1e3 1/s: 5 103 steps over 2 s)
DOPRI5_REAL_STABILITY = 3.3
#: GENALPHA by hand (``newton_local_error``): the fraction of the local error estimate at which
#: Newton may stop (2.3 instead of 3.2-4.4 iterations per step on the paper scene, the same
#: answer; docs/integrators.md) ...
NEWTON_LOCAL_ERROR = 0.3
#: ... safe only on steps this coarse against the fastest mode, ``h omega_max``: on the ANCF
#: coupler (N = 4 and 8) the looser test keeps the answer at ``h omega_max`` >= 3.5 with
#: ``rho_inf`` 0.9 and >= 8.7 with 1.0, and lets it drift off at 2.2-2.6 (0.9) and 4.4 (1.0):
#: the accepted Newton error feeds the next local error estimates (docs/integrators.md)
LOCAL_NEWTON_MIN_STEP_OMEGA = 8.0
#: a mode is elastic when more than this share of omega^2 is the material stiffness of its strains
#: (elastic bodies, springs) rather than gravity, constraint forces or stress (``elastic_shares``)
ELASTIC_SHARE = 0.5
#: a mode belongs to a flexible body when it carries at least this share of the mode's kinetic energy
BODY_SHARE = 0.2
#: large systems (``System.SPARSE_MODES_MIN`` coordinates and more): the sparse modal analysis
#: starts from this many lowest modes and takes four times more until every flexible body's
#: lowest elastic mode is among them; ``omega_max`` comes from ``System.max_frequency``
FIRST_MODES = 8


#: the body points at which the floor's displacements are read (fractions of a beam's length)
FLOOR_POINTS = (0.25, 0.5, 0.75, 1.0)


def radau_stability(z: np.ndarray) -> np.ndarray:
    """Stability function of Radau IIA (3 stages, order 5): ``R(z)``, the factor a step of
    ``y' = lambda y`` multiplies ``y`` by, ``z = h lambda``."""
    return (1.0 + 2.0 * z / 5.0 + z * z / 20.0) / (1.0 - 3.0 * z / 5.0 + 3.0 * z * z / 20.0 - z ** 3 / 60.0)


def _mode_displacements(system, q: np.ndarray, shapes: np.ndarray) -> np.ndarray:
    """Largest displacement of a beam point per unit modal coordinate, one per mode (``shapes``
    columns): central differences of ``System.beam_point`` at :data:`FLOOR_POINTS` (beams only:
    the displacements of rigid and modal bodies are not read)."""
    out = np.zeros(shapes.shape[1])
    scale = np.abs(shapes).max(axis=0)
    eps = 1e-7 / np.where(scale > 0.0, scale, 1.0)
    from ukflex.results.outputs import beam_names

    for body in beam_names(system):
        plus = q[:, None] + shapes * eps
        minus = q[:, None] - shapes * eps
        for xi in FLOOR_POINTS:
            dp = np.asarray(system.beam_point(body, xi, plus))[:2] - np.asarray(system.beam_point(body, xi, minus))[:2]
            out = np.maximum(out, np.hypot(dp[0], dp[1]) / (2.0 * eps))
    return out


def _rigidified_acceleration(system, t0: float, q: np.ndarray, qd: np.ndarray, M: np.ndarray) -> np.ndarray:
    """The acceleration at ``(t0, q, qd)`` of the motion in which no body deforms: the
    Udwadia-Kalaba acceleration restricted to the bodies' rigid motions (``core.rigid_motions``:
    ``qdd = B x + cen``), the constraints met in the least-squares sense."""
    B, cen = (np.asarray(a) for a in system.core.rigid_motions(q, qd))
    A = np.asarray(system.A(q)).reshape(-1, q.size)
    Mr = B.T @ M @ B
    fr = B.T @ (np.asarray(system.Q(t0, q, qd)) - M @ cen)
    if A.shape[0] == 0:
        return B @ np.linalg.lstsq(Mr, fr, rcond=None)[0] + cen
    Ar = A @ B
    br = np.asarray(system.b(t0, q, qd)) - A @ cen
    k, m = Mr.shape[0], Ar.shape[0]
    kkt = np.block([[Mr, Ar.T], [Ar, np.zeros((m, m))]])
    x = np.linalg.lstsq(kkt, np.concatenate([fr, br]), rcond=None)[0][:k]
    return B @ x + cen


def transient_floor(system, t0: float, q: np.ndarray, qd: np.ndarray, omega: np.ndarray, shapes: np.ndarray,
                    omega_c: float, h: float, span: float) -> Dict[str, Any]:
    """The error floor of RADAU5M at the fixed step ``h``: the free vibrations of the modes above
    ``omega_c`` that the initial state sets off, which the step damps (or resolves badly) while the
    physical motion keeps them; tightening rtol does not lower it (below it the history error
    stays: docs/integrators.md, "Does auto honour rtol?").

    A mode ``k`` (mass-normalized ``phi_k``, ``omega_k``) starts off its quasi-static path by the
    modal acceleration that sets it off over ``omega_k^2`` and oscillates about it with that
    amplitude ``a_k``: ``phi_k^T M (qdd(t0) - qdd_r) / omega_k^2``, ``qdd_r`` the acceleration the
    mechanism would have with no body deforming (:func:`_rigidified_acceleration`; the
    difference is what the deformation feels: on the paper's undeformed start the coupler's ends
    are pulled apart, the axial mode rings at ~4e-6 m). Initial elastic *velocities* are not
    counted: a start with given elastic rates may have a higher floor than stated.
    After ``j`` steps the method has ``R(z)^j`` of it where the motion has ``exp(z j)``, ``z = h
    lambda_k``, ``lambda_k = omega_k (-zeta_k + i sqrt(1 - zeta_k^2))`` with the mode's damping
    ratio ``zeta_k`` (:func:`radau_stability`): the error ``a_k max_j |R^j - e^{z j}|`` over the
    run, read at the bodies' points (:func:`_mode_displacements`), summed over the modes.

    Returns ``{"floor": metres (largest displacement error of a beam point), "floor_modes": [(omega,
    amplitude of the body point, error), ...] of the three largest contributions}``."""
    fast = omega > omega_c * (1.0 + 1e-9)
    if not fast.any():
        return {"floor": 0.0, "floor_modes": []}
    M = np.asarray(system.M(q))
    excite = np.asarray(system.qdd(t0, q, qd)) - _rigidified_acceleration(system, t0, q, qd, M)
    w, phi = omega[fast], shapes[:, fast]
    amp = np.abs(phi.T @ (M @ excite)) / w ** 2
    zeta = damping_ratios(system, t0, q, qd, w, phi, M)  # the physical motion decays as exp(lambda t)
    lam = w * (-zeta + np.sqrt(zeta * zeta - 1.0 + 0j))  # under-damped: the oscillating root; over: the slow one
    z = lam * h
    steps = max(1, int(math.ceil(span / h)))
    # max_j |R^j - e^{z j}| over the run's steps, from moduli and phases (real arithmetic), on the
    # first 32 steps and 64 more spread geometrically up to the last (the curve is smooth in j
    # where its phase error per step is small, and near its bound where it is not)
    j = np.unique(np.concatenate([np.arange(1, min(steps, 32) + 1), np.geomspace(min(steps, 32), steps, 64).round()]))
    r = radau_stability(z)
    lr, lz = np.log(np.abs(r))[:, None] * j, z.real[:, None] * j
    dphase = (np.angle(r) - z.imag)[:, None] * j
    err = np.sqrt(np.maximum(np.exp(2 * lr) + np.exp(2 * lz) - 2 * np.exp(lr + lz) * np.cos(dphase), 0.0)).max(axis=1)
    d = _mode_displacements(system, q, phi)
    part = amp * err * d
    top = np.argsort(part)[::-1][:3]
    return {"floor": float(part.sum()),
            "floor_modes": [(float(w[k]), float(amp[k] * d[k]), float(part[k])) for k in top if part[k] > 0.0]}


def lowest_elastic_frequency(system, omega, shapes, shares, q) -> Optional[float]:
    """The frequency the step must resolve: every flexible body's lowest elastic mode (the
    lowest elastic mode with at least ``BODY_SHARE`` of its kinetic energy in that body), the
    highest of those; without flexible bodies the lowest elastic (spring) mode; ``None`` if no
    mode is elastic."""
    elastic = (omega > 0.0) & (shares > ELASTIC_SHARE)
    if not elastic.any():
        return None
    per_body = [w for w in _lowest_per_body(system, omega, shapes, elastic, q).values() if w is not None]
    return max(per_body) if per_body else float(omega[elastic].min())


def _lowest_per_body(system, omega, shapes, elastic, q) -> Dict[str, Optional[float]]:
    """Each flexible body's lowest elastic mode among ``omega`` (None if none is there)."""
    sparse = system.n_coords >= system.SPARSE_MODES_MIN
    M = system.M_sparse(q) if sparse else np.asarray(system.M(q))
    out: Dict[str, Optional[float]] = {}
    for body in system.body_names:
        if not system.capabilities(body)["elastic"]:
            continue
        sl = system.body_slice(body)
        if sparse:
            kinetic = np.einsum("ik,ik->k", shapes[sl], M[sl, sl] @ shapes[sl])
        else:
            kinetic = np.einsum("ik,ij,jk->k", shapes[sl], M[sl, sl], shapes[sl])  # mass-normalized: sums to 1
        mine = elastic & (kinetic > BODY_SHARE)
        out[body] = float(omega[mine].min()) if mine.any() else None
    return out


def damping_ratios(system, t0: float, q: np.ndarray, qd: np.ndarray, omega: np.ndarray, shapes: np.ndarray,
                   M: np.ndarray) -> np.ndarray:
    """Each mode's damping ratio ``zeta_k = -phi_k^T M dqdd/dqd phi_k / (2 omega_k)`` (mass-normalized
    ``phi_k``), by a central difference of the acceleration along the mode's velocity (gyroscopic
    terms, skew, drop out); zeros for an undamped scene and for modes with ``omega_k <= 0``."""
    zeta = np.zeros(omega.size)
    if not _has_damping(system):
        return zeta
    for k in np.flatnonzero(omega > 0.0):
        eps = 1e-6 * max(1.0, float(np.abs(qd).max())) / max(float(np.abs(shapes[:, k]).max()), 1e-300)
        dq = (np.asarray(system.qdd(t0, q, qd + eps * shapes[:, k])) - np.asarray(system.qdd(t0, q, qd - eps * shapes[:, k]))) / (2 * eps)
        zeta[k] = max(0.0, -float(shapes[:, k] @ (M @ dq)) / (2.0 * omega[k]))
    return zeta


def overdamped_roots(omega: np.ndarray, zeta: np.ndarray):
    """``(fast, slow)``: the decay rates ``omega (zeta +- sqrt(zeta^2 - 1))`` of each overdamped mode
    (``zeta > 1``; its motion is ``exp(-slow t)`` once ``exp(-fast t)`` has died out); ``omega``
    for the others."""
    over = zeta > 1.0
    root = np.sqrt(np.maximum(zeta * zeta - 1.0, 0.0))
    w = np.abs(omega)
    return np.where(over, w * (zeta + root), w), np.where(over, w * (zeta - root), w)


def _has_damping(system) -> bool:
    """Whether any body or force of the scene dissipates (a damping coefficient, a modal body's
    damping matrix ``d_ff``)."""
    d = system.description
    items = list(d.get("bodies", [])) + list(d.get("forces", []))
    return any(np.any(np.asarray(it.get(k) if it.get(k) is not None else 0.0, dtype=float) != 0.0)
               for it in items for k in ("damping", "d_ff"))


def _has_beam3(system) -> bool:
    """Whether the scene has a geometrically exact beam (``beam3``)."""
    return any(b.get("kind") == "beam3" for b in system.description.get("bodies", []))


def _has_elastic_potential(system) -> bool:
    """Whether any mode can store strain or spring energy: a flexible body, a geometrically exact
    beam (``beam3``: its elements store the strain energy between rigid node bodies; updated on
    purpose with the core's ``SceneTraits``, which had left the beam out and run it with DOPRI5)
    or a spring."""
    if any(system.capabilities(b)["elastic"] for b in system.body_names):
        return True
    if _has_beam3(system):
        return True
    return any(f.get("kind") == "spring_damper" and float(f.get("stiffness", 0.0)) > 0.0
               for f in system.description.get("forces", []))


def _spectrum(system, t0, q, qd, deadline):
    """``(omega, shapes, omega_max)`` for the chooser.  Small systems: every mode.  Large ones
    (sparse, ``System.SPARSE_MODES_MIN``): ``omega_max`` from ``System.max_frequency`` and the
    lowest modes by shift-invert Lanczos, ``FIRST_MODES`` then four times more until every
    flexible body's lowest elastic mode is among them; ``(None, None, omega_max)`` when no mode
    can be elastic (no flexible body, no spring)."""
    if system.n_coords < system.SPARSE_MODES_MIN:
        omega, shapes = system.frequencies(t0, q, qd, modes=True)
        return omega, shapes, float(np.abs(omega).max())
    omega_max = system.max_frequency(t0, q, qd, deadline=deadline)
    if not _has_elastic_potential(system):
        return None, None, omega_max
    qq = system.q0 if q is None else np.asarray(q, dtype=float)
    n_dof, k = system.n_dof, FIRST_MODES
    while True:
        omega, shapes = system.frequencies(t0, q, qd, modes=True, count=min(k, n_dof), deadline=deadline)
        if omega.size >= n_dof:
            break
        elastic = (omega > 0.0) & (elastic_shares(system, omega, shapes, qq) > ELASTIC_SHARE)
        found = _lowest_per_body(system, omega, shapes, elastic, qq)
        if (found and all(w is not None for w in found.values())) or (not found and elastic.any()):
            break
        k *= 4
    return omega, shapes, max(omega_max, float(np.abs(omega).max()))


def local_newton_ok(h: float, omega_max: float) -> bool:
    """Whether GENALPHA's Newton may stop at the local error level (``newton_local_error``) with
    step ``h`` on a system whose fastest mode is ``omega_max``: only on coarse steps."""
    return h * omega_max >= LOCAL_NEWTON_MIN_STEP_OMEGA


def _overdamped_choice(system, t0, q, qd, omega, shapes, shares, phase, span) -> Optional[MethodChoice]:
    """Adaptive RADAU5M when overdamped modes make an explicit step short: stiff dampers (MBS
    benchmark A05: spring-dampers with ``C = 4e4`` N s/m) turn a mode of frequency ``omega`` and
    damping ratio ``zeta > 1`` into a fast decay ``omega (zeta + sqrt(zeta^2 - 1))`` that bounds
    DOPRI5's step to ``DOPRI5_REAL_STABILITY`` over it, and a slow one ``omega (zeta - sqrt(zeta^2 -
    1))``, the motion left to resolve. The undamped frequencies miss both. When the step that the
    motion needs (the rule of the fixed-step choice, on the modes' slow rates) exceeds
    ``RADAU_COST_RATIO`` explicit steps, Radau IIA with its own error control is cheaper: the fast
    decays die out within a step (L-stable) and its error estimate sees them die. Small systems
    (every mode known) only; ``None`` otherwise."""
    if omega.size < system.n_dof or not _has_damping(system):
        return None
    qd0 = system.qd0 if qd is None else np.asarray(qd, dtype=float)
    zeta = damping_ratios(system, t0, q, qd0, omega, shapes, np.asarray(system.M(q)))
    over = zeta > 1.0
    if not over.any():
        return None
    fast, slow = overdamped_roots(omega, zeta)
    omega_m = lowest_elastic_frequency(system, np.where(omega > 0.0, slow, omega), shapes, shares, q)
    if omega_m is None:
        return None
    y = min(RADAU_MAX_STEP_OMEGA, (phase / (RADAU_DECAY * omega_m * span)) ** 0.2)
    h = min(y / omega_m, span / MIN_STEPS)
    h_explicit = DOPRI5_REAL_STABILITY / float(fast[over].max())
    if h <= RADAU_COST_RATIO * h_explicit:
        return None
    k = int(np.argmax(np.where(over, fast, 0.0)))
    return MethodChoice(
        "RADAU5M", omega_elastic=omega_m, omega_max=float(fast[over].max()),
        reason=(f"stiff by damping: the mode at {omega[k]:.4g} rad/s is overdamped (zeta {zeta[k]:.3g}): it decays at "
                f"{fast[k]:.4g} 1/s, which holds an explicit step to {h_explicit:.2g} s, while the motion "
                f"(slowest elastic rate {omega_m:.4g} 1/s) needs only ~{h:.2g} s: Radau IIA (L-stable) with its own "
                "step control"))


def choose_method(system, t0: float, t_end: float, rtol: float, q: Optional[np.ndarray] = None,
                  qd: Optional[np.ndarray] = None, deadline: Optional[float] = None) -> MethodChoice:
    """The integrator ``method="auto"`` runs for ``system`` over ``[t0, t_end]`` at ``rtol``
    (``deadline``: a ``time.perf_counter()`` value; past it ``ukflex.analysis.modes.BudgetExceeded``)."""
    span = float(t_end) - float(t0)
    if not (math.isfinite(span) and span > 0.0):
        raise ValueError(f"t_end must be finite and greater than t0 = {t0}, got {t_end!r}")
    _core.check_tolerances(rtol, [0.0], 1)  # the one tolerance rule (rust/integrate/options.rs)
    if system.n_dof == 0:
        return MethodChoice("DOPRI5", reason="no degrees of freedom: the motion is prescribed")
    if not _has_elastic_potential(system):  # leave out what a scene does not need
        return MethodChoice("DOPRI5", reason="no elastic mode (rigid bodies, no springs: no frequency analysis "
                                             "needed): not stiff, explicit")
    omega, shapes, omega_max = _spectrum(system, t0, q, qd, deadline)
    q = system.q0 if q is None else np.asarray(q, dtype=float)
    if omega is None:
        omega_c = None
    else:
        shares = elastic_shares(system, omega, shapes, q)
        omega_c = lowest_elastic_frequency(system, omega, shapes, shares, q)
    if omega_c is None:
        return MethodChoice("DOPRI5", omega_max=omega_max,
                            reason=f"no elastic mode (fastest mode {omega_max:.4g} rad/s): not stiff, explicit")
    phase = min(PHASE_CAP, PHASE_PER_RTOL * rtol)
    y = min(RADAU_MAX_STEP_OMEGA, (phase / (RADAU_DECAY * omega_c * span)) ** 0.2)
    h = min(y / omega_c, span / MIN_STEPS)
    if h * omega_max > EXPLICIT_STEP_OMEGA * RADAU_COST_RATIO:
        # changed deliberately with the core (i26-def): an overdamped lowest elastic mode has no
        # oscillation for the fixed step to resolve, so the overdamped rule decides first
        if omega.size >= system.n_dof and _has_damping(system):
            qd0 = system.qd0 if qd is None else np.asarray(qd, dtype=float)
            zeta = damping_ratios(system, t0, q, qd0, omega, shapes, np.asarray(system.M(q)))
            kc = np.flatnonzero(omega == omega_c)
            if kc.size and zeta[kc[0]] > 1.0:
                damped = _overdamped_choice(system, t0, q, qd, omega, shapes, shares, phase, span)
                if damped is not None:
                    return damped
        floor: Dict[str, Any] = {}
        if omega.size >= system.n_dof:  # every mode known (small systems): the floor
            qd0 = system.qd0 if qd is None else np.asarray(qd, dtype=float)
            floor = transient_floor(system, t0, q, qd0, omega, shapes, omega_c, h, span)
        said = ""
        if floor.get("floor"):
            said = (f"; the fast modes the start sets off (largest at {floor['floor_modes'][0][0]:.4g} rad/s) are "
                    f"damped: the history stays ~{floor['floor']:.1e} m off at a body point whatever rtol "
                    "(method='DOPRI5' keeps them)")
        return MethodChoice(
            "RADAU5M", options={"step": h}, omega_elastic=omega_c, omega_max=omega_max, step=h,
            rtol=min(NEWTON_PER_RTOL * rtol, NEWTON_MAX_RTOL_BEAM,
                     NEWTON_MAX_RTOL_BEAM * (rtol / NEWTON_BEAM_FULL_RTOL) ** NEWTON_BEAM_EXPONENT)
            if _has_beam3(system) else min(NEWTON_PER_RTOL * rtol, NEWTON_MAX_RTOL), **floor,
            reason=(f"stiff: the step {h:.3g} s ({omega_c * h:.2g} rad of the lowest elastic mode, {omega_c:.4g} rad/s, "
                    f"amplitude loss {RADAU_DECAY * (omega_c * h) ** 5 * omega_c * span:.1e} over the run) is "
                    f"{h * omega_max:.3g}/omega_max ({omega_max:.4g} rad/s), beyond what an explicit method may take "
                    f"(~{EXPLICIT_STEP_OMEGA * RADAU_COST_RATIO:g}/omega_max at equal cost): Radau IIA (order 5, "
                    "L-stable) damps the fast modes instead of resolving them" + said))
    damped = _overdamped_choice(system, t0, q, qd, omega, shapes, shares, phase, span)
    if damped is not None:  # after the fixed-step rule: the scenes it takes keep their tuned step
        return damped
    return MethodChoice(
        "DOPRI5", omega_elastic=omega_c, omega_max=omega_max,
        reason=(f"not stiff at this tolerance: the step {h:.3g} s that resolves the lowest elastic mode "
                f"({omega_c:.4g} rad/s) to an amplitude loss of {phase:.2g} over the run is only "
                f"{h * omega_max:.3g}/omega_max ({omega_max:.4g} rad/s): explicit, fifth order, is cheaper"))
