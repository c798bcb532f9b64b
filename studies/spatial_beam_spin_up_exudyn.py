"""``python -m studies spatial-beam-spin-up-exudyn``: Kane's spin-up beam in 3D (the beam of
``studies/spatial_beam_spin_up.py``) three ways, and against Exudyn.

1. The beam as a 3D modal body (``flexible3``) from the FE data of a solid bar with the same
   ``EA``, in-plane ``EI``, out-of-plane ``3 EI`` and ``rho A`` (a ``b x h`` rectangle,
   ``h = sqrt(3) b``), clamped modes, with and without ``stress_stiffening``, against the
   geometrically exact ``beam3`` (and the planar ANCF cable of the first study).
2. The same spin-up in Exudyn 1.13.6: ``ObjectBeamGeometricallyExact`` elements on
   ``NodeRigidBodyEP`` nodes, the first node held to a hub (``NodeRigidBodyRxyz`` rigid body) by a
   ``GenericJoint``, the hub's six coordinates prescribed by ``CoordinateConstraint`` s (its
   angle about z a Python ``offsetUserFunction`` of Kane's profile), generalized-alpha without
   numerical damping.

Output: the tip's deflection in the hub frame, ``v`` (across, in the plane of the spin) and
``u`` (along), at 0.1 s intervals; gaps in units of the dip (the largest ``|v|``); wall times of
the whole solve call on a fresh system, medians of interleaved repetitions. The whole study took
6 min 14 s on the shared machine (load 5-6); the tables are in docs/spatial-flexible.md.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

import ukflex
from studies._exudyn_beam import add_member, beam_section, history, settings, solve
from studies.right_angle_cantilever import richardson
from studies.spatial_beam_spin_up import EA, EI, GA, L, MU, OMEGA, T_END, T_SPIN, _in_hub_frame, beam3, cable, hub_angle

#: the solid bar with Kane's beam's EA, EI (in-plane, bending about z: width b along y) and 3 EI
#: out of the plane (height h = sqrt(3) b along z), rho A; E from EA
B = math.sqrt(12.0 * EI / EA)
H = math.sqrt(3.0) * B
E_SOLID = EA / (B * H)
RHO = MU / (B * H)
NU = 0.3
#: the accuracy targets on the history (issue 31), in units of the dip
TARGETS = (5e-3, 1e-3)

Hist = Tuple[np.ndarray, np.ndarray]


def _log(msg: str) -> None:
    print(f"[spin-up-exudyn {time.perf_counter() - _T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


_T0 = time.perf_counter()


def hub_rate(t: float) -> float:
    """The derivative of ``hub_angle``."""
    u = min(t, T_SPIN)
    return OMEGA / T_SPIN * (u - T_SPIN / (2.0 * math.pi) * math.sin(2.0 * math.pi / T_SPIN * u)) + OMEGA * (t - u)


def kane_motion() -> str:
    """Kane's profile as a ukflex expression of ``t`` (``hub_angle``)."""
    u = f"((t + {T_SPIN!r} - abs(t - {T_SPIN!r})) / 2)"
    c = (T_SPIN / (2.0 * math.pi)) ** 2
    return f"{OMEGA / T_SPIN!r} * ({u}^2 / 2 + {c!r} * (cos({2.0 * math.pi / T_SPIN!r} * {u}) - 1)) + {OMEGA!r} * (t - {u})"


def fe_data(cells: Sequence[int], modes: int, **kw: Any) -> Any:
    """The clamped-mode data of the solid bar on ``cells`` P2 tetrahedra boxes."""
    from ukflex import fe3

    mesh = fe3.bar_mesh(L, B, H, tuple(cells))
    return fe3.from_mesh(mesh, density=RHO, youngs_modulus=E_SOLID, poisson_ratio=NU,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9, "B": lambda x: x[:, 0] > L - 1e-9}, modes=modes,
                         frame=("clamped", "A"), **kw)


def modal(t: np.ndarray, data: Any, stiffening: bool, **run: Any) -> Tuple[np.ndarray, np.ndarray, float, float]:
    """The modal body on the driven hub: the tip face's centroid ``(u, v)`` in the hub frame at
    ``t`` (up to where the run got), the wall time of ``simulate`` and the end time reached."""
    s = ukflex.SpatialScene()
    hub = s.rigid_body("hub", 1.0, (1.0, 1.0, 1.0))
    s.revolute(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), name="axle")
    s.rotation_driver(s.ground.marker((0, 0, 0)), hub.marker((0, 0, 0)), kane_motion(), name="spin")
    bar = s.flexible_body("bar", data, stress_stiffening=stiffening)
    s.fixed(hub.marker((0, 0, 0)), bar.interface("A"), name="clamp")
    system = ukflex.System(s)
    t0 = time.perf_counter()
    res = ukflex.simulate(system, T_END, t_eval=t, **run)
    dt = time.perf_counter() - t0
    n = data.m_ff.shape[0]
    tip = np.asarray(data.interfaces["B"].phi).T @ np.asarray(res.q)[-n:]  # frame (= hub) axes
    # the clamped frame is the hub's: the tip face's centroid sits at (L, 0, 0) + tip
    return tip[0], tip[1], dt, float(res.t[-1])


def exudyn_run(elements: int, t: np.ndarray, steps: int, spectral_radius: float = 0.8,
               absolute_tolerance: float = 1e-6) -> Tuple[np.ndarray, np.ndarray, float]:
    """The spin-up in Exudyn on ``elements`` elements and ``steps`` steps over ``T_END``
    (generalized-alpha at ``spectral_radius``, Newton to ``absolute_tolerance`` [N]): the tip's
    ``(u, v)`` in the hub frame interpolated at ``t``, and the wall time of
    ``mbs.SolveDynamic``. The defaults are the settings that run on this beam: at spectral
    radius 1 Exudyn's Newton does not converge (the undamped axial and shear modes of the short
    elements), at its default absolute tolerance 1e-10 its residual stalls in rounding
    (docs/spatial-flexible.md)."""
    import exudyn as exu
    from exudyn.itemInterface import (CoordinateConstraint, GenericJoint, MarkerNodeCoordinate, MarkerNodeRigid, NodePointGround,
                                      NodeRigidBodyRxyz, ObjectRigidBody, SensorNode)

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    rho_i = MU / 4e-4 * EI / 7e10  # rho I, as in the ukflex beam (spatial_beam_spin_up.beam3)
    sec = beam_section(EA, GA, GA, EI, 3 * EI, EI, MU, (4 * rho_i, 3 * rho_i, rho_i))
    nodes = add_member(mbs, (0.0, 0.0, 0.0), np.eye(3), L, elements, sec)
    hub = mbs.AddNode(NodeRigidBodyRxyz(referenceCoordinates=[0.0] * 6))
    mbs.AddObject(ObjectRigidBody(nodeNumber=hub, mass=1.0, inertia=[1.0, 1.0, 1.0, 0, 0, 0]))
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    for k in range(5):
        mbs.AddObject(CoordinateConstraint(markerNumbers=[m_ground, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=hub, coordinate=k))]))
    mbs.AddObject(CoordinateConstraint(markerNumbers=[m_ground, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=hub, coordinate=5))],
                                       offsetUserFunction=lambda mbs, t, item, off: float(hub_angle(np.array(t))),
                                       offsetUserFunction_t=lambda mbs, t, item, off: hub_rate(t)))
    mbs.AddObject(GenericJoint(markerNumbers=[mbs.AddMarker(MarkerNodeRigid(nodeNumber=hub)), mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[0]))],
                               constrainedAxes=[1] * 6))
    s_tip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], outputVariableType=exu.OutputVariableType.Position, storeInternal=True))
    mbs.Assemble()
    dt = solve(mbs, settings(T_END, steps, spectral_radius, newton_atol=absolute_tolerance, sparse=True))
    tip = history(mbs, s_tip, t)
    u, v = _in_hub_frame(t, tip[:, 0], tip[:, 1])
    return u, v, dt


def gap(a: Hist, ref: Hist) -> Tuple[float, float]:
    """The largest ``|v - v_ref|`` and ``|u - u_ref|`` over the history, over the dip of ``ref``
    (its largest ``|v|``)."""
    dip = float(np.max(np.abs(ref[1])))
    return float(np.max(np.abs(a[1] - ref[1])) / dip), float(np.max(np.abs(a[0] - ref[0])) / dip)


#: the FE meshes (P2 tetrahedra boxes) and mode counts of the modal body
FE_CASES = (((40, 1, 1), 4), ((80, 1, 1), 4), ((80, 1, 1), 8), ((160, 1, 2), 8))
#: the converged runs: ukflex's beam3 (RADAU5M at rtol 1e-7) and Exudyn (steps over 20 s)
UK_REF = dict(method="RADAU5M", rtol=1e-7, atol=1e-9)
EX_REF_STEPS = 6000


def _fmt(g: Tuple[float, float]) -> str:
    return f"{g[0]:.2e} | {g[1]:.2e}"


def ffrf_part(t: np.ndarray, beam_lim: Hist, cab: Hist, fe_cases: Sequence[Tuple[Tuple[int, int, int], int]]) -> List[str]:
    """The modal body's rows: with stress stiffening per FE case, and the linear body's (and the
    quadratic strain's) divergence on the first."""
    lines = ["| model | build [s] | first bending [rad/s] (E-B 3.7977) | dip [m] | v: to beam3's limit / dip | u: to beam3's limit / dip "
             "| v: to the cable / dip | `simulate` [s] |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    first = None
    for cells, modes in fe_cases:
        _log(f"flexible3 {cells}, {modes} modes, stress_stiffening")
        t0 = time.perf_counter()
        d = fe_data(cells, modes, stress_stiffening=True)
        build = time.perf_counter() - t0
        first = first or d
        u, v, dt, _ = modal(t, d, True, method="RADAU5M", rtol=1e-8, atol=1e-10)
        w1 = 2.0 * math.pi * float(d.info["frequencies"][0])
        lines.append(f"| flexible3 {cells}, {modes} modes, `stress_stiffening=True` | {build:.1f} | {w1:.4f} | {-v.min():.5f} | "
                     f"{_fmt(gap((u, v), beam_lim))} | {gap((u, v), cab)[0]:.2e} | {dt:.2f} |")
    _log("flexible3, linear (no stiffening)")
    u, v, dt, te = modal(t, first, False, method="RADAU5M", rtol=1e-8, atol=1e-10)
    at = [f"{abs(v[np.searchsorted(t, x)]):.3g} m at {x:g} s" for x in (8.0, 10.0, 11.0) if x <= te]
    lines.append(f"| flexible3 {fe_cases[0][0]}, {fe_cases[0][1]} modes, linear | | | | run stops at {te:.2f} s; |v| {', '.join(at)} | | | {dt:.2f} |")
    return lines


def converged(t: np.ndarray, uk_meshes: Sequence[int], ex_meshes: Sequence[int]) -> Tuple[Dict[int, Hist], Dict[int, Hist], List[str]]:
    """Each code's converged runs on its meshes and the lines of their table; ``[0]`` of each
    dict holds the mesh limit (Richardson on the two finest)."""
    uk: Dict[int, Hist] = {}
    ex: Dict[int, Hist] = {}
    for n in uk_meshes:
        _log(f"beam3 {n} elements, RADAU5M rtol 1e-7")
        uk[n] = beam3(t, n, **UK_REF)[:2]
    for n in ex_meshes:
        _log(f"Exudyn {n} elements, {EX_REF_STEPS} steps")
        ex[n] = exudyn_run(n, t, EX_REF_STEPS)[:2]
    fu, fx = sorted(uk)[-2:], sorted(ex)[-2:]
    uk[0], ex[0] = richardson(uk[fu[0]], uk[fu[1]]), richardson(ex[fx[0]], ex[fx[1]])
    lines = [f"mesh limits (Richardson {fu[0]}/{fu[1]} and {fx[0]}/{fx[1]}): ukflex dip {-uk[0][1].min():.5f} m, Exudyn "
             f"{-ex[0][1].min():.5f} m; Exudyn's limit to ukflex's: v {gap(ex[0], uk[0])[0]:.2e}, u {gap(ex[0], uk[0])[1]:.2e} "
             "of the dip", "", "| code | elements | converged run | dip [m] | v: to ukflex's limit | u | v: to Exudyn's limit | u |",
             "|---|---:|---|---:|---:|---:|---:|---:|"]
    for code, runs, how in (("ukflex beam3", uk, "RADAU5M rtol 1e-7"), ("Exudyn", ex, f"{EX_REF_STEPS} steps")):
        for n in sorted(k for k in runs if k):
            lines.append(f"| {code} | {n} | {how} | {-runs[n][1].min():.5f} | {_fmt(gap(runs[n], uk[0]))} | {_fmt(gap(runs[n], ex[0]))} |")
    return uk, ex, lines


def speed(t: np.ndarray, ref: Hist, uk_meshes: Sequence[int], rtols: Sequence[float], ex_meshes: Sequence[int],
          steps: Sequence[int], repeat: int, ex_repeat: int) -> List[str]:
    """ukflex's default ``simulate()`` (``rtol`` only) and Exudyn's runs, interleaved; each run's
    error to ``ref`` and its median wall time; per target the fastest of each code within it."""
    runs: Dict[Tuple[str, int, Any], List[Tuple[np.ndarray, np.ndarray, float]]] = {}
    failed: List[str] = []
    for k in range(repeat):
        for n in uk_meshes:
            for rt in rtols:
                _log(f"repetition {k + 1}/{repeat}: ukflex {n} elements, simulate(rtol={rt:g})")
                runs.setdefault(("ukflex", n, rt), []).append(beam3(t, n, rtol=rt))
        for n in ex_meshes if k < ex_repeat else ():
            for st in steps:
                _log(f"repetition {k + 1}/{repeat}: Exudyn {n} elements, {st} steps")
                try:
                    runs.setdefault(("Exudyn", n, st), []).append(exudyn_run(n, t, st))
                except Exception as exc:  # Exudyn's Newton failing at too large a step: reported
                    failed.append(f"Exudyn {n} elements, {st} steps failed: {type(exc).__name__}: {str(exc)[:60]}")
    lines = failed + ["", "| code | elements | rtol / steps | v: error / dip | u: error / dip | wall time [s], median |",
                      "|---|---:|---:|---:|---:|---:|"]
    timed = []
    for (code, n, opt), rs in runs.items():
        err = gap(rs[0][:2], ref)
        wall = float(np.median([r[2] for r in rs]))
        timed.append((code, n, opt, max(err), wall))
        lines.append(f"| {code} | {n} | {opt:g} | {_fmt(err)} | {wall:.2f} |")
    lines += ["", "| target | ukflex: fastest default run within it | Exudyn: fastest run within it | Exudyn / ukflex |", "|---|---|---|---:|"]
    for target in TARGETS:
        best = [min((r for r in timed if r[0] == c and r[3] <= target), key=lambda r: r[4], default=None) for c in ("ukflex", "Exudyn")]
        cells = [f"{b[1]} el., {'rtol ' if b[0] == 'ukflex' else ''}{b[2]:g}{'' if b[0] == 'ukflex' else ' steps'}: {b[3]:.2e} in {b[4]:.2f} s"
                 if b else "none" for b in best]
        ratio = f"{best[1][4] / best[0][4]:.1f}" if best[0] and best[1] else "n/a"
        lines.append(f"| {target:.1%} | {cells[0]} | {cells[1]} | {ratio} |")
    return lines


def main(argv: Optional[List[str]] = None) -> int:
    """The modal body against the beam, the two codes converged, and the speed at equal accuracy
    (module docs)."""
    import argparse

    def ints(text: str) -> Tuple[int, ...]:
        return tuple(int(x) for x in text.split(","))

    ap = argparse.ArgumentParser(prog="python -m studies spatial-beam-spin-up-exudyn")
    ap.add_argument("--meshes", default="8,12,16,20,24", help="the elements of ukflex's timed default runs")
    ap.add_argument("--rtols", default="1e-3,1e-5", help="their rtol")
    ap.add_argument("--exudyn-meshes", default="8,12,16,24", help="the elements of Exudyn's timed runs")
    ap.add_argument("--steps", default="1000,2000,4000", help="Exudyn's step counts over 20 s")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved repetitions of ukflex's timed runs")
    ap.add_argument("--exudyn-repeat", type=int, default=1, help="... of Exudyn's")
    ap.add_argument("--no-fe", action="store_true", help="leave out the modal body (part 1)")
    args = ap.parse_args(argv)
    t = np.linspace(0.0, T_END, 201)
    _log("ANCF cable, 16 elements (RADAU5M rtol 1e-8)")
    cab = cable(t, 16)[:2]
    uk, ex, conv = converged(t, (8, 16, 32), (16, 32))
    print(f"ANCF cable 16 elements: dip {-cab[1].min():.5f} m; to beam3's mesh limit: v {gap(cab, uk[0])[0]:.2e}, "
          f"u {gap(cab, uk[0])[1]:.2e} of the dip")
    if not args.no_fe:
        print("\n".join(["", "## The modal body against the beam (errors over the dip of beam3's mesh limit)", ""]
                        + ffrf_part(t, uk[0], cab, FE_CASES)))
    print("\n".join(["", "## Both codes converged", ""] + conv))
    print("\n".join(["", "## Speed at equal accuracy (errors to ukflex's mesh limit, over its dip)"]
                    + speed(t, uk[0], ints(args.meshes), [float(x) for x in args.rtols.split(",")], ints(args.exudyn_meshes),
                            ints(args.steps), args.repeat, args.exudyn_repeat)))
    _log("done")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
