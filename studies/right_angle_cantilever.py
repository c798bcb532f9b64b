"""``python -m studies right-angle-cantilever``: Simo and Vu-Quoc's right-angle cantilever (1988,
"On the dynamics in space of rods undergoing large motions - a geometrically exact approach",
CMAME 66): two members of length 10 in the ``x y`` plane, the first from the clamped root
``(0, 0, 0)`` to the elbow ``(10, 0, 0)``, the second from the elbow to the tip ``(10, 10, 0)``;
``EA = GA = 1e6``, ``GJ = EI = 1e3``, ``rho A = 1``, ``rho J = diag(20, 10, 10)``; an
out-of-plane force ``F_z`` at the elbow, a triangular pulse ``0 -> 50`` at ``t = 1 -> 0`` at
``t = 2``, then free vibration to ``t = 30``.

ukflex: two ``SpatialScene.beam`` members welded at the elbow with ``fixed``, the pulse a
``point_load`` expression of ``t``. Exudyn 1.13.6: ``ObjectBeamGeometricallyExact`` elements on
``NodeRigidBodyEP`` nodes, the members joined by a ``GenericJoint``, the pulse a Python
``loadVectorUserFunction``, generalized-alpha without numerical damping (spectral radius 1).

Output: the displacement histories of the elbow and the tip, every 0.1 s; the gap between the
two codes, each converged in mesh and in time, and the wall times of ukflex's default
``simulate()`` and of Exudyn's ``SolveDynamic`` at equal accuracy (medians of interleaved
repetitions).
"""

from __future__ import annotations

import sys
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

import ukflex
from studies import _exudyn_beam as xb

L, EA, GA, GJ, EI, RHO_A, RHO_J = 10.0, 1e6, 1e6, 1e3, 1e3, 1.0, (20.0, 10.0, 10.0)
T_END = 30.0
#: the meshes (elements per member) of each code: ukflex's default ``simulate()`` and its
#: time-converged run (RADAU5 at rtol 1e-9) on each; Exudyn at each of ``STEPS`` steps over 30 s
UK_MESHES = (5, 10, 20, 40)
EX_MESHES = (10, 20, 40, 80)
STEPS = (500, 1000, 3000)
#: Exudyn's time-converged run: 3000 steps (within 1.3e-4 of 24000 at 10 elements per member,
#: 9.1e-5 of 6000 at 20)
EX_REF_STEPS = 3000


def exudyn_newton_rtol(elements: int) -> float:
    """Exudyn's Newton tolerance on a mesh of ``elements`` per member. Its default 1e-8 (relative
    to the initial residual) is below what the residual reaches in rounding on fine meshes: in
    the first steps, where the load is still small, it stalls at 1.0e-8 .. 2.6e-8 (20 elements per
    member) and 3.7e-7 .. 4.0e-7 (80), at every step size ("SolveDynamic terminated"). 1e-7 runs
    up to 40 elements (and moves the 10-element history by 2e-5 of its largest displacement),
    1e-6 beyond (it moves the 20-element history by 4e-7)."""
    return 1e-7 if elements <= 40 else 1e-6


#: the accuracy targets on the history (issue 31)
TARGETS = (5e-3, 1e-3)
#: the triangular pulse 50 max(0, 1 - |t - 1|), written with abs
PULSE = "25 * (1 - abs(t - 1) + abs(1 - abs(t - 1)))"


def pulse(t: float) -> float:
    return 50.0 * max(0.0, 1.0 - abs(t - 1.0))


def scene(elements: int) -> ukflex.SpatialScene:
    """The frame with ``elements`` beam elements per member."""
    s = ukflex.SpatialScene()
    sec = ukflex.CustomSection3(ea=EA, ga_y=GA, ga_z=GA, gj=GJ, ei_y=EI, ei_z=EI, mass_per_length=RHO_A, rotary_inertia=RHO_J)
    a = s.beam("a", (0, 0, 0), (L, 0, 0), sec, elements=elements)
    b = s.beam("b", (L, 0, 0), (L, L, 0), sec, elements=elements)
    s.fixed(s.ground.marker((0, 0, 0)), a.node(0), name="root")
    # the elbow: world axes on both sides (b's section frame is [y, -x, z] of the world)
    s.fixed(a.node(-1, z=(0, 0, 1), x=(1, 0, 0)), b.node(0, z=(0, 0, 1), x=(0, -1, 0)), name="elbow")
    s.point_load(a.node(-1), [0, 0, PULSE], name="pulse")
    return s


def _node_point(system: ukflex.System, q: np.ndarray, body: str, elements: int) -> np.ndarray:
    """The world position of an end node of a member (its body's ``r`` is the end segment's
    centre of mass, a quarter element inwards along the section's axis)."""
    i = system.body_names.index(body)
    qq = q[7 * i:7 * i + 7]
    p = qq[3:] / np.linalg.norm(qq[3:], axis=0)
    ax = np.array([p[0] ** 2 + p[1] ** 2 - p[2] ** 2 - p[3] ** 2, 2 * (p[1] * p[2] + p[0] * p[3]), 2 * (p[1] * p[3] - p[0] * p[2])])
    return qq[:3] + 0.25 * L / elements * ax


def ukflex_run(elements: int, t: np.ndarray, **run: Any) -> Tuple[np.ndarray, np.ndarray, float]:
    """Elbow and tip displacements ``(nt, 3)`` each at ``t`` and the wall time of ``simulate``
    (a freshly built System)."""
    system = ukflex.System(scene(elements))
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END if t[-1] >= T_END else float(t[-1]), t_eval=t, **run)
    dt = time.perf_counter() - t0
    if res.status != 0:
        raise RuntimeError(f"ukflex: {res.message}")
    q = np.asarray(res.q)
    elbow = _node_point(system, q, f"a[{elements}]", elements).T - [L, 0, 0]
    tip = _node_point(system, q, f"b[{elements}]", elements).T - [L, L, 0]
    return elbow, tip, dt


def exudyn_run(elements: int, t: np.ndarray, steps: int, spectral_radius: float = 1.0,
               settings: Optional[Dict[str, Any]] = None) -> Tuple[np.ndarray, np.ndarray, float]:
    """The same frame in Exudyn: elbow and tip displacements interpolated at ``t`` from its
    ``steps`` steps over ``[0, t[-1]]`` (generalized-alpha at ``spectral_radius``), and the wall
    time of ``mbs.SolveDynamic``."""
    import exudyn as exu
    from exudyn.itemInterface import Force, GenericJoint, MarkerBodyRigid, MarkerNodeRigid, ObjectGround, SensorNode
    from exudyn.rigidBodyUtilities import RotationMatrixZ

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    sec = xb.beam_section(EA, GA, GA, GJ, EI, EI, RHO_A, RHO_J)
    rot_b = RotationMatrixZ(np.pi / 2)
    na = xb.add_member(mbs, (0.0, 0.0, 0.0), np.eye(3), L, elements, sec)
    nb = xb.add_member(mbs, (L, 0.0, 0.0), rot_b, L, elements, sec)
    ground = mbs.AddObject(ObjectGround())
    mg = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0, 0, 0]))
    mbs.AddObject(GenericJoint(markerNumbers=[mg, mbs.AddMarker(MarkerNodeRigid(nodeNumber=na[0]))], constrainedAxes=[1] * 6))
    m_elbow = mbs.AddMarker(MarkerNodeRigid(nodeNumber=na[-1]))
    # joint frames: the elbow node of a in its own axes (the world's), b's first node turned back
    mbs.AddObject(GenericJoint(markerNumbers=[m_elbow, mbs.AddMarker(MarkerNodeRigid(nodeNumber=nb[0]))],
                               rotationMarker1=rot_b.T, constrainedAxes=[1] * 6))
    mbs.AddLoad(Force(markerNumber=m_elbow, loadVector=[0, 0, 1.0], loadVectorUserFunction=lambda mbs, t, v: [0, 0, pulse(t)]))
    s_elbow = mbs.AddSensor(SensorNode(nodeNumber=na[-1], outputVariableType=exu.OutputVariableType.Displacement, storeInternal=True))
    s_tip = mbs.AddSensor(SensorNode(nodeNumber=nb[-1], outputVariableType=exu.OutputVariableType.Displacement, storeInternal=True))
    mbs.Assemble()
    # its sparse solver: the dense default factors the whole (n + m) matrix (at 40 elements per
    # member and 3000 steps 59 s against 13 s, the same answer to 1e-9; one run each)
    ss = xb.settings(float(t[-1]), steps, spectral_radius, newton_rtol=exudyn_newton_rtol(elements), sparse=True, overrides=settings)
    dt = xb.solve(mbs, ss)
    return xb.history(mbs, s_elbow, t), xb.history(mbs, s_tip, t), dt


def gap(a: Tuple[np.ndarray, np.ndarray], b: Tuple[np.ndarray, np.ndarray]) -> float:
    """Largest distance between two histories of the elbow and the tip, over the largest
    displacement of ``b``."""
    d = max(np.max(np.linalg.norm(x - y, axis=1)) for x, y in zip(a, b))
    return float(d / max(np.max(np.linalg.norm(y, axis=1)) for y in b))


def richardson(coarse: Tuple[np.ndarray, ...], fine: Tuple[np.ndarray, ...]) -> Tuple[np.ndarray, np.ndarray]:
    """The mesh limit of two histories at ``n`` and ``2 n`` elements per member of a second-order
    discretization: ``fine + (fine - coarse) / 3`` (both codes converge at second order, measured)."""
    return fine[0] + (fine[0] - coarse[0]) / 3.0, fine[1] + (fine[1] - coarse[1]) / 3.0


def _log(msg: str) -> None:
    print(f"[right-angle-cantilever {time.perf_counter() - _T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


_T0 = time.perf_counter()
Run = Tuple[np.ndarray, np.ndarray, float]


def _converged(t: np.ndarray, uk_meshes: Sequence[int], ex_meshes: Sequence[int], done: Dict[Tuple[str, int, int], List[Run]]
               ) -> Tuple[Dict[int, Run], Dict[int, Run], List[str], Tuple[np.ndarray, np.ndarray]]:
    """Each code's time-converged run on each of its meshes (Exudyn's from ``done``, the timed
    runs, when there), the table of their gaps to the two mesh limits (Richardson on each code's
    two finest meshes) and ukflex's mesh limit."""
    ref_u: Dict[int, Run] = {}
    ref_x: Dict[int, Run] = {}
    for n in uk_meshes:
        _log(f"ukflex {n} el./member, RADAU5 rtol 1e-9")
        ref_u[n] = ukflex_run(n, t, method="RADAU5", rtol=1e-9, atol=1e-10)
    for n in ex_meshes:
        if ("Exudyn", n, EX_REF_STEPS) not in done:
            _log(f"Exudyn {n} el./member, {EX_REF_STEPS} steps")
        ref_x[n] = done[("Exudyn", n, EX_REF_STEPS)][0] if ("Exudyn", n, EX_REF_STEPS) in done else exudyn_run(n, t, EX_REF_STEPS)
    nu, nx = sorted(ref_u)[-2:], sorted(ref_x)[-2:]
    lim_u, lim_x = richardson(ref_u[nu[0]], ref_u[nu[1]]), richardson(ref_x[nx[0]], ref_x[nx[1]])
    lines = [f"mesh limits: ukflex's Richardson {nu[0]}/{nu[1]} (the reference below) against Exudyn's {nx[0]}/{nx[1]}: "
             f"gap {gap(lim_x, lim_u):.2e}; elbow max u_z {np.max(np.abs(lim_u[0][:, 2])):.4f} / {np.max(np.abs(lim_x[0][:, 2])):.4f}, "
             f"tip max u_z {np.max(np.abs(lim_u[1][:, 2])):.4f} / {np.max(np.abs(lim_x[1][:, 2])):.4f}",
             "", "| code | el./member | time-converged run | elbow max u_z | tip max u_z | to ukflex's mesh limit | to Exudyn's mesh limit |",
             "|---|---:|---|---:|---:|---:|---:|"]
    for code, refs, run in (("ukflex", ref_u, "RADAU5 rtol 1e-9"), ("Exudyn", ref_x, f"{EX_REF_STEPS} steps")):
        for n, r in refs.items():
            lines.append(f"| {code} | {n} | {run} | {np.max(np.abs(r[0][:, 2])):.4f} | {np.max(np.abs(r[1][:, 2])):.4f} | "
                         f"{gap(r[:2], lim_u):.2e} | {gap(r[:2], lim_x):.2e} |")
    return ref_u, ref_x, lines + ["", f"reference: ukflex's mesh limit; elbow max u_z {np.max(np.abs(lim_u[0][:, 2])):.4f}"], lim_u


def published(elements: int, step: Optional[float] = None) -> int:
    """ukflex's time-converged run (RADAU5 at rtol 1e-9, outputs every 0.01 s) on ``elements``
    per member against the extrema of Simo and Vu-Quoc's published curves, as read from their
    figure, and against those of a third code's computed histories (AeroBeams.jl's,
    ``studies/_rac_published.py``). ``step``: instead, generalized-alpha without numerical
    damping (``rho_inf = 1``: Newmark's average acceleration, as Simo and Vu-Quoc's scheme) at
    that fixed step, e.g. 0.25 s (what a large step of the original computation would do)."""
    from studies import _rac_published as pub

    t = np.linspace(0.0, T_END, 3001)
    run = dict(method="RADAU5", rtol=1e-9, atol=1e-10) if step is None else dict(method="GENALPHA", step=step, rho_inf=1.0, rtol=1e-8)
    how = "RADAU5 rtol 1e-9" if step is None else f"generalized-alpha rho_inf 1, fixed step {step} s"
    _log(f"ukflex {elements} el./member, {how}")
    elbow, tip, _ = ukflex_run(elements, t, **run)
    scale = max(np.max(np.abs(elbow[:, 2])), np.max(np.abs(tip[:, 2])))
    print(f"ukflex {elements} el./member, {how}, against the published curves (read from the figure); max |u_z| {scale:.4f}")
    print("\n".join(pub.compare(t, elbow[:, 2], tip[:, 2], scale)))
    print(f"\nukflex and the published readings against AeroBeams.jl's computed histories (20 el./member, step 0.05 s)")
    print("\n".join(pub.compare_computed(t, elbow[:, 2], tip[:, 2], scale)))
    return 0


def main(argv: Optional[List[str]] = None) -> int:
    """The converged comparison (each code's time-converged runs on its meshes, the mesh limits by
    Richardson extrapolation of the two finest) and the speed at equal accuracy: ukflex's default
    ``simulate()`` on each mesh and Exudyn at ``STEPS`` on each of its meshes, each run's error
    against ukflex's mesh limit and its wall time (medians of ``--repeat`` interleaved runs of
    ukflex, ``--exudyn-repeat`` of Exudyn, a fresh System / SystemContainer each), and per target
    the fastest run of each code within it."""
    import argparse

    ap = argparse.ArgumentParser(prog="python -m studies right-angle-cantilever")
    ap.add_argument("--meshes", default=",".join(map(str, UK_MESHES)), help="ukflex's elements per member")
    ap.add_argument("--exudyn-meshes", default=",".join(map(str, EX_MESHES)), help="Exudyn's elements per member")
    ap.add_argument("--steps", default=",".join(map(str, STEPS)), help="Exudyn's step counts over 30 s")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved repetitions of ukflex's timed runs")
    ap.add_argument("--exudyn-repeat", type=int, default=1, help="... of Exudyn's (a minute and more each on the fine meshes)")
    ap.add_argument("--quick", action="store_true", help="meshes 5, 10, 20 (Exudyn 10, 20, 40), one repetition")
    ap.add_argument("--published", type=int, nargs="?", const=20, metavar="ELEMENTS",
                    help="only ukflex (ELEMENTS per member, 20 if not given) against Simo and Vu-Quoc's published curves")
    ap.add_argument("--step", type=float, default=None,
                    help="with --published: generalized-alpha (rho_inf 1, Newmark's average acceleration) at this fixed step [s]")
    args = ap.parse_args(argv)
    if args.published:
        return published(args.published, args.step)

    def ints(text: str) -> Tuple[int, ...]:
        return tuple(int(x) for x in text.split(","))

    uk_meshes, ex_meshes, steps, repeat = ints(args.meshes), ints(args.exudyn_meshes), ints(args.steps), args.repeat
    if args.quick:
        uk_meshes, ex_meshes, repeat = (5, 10, 20), (10, 20, 40), 1
    t = np.linspace(0.0, T_END, 301)
    runs: Dict[Tuple[str, int, int], List[Run]] = {}
    failed: List[str] = []
    for k in range(repeat):
        for n in uk_meshes:
            _log(f"repetition {k + 1}/{repeat}: ukflex {n} el./member, default simulate()")
            runs.setdefault(("ukflex default simulate()", n, 0), []).append(ukflex_run(n, t))
        if k < args.exudyn_repeat:
            xb.run_grid(runs, failed, ex_meshes, steps, lambda n, st: exudyn_run(n, t, st), _log,
                        prefix=f"repetition {k + 1}/{repeat}: ", unit="el./member")
    ref_u, ref_x, lines, lim = _converged(t, uk_meshes, ex_meshes, runs)
    lines += failed + ["", "| code | el./member | steps | error (to the mesh limit) | to its own time-converged run | wall time [s], median |",
              "|---|---:|---:|---:|---:|---:|"]
    timed = []
    for (code, n, st), rs in runs.items():
        err, own = gap(rs[0][:2], lim), gap(rs[0][:2], (ref_u if code.startswith("ukflex") else ref_x)[n][:2])
        wall = float(np.median([r[2] for r in rs]))
        timed.append((code, n, st, err, wall))
        lines.append(f"| {code} | {n} | {st or 'auto'} | {err:.2e} | {own:.2e} | {wall:.2f} |")
    lines += ["", "| target | ukflex: fastest default run within it | Exudyn: fastest run within it | Exudyn / ukflex |", "|---|---|---|---:|"]
    for target in TARGETS:
        best = [min((r for r in timed if r[0].startswith(c) and r[3] <= target), key=lambda r: r[4], default=None) for c in ("ukflex", "Exudyn")]
        cells = [f"{b[1]} el., {b[2] or 'auto'}: {b[3]:.2e} in {b[4]:.2f} s" if b else "none" for b in best]
        ratio = f"{best[1][4] / best[0][4]:.1f}" if best[0] and best[1] else "n/a"
        lines.append(f"| {target:.1%} | {cells[0]} | {cells[1]} | {ratio} |")
    print("gap, error = max over the 301 outputs (0.1 s) of |elbow and tip displacement - reference| / max |reference displacement|")
    print("\n".join(lines))
    _log("done")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
