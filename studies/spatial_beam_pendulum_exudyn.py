"""``python -m studies spatial-beam-pendulum-exudyn``: the 3D flexible pendulum's geometrically
exact beam (the ``beam3`` model of ``python -m studies spatial-beam-pendulum``) side by side
with Exudyn 1.13.6's ``ObjectBeamGeometricallyExact`` (docs/spatial-flexible.md).

The pendulum: a 0.5 m x 20 mm x 20 mm bar (rho = 7850 kg/m^3, E = 2.1 GPa, nu = 0.3) on a
spherical joint at its end, spin 3 rad/s about z, gravity -z, 0.3 s. Exudyn: the same section
data (``_exudyn_beam.rectangle_section``: Cowper's shear factor, Saint-Venant's torsion
constant, the section's rotary inertia), ``NodeRigidBodyEP`` nodes with the rigid spin as
initial velocities, a ``SphericalJoint`` at the first node, gravity as the nodal weights of its
lumped mass (``rho A L_e / 2`` per element end, which is its element's own mass lumping),
generalized-alpha at spectral radius 1, its sparse solver.

Output: the tip (the last node) at 61 instants. Error of a history: the largest distance to
the reference over the elastic part of the tip motion (the reference against the rigid bar of
the same mass and inertia, ``rigid3``); also stated over the length. Reference: ukflex's mesh
limit (Richardson extrapolation of its two finest meshes, each time-converged).
"""

from __future__ import annotations

import sys
import time
import types
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from studies import _exudyn_beam as xb
from studies.spatial_beam_pendulum import E, NU, RHO, SIDE, beam_tip, rigid_tip
from studies.spatial_flexible_exudyn import GRAVITY, LENGTH, OMEGA0, T_END

#: ukflex's meshes (elements), each time-converged with ``UK_REF`` ...
UK_MESHES = (10, 20, 40, 80)
#: ... the default ``simulate()`` at these rtol (only rtol set) ...
UK_RTOLS = (1e-6, 1e-7, 1e-8, 1e-9)
#: ... and its time-converged run: ``method="auto"`` at rtol 1e-10 (within 1.5e-4 of the
#: elastic part of DOPRI5 at rtol 1e-11 at 10 and 20 elements)
UK_REF = {"rtol": 1e-10}
#: Exudyn's meshes and step counts over 0.3 s; its time-converged runs at ``EX_REF_STEPS``
#: (its time error falls as about h^1.5 here, at spectral radius 1, 0.7 and 0.4 alike: its
#: mesh limit 80/160 is 7.8e-3, 3.8e-3 and 8.9e-4 of the elastic part from ukflex's at 2000,
#: 4000 and 8000 steps)
EX_MESHES = (40, 80, 160)
STEPS = (1000, 2000, 4000, 8000)
EX_REF_STEPS = 8000
#: Exudyn's Newton goal relative to the initial residual: its default 1e-8 makes it cut its
#: steps on fine meshes (80 elements at 4000 steps: 208 s against 16 s at 1e-6)
EX_NEWTON_RTOL = 1e-6
#: the accuracy targets on the history, over the elastic part (issue 31)
TARGETS = (5e-3, 1e-3)

Run = Tuple[np.ndarray, float]


def exudyn_tip(elements: int, t: np.ndarray, steps: int, **settings: Any) -> Run:
    """The pendulum in Exudyn: the tip node's positions at ``t`` (interpolated from its
    ``steps`` steps) and the wall time of ``mbs.SolveDynamic`` (a fresh SystemContainer)."""
    import exudyn as exu
    from exudyn.itemInterface import Force, MarkerBodyPosition, MarkerNodePosition, ObjectGround, SensorNode, SphericalJoint

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    sec = xb.rectangle_section(SIDE, SIDE, RHO, E, NU)
    nodes = xb.add_member(mbs, (0.0, 0.0, 0.0), np.eye(3), LENGTH, elements, xb.beam_section(**sec), angular_velocity=OMEGA0)
    le = LENGTH / elements
    for k, n in enumerate(nodes):
        weight = sec["mass_per_length"] * le * (0.5 if k in (0, elements) else 1.0) * np.asarray(GRAVITY)
        mbs.AddLoad(Force(markerNumber=mbs.AddMarker(MarkerNodePosition(nodeNumber=n)), loadVector=list(weight)))
    ground = mbs.AddObject(ObjectGround())
    mbs.AddObject(SphericalJoint(markerNumbers=[mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0])),
                                               mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[0]))]))
    tip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], outputVariableType=exu.OutputVariableType.Position, storeInternal=True))
    mbs.Assemble()
    dt = xb.solve(mbs, xb.settings(T_END, steps, sparse=True, **{"newton_rtol": EX_NEWTON_RTOL, **settings}))
    return xb.history(mbs, tip, t), dt


def rigid_bar_tip(t: np.ndarray) -> np.ndarray:
    """The tip of the rigid bar of the same mass and inertia (``rigid3``, DOPRI5 at rtol 1e-10)."""
    m = RHO * SIDE * SIDE * LENGTH
    across = m * (LENGTH ** 2 + SIDE ** 2) / 12
    bar = types.SimpleNamespace(mass=m, com=(0.5 * LENGTH, 0.0, 0.0), inertia=np.diag([m * SIDE * SIDE / 6, across, across]))
    return rigid_tip(bar, t)


def richardson(coarse: np.ndarray, fine: np.ndarray) -> np.ndarray:
    """The mesh limit of two histories at ``n`` and ``2 n`` elements of a second-order
    discretization (both codes converge at second order here, measured in the study)."""
    return fine + (fine - coarse) / 3.0


def gap(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two tip histories (m)."""
    return float(np.max(np.linalg.norm(a - b, axis=1)))


_T0 = time.perf_counter()


def _log(msg: str) -> None:
    print(f"[spatial-beam-pendulum-exudyn {time.perf_counter() - _T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


def _converged(t: np.ndarray, uk_meshes: Sequence[int], ex_meshes: Sequence[int], ex_ref_steps: int,
               done: Dict[Tuple[str, int, Any], List[Run]]) -> Tuple[np.ndarray, float, List[str]]:
    """Each code's time-converged runs on its meshes (Exudyn's from ``done``, the timed runs),
    their mesh limits (Richardson on the two finest meshes), the elastic part of the motion and
    the table of the converged runs."""
    ref_u = {}
    for n in uk_meshes:
        _log(f"ukflex {n} elements, rtol {UK_REF['rtol']:g} (time-converged)")
        ref_u[n] = beam_tip(n, t, **UK_REF)[0]
    ref_x = {n: done[("Exudyn", n, ex_ref_steps)][0][0] for n in ex_meshes}
    nu, nx = sorted(ref_u)[-2:], sorted(ref_x)[-2:]
    lim_u, lim_x = richardson(ref_u[nu[0]], ref_u[nu[1]]), richardson(ref_x[nx[0]], ref_x[nx[1]])
    elastic = gap(lim_u, rigid_bar_tip(t))
    lines = [f"elastic part of the tip motion (ukflex's mesh limit against the rigid bar): {elastic:.3e} m = {elastic / LENGTH:.2e} L",
             f"mesh limits: ukflex's Richardson {nu[0]}/{nu[1]} (the reference) against Exudyn's {nx[0]}/{nx[1]} ({ex_ref_steps} steps): "
             f"{gap(lim_x, lim_u):.2e} m = {gap(lim_x, lim_u) / elastic:.2e} of the elastic part = {gap(lim_x, lim_u) / LENGTH:.2e} L",
             "", "| code | elements | time-converged run | to ukflex's mesh limit / elastic part | to Exudyn's mesh limit / elastic part |",
             "|---|---:|---|---:|---:|"]
    for code, refs, run in (("ukflex", ref_u, f"auto, rtol {UK_REF['rtol']:g}"), ("Exudyn", ref_x, f"{ex_ref_steps} steps")):
        for n, r in refs.items():
            lines.append(f"| {code} | {n} | {run} | {gap(r, lim_u) / elastic:.2e} | {gap(r, lim_x) / elastic:.2e} |")
    return lim_u, elastic, lines


def fastest_within(timed: Sequence[Tuple[str, int, Any, float, float]], code: str, target: float) -> Optional[Tuple[str, int, Any, float, float]]:
    """The fastest of ``code``'s runs ``(code, elements, setting, error, wall time)`` whose
    error is within ``target``, or None."""
    return min((r for r in timed if r[0] == code and r[3] <= target), key=lambda r: r[4], default=None)


def main(argv: Optional[List[str]] = None) -> int:
    """The speed at equal accuracy and the converged comparison: ukflex's default
    ``simulate()`` (``method="auto"``, only rtol set) on each mesh at each of ``UK_RTOLS`` and
    Exudyn on each of its meshes at each of ``STEPS`` (the last its time-converged run), each
    run's error against ukflex's mesh limit and its wall time (medians of ``--repeat``
    interleaved repetitions of ukflex, one of Exudyn; a fresh System / SystemContainer each),
    and per target the fastest run of each code within it."""
    import argparse

    ap = argparse.ArgumentParser(prog="python -m studies spatial-beam-pendulum-exudyn")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved repetitions of ukflex's timed runs")
    ap.add_argument("--quick", action="store_true", help="Exudyn 40 and 80 elements up to 4000 steps (its reference at 4000), one repetition")
    args = ap.parse_args(argv)
    ex_meshes, steps, repeat = (EX_MESHES[:2], STEPS[:3], 1) if args.quick else (EX_MESHES, STEPS, args.repeat)
    t = np.linspace(0.0, T_END, 61)
    runs: Dict[Tuple[str, int, Any], List[Run]] = {}
    failed: List[str] = []
    for k in range(repeat):
        for n in UK_MESHES:
            for rtol in UK_RTOLS:
                _log(f"repetition {k + 1}/{repeat}: ukflex {n} elements, default simulate(rtol={rtol:g})")
                runs.setdefault(("ukflex", n, rtol), []).append(beam_tip(n, t, rtol=rtol))
        if k == 0:
            xb.run_grid(runs, failed, ex_meshes, steps, lambda n, st: exudyn_tip(n, t, st), _log)
    lim, elastic, lines = _converged(t, UK_MESHES, ex_meshes, steps[-1], runs)
    lines += failed + ["", "| code | elements | rtol / steps | error / elastic part | error / L | wall time [s], median |",
                       "|---|---:|---:|---:|---:|---:|"]
    timed = []
    for (code, n, setting), rs in runs.items():
        err, wall = gap(rs[0][0], lim), float(np.median([r[1] for r in rs]))
        timed.append((code, n, setting, err / elastic, wall))
        cell = f"rtol {setting:g}" if code == "ukflex" else f"{setting} steps"
        lines.append(f"| {code} | {n} | {cell} | {err / elastic:.2e} | {err / LENGTH:.2e} | {wall:.3f} |")
    lines += ["", "| target (of the elastic part) | ukflex: fastest default run within it | Exudyn: fastest run within it | Exudyn / ukflex |",
              "|---|---|---|---:|"]
    for target in TARGETS:
        best = [fastest_within(timed, c, target) for c in ("ukflex", "Exudyn")]
        cells = [f"{b[1]} el., {'rtol %g' % b[2] if b[0] == 'ukflex' else '%d steps' % b[2]}: {b[3]:.2e} in {b[4]:.3f} s" if b else "none"
                 for b in best]
        ratio = f"{best[1][4] / best[0][4]:.0f}" if best[0] and best[1] else "n/a"
        lines.append(f"| {target:.1%} | {cells[0]} | {cells[1]} | {ratio} |")
    print("\n".join(lines))
    _log("done")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
