"""``python -m studies spatial-flexible-crank [--quick | --gap]``: Haug's spatial slider-crank with a
flexible connecting rod (``ukflex.spatial_scenes.flexible_slider_crank``, docs/spatial-flexible.md),
the rod built once as a geometrically exact beam (``beam3``) and once as a 3D modal body from a
solid FE model (``flexible3``, Craig-Bampton at the two end faces; linear, and with the
Green-Lagrange strain's cubic energy, ``quadratic_strain=True``), and the beam side by side
with Exudyn 1.13.6 (``ObjectBeamGeometricallyExact`` on ``NodeRigidBodyEP`` nodes).

Outputs, from the public results: the slider's position ``x(t)`` and the rod's deflection, the
midpoint's displacement from the chord of the two ends (the 3-vector ``d = m - a - ((m - a).e)
e``, ``e = (b - a)/|b - a|``; the beam's middle node, the modal body's mid-length section's
centroid, the ends the joint points). Error of a history against a reference: the largest
distance over the outputs divided by the reference's largest amplitude (``max |x - x_ref|
/ max |x_ref - x_ref(0)|`` for the slider, ``max |d - d_ref| / max |d_ref|`` for the
deflection).
"""

from __future__ import annotations

import sys
import time
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

import ukflex
from studies import _exudyn_beam as xb
from ukflex import spatial_scenes as sps
from ukflex.results.fields import modal_fields

OMEGA, SPIN_UP, CRANK, ROD = 150.0, 0.05, 0.08, 0.3
#: the spin-up and two turns at constant speed
T_END = SPIN_UP + 2 * 2 * np.pi / OMEGA
N_OUT = 401
#: Exudyn's Newton goal on the residual (N)
NEWTON_ABS = 1e-6


def times(t_end: float = T_END, n: int = N_OUT) -> np.ndarray:
    return np.linspace(0.0, t_end, n)


def _chord(a: np.ndarray, b: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The midpoint's displacement from the chord ``a -> b`` (nt, 3)."""
    e = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    w = m - a
    return w - np.einsum("ti,ti->t", w, e)[:, None] * e


def outputs(system: ukflex.System, res: Any, data: Any = None) -> Dict[str, np.ndarray]:
    """``slider`` (nt,) world ``x`` of the slider, ``deflection`` (nt, 3), ``ends`` (2, nt, 3) of
    a run of the flexible slider-crank; ``data`` the modal rod's data (None: the beam)."""
    out = ukflex.spatial_outputs(system, res)
    bodies = out["bodies"]
    slider = bodies["slider"]["position"][:, 0]
    if data is None:
        nodes = sorted((int(k[4:-1]) for k in bodies if k.startswith("rod[")))
        n = nodes[-1]
        le = ROD / n
        first, last, mid = bodies["rod[0]"], bodies[f"rod[{n}]"], bodies[f"rod[{n // 2}]"]
        # an end node's body sits at its half-segment's centre of mass, a quarter element inwards
        a = first["position"] - 0.25 * le * first["rotation"][:, :, 0]
        b = last["position"] + 0.25 * le * last["rotation"][:, :, 0]
        m = mid["position"]
    else:
        pos = modal_fields(system, res, "rod", data)["position"]
        x = np.asarray(data.info["nodes"])[:, 0]
        a = pos[:, np.asarray(data.interfaces["A"].nodes)].mean(axis=1)
        b = pos[:, np.asarray(data.interfaces["B"].nodes)].mean(axis=1)
        m = pos[:, np.abs(x - 0.5 * ROD) < 1e-9 * ROD].mean(axis=1)
    return {"slider": slider, "deflection": _chord(a, b, m), "ends": np.stack([a, b])}


def ukflex_run(rod_model: str, t: np.ndarray, elements: int = 8, data: Any = None, **run: Any) -> Tuple[Dict[str, np.ndarray], float]:
    """One run on a freshly built System: outputs at ``t`` and the wall time of ``simulate``; the
    modal rod's ``data`` default to the builder's default rod (:data:`ukflex.spatial_scenes.ROD_DEFAULTS`)."""
    if rod_model == "modal" and data is None:
        data = sps.slider_crank_rod_data()
    system = ukflex.System(sps.flexible_slider_crank(rod_model, elements=elements, data=data, omega=OMEGA,
                                                     spin_up_time=SPIN_UP, crank=CRANK, rod=ROD))
    t0 = time.perf_counter()
    res = ukflex.simulate(system, float(t[-1]), t_eval=t, **run)
    dt = time.perf_counter() - t0
    if res.status != 0:
        raise RuntimeError(f"ukflex: {res.message}")
    return outputs(system, res, data), dt


def _exudyn_beam(mbs: Any, elements: int, B: np.ndarray, Rr: np.ndarray) -> Tuple[int, int, List[int]]:
    """The rod as ``elements`` ``ObjectBeamGeometricallyExact`` on ``NodeRigidBodyEP`` nodes
    (the section data as ``beam3`` derives them): the markers of its two ends (position, rigid)
    and the position sensors of its ends and middle node."""
    import exudyn as exu
    from exudyn.itemInterface import MarkerNodePosition, MarkerNodeRigid, SensorNode

    a, rho, e, nu = sps.ROD_SECTION
    nodes = xb.add_member(mbs, B, Rr, ROD, elements, xb.beam_section(**xb.rectangle_section(a, a, rho, e, nu)))
    sensors = [mbs.AddSensor(SensorNode(nodeNumber=n, outputVariableType=exu.OutputVariableType.Position, storeInternal=True))
               for n in (nodes[0], nodes[elements // 2], nodes[-1])]
    return mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[0])), mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[-1])), sensors


def _exudyn_modal(mbs: Any, data: Any, mesh: Tuple[int, int, int], B: np.ndarray, Rr: np.ndarray) -> Tuple[int, int, List[int]]:
    """The rod as Exudyn's ``ObjectFFRFreducedOrder`` on the same FE model and mode basis as
    ``data`` (``FEMinterface``; Exudyn computes its own invariants): the face ``A``'s centroid
    (``MarkerSuperElementPosition``), the face ``B`` (``MarkerSuperElementRigid``, its own
    weighted rotation) and the position sensors of the two faces and the mid-length section."""
    import exudyn as exu
    import scipy.sparse as sp
    from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface
    from exudyn.itemInterface import MarkerSuperElementPosition, MarkerSuperElementRigid, SensorMarker
    from ukflex import fe3

    a, rho, e, nu = sps.ROD_SECTION
    nodes, k, ms = fe3.solid_matrices(fe3.bar_mesh(ROD, a, a, mesh), density=rho, youngs_modulus=e, poisson_ratio=nu)
    if not np.allclose(nodes, data.info["nodes"]):
        raise ValueError("the FE model does not match the modal data's nodes")
    fem = FEMinterface()
    fem.nodes = {"Position": nodes}
    fem.massMatrix = sp.kron(ms, sp.eye(3)).tocsr()
    fem.stiffnessMatrix = k.tocsr()
    fem.modeBasis = {"matrix": data.info["modes"], "type": "NormalModes"}
    body = ObjectFFRFreducedOrderInterface(fem).AddObjectFFRFreducedOrder(mbs, positionRef=list(B), rotationMatrixRef=Rr)["oFFRFreducedOrder"]

    def weights(idx: np.ndarray) -> Dict[str, Any]:
        idx = [int(i) for i in idx]
        return {"bodyNumber": body, "meshNodeNumbers": idx, "weightingFactors": [1.0 / len(idx)] * len(idx)}

    face_a, face_b = np.asarray(data.interfaces["A"].nodes), np.asarray(data.interfaces["B"].nodes)
    mid = np.nonzero(np.abs(nodes[:, 0] - 0.5 * ROD) < 1e-9 * ROD)[0]
    pos = [mbs.AddMarker(MarkerSuperElementPosition(**weights(i))) for i in (face_a, mid, face_b)]
    sensors = [mbs.AddSensor(SensorMarker(markerNumber=m, outputVariableType=exu.OutputVariableType.Position, storeInternal=True)) for m in pos]
    return pos[0], mbs.AddMarker(MarkerSuperElementRigid(offset=[0.0, 0.0, 0.0], **weights(face_b))), sensors


def exudyn_run(t: np.ndarray, steps: int, elements: int = 8, spectral_radius: float = 1.0, data: Any = None,
               mesh: Optional[Tuple[int, int, int]] = None) -> Tuple[Dict[str, np.ndarray], float]:
    """The same slider-crank in Exudyn 1.13.6, the rod of ``elements``
    ``ObjectBeamGeometricallyExact`` on ``NodeRigidBodyEP`` nodes (``data`` given: Exudyn's
    ``ObjectFFRFreducedOrder`` of the same FE model, ``mesh`` its cells, and mode basis); the crank a rigid body on a
    ``NodeRigidBodyRxyz`` at the pivot, its six coordinates held by ``CoordinateConstraint`` (the
    rotation about ``x`` following the spin-up through a Python ``offsetUserFunction``); the
    spherical joint ``SphericalJoint``; the universal joint a ``GenericJoint`` with one rotation
    held (``y_0 . z_1 = 0``: its joint frames put the slider's arm on ``y_0`` and the rod's on
    ``z_1``); the prismatic a ``GenericJoint`` free along ``x``. Generalized-alpha at
    ``spectral_radius``, ``steps`` steps over ``[0, t[-1]]``. Outputs as :func:`outputs` (at
    ``t``, interpolated) and the wall time of ``mbs.SolveDynamic``."""
    import exudyn as exu
    from exudyn.itemInterface import (CoordinateConstraint, GenericJoint, MarkerBodyPosition, MarkerBodyRigid, MarkerNodeCoordinate,
                                      NodePointGround, NodeRigidBodyEP, NodeRigidBodyRxyz, ObjectGround, ObjectRigidBody, SensorNode,
                                      SphericalJoint)

    angle = sps.spin_up(OMEGA, SPIN_UP)
    theta = eval("lambda t: " + angle.replace("^", "**"), {"abs": abs, "cos": np.cos})  # the same expression
    A, _, B, C, Rr = sps.crank_geometry(CRANK, ROD, (0.0, 0.1, 0.12))
    mc, ms = 0.12, 0.1
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    gnode = mbs.AddNode(NodePointGround())
    # crank: node at the pivot, frame = world at angle 0; pin at (0, 0, crank) in it
    cn = mbs.AddNode(NodeRigidBodyRxyz(referenceCoordinates=list(A) + [0.0, 0.0, 0.0]))
    crank_b = mbs.AddObject(ObjectRigidBody(nodeNumber=cn, physicsMass=mc, physicsCenterOfMass=[0, 0, CRANK / 2],
                                            physicsInertia=[1e-4 + mc * CRANK ** 2 / 4, 1e-4 + mc * CRANK ** 2 / 4, 1e-5, 0, 0, 0]))
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=gnode, coordinate=0))
    for c in range(6):
        mk = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=cn, coordinate=c))
        if c == 3:
            mbs.AddObject(CoordinateConstraint(markerNumbers=[mg, mk], offsetUserFunction=lambda mbs, tt, item, off: float(theta(tt))))
        else:
            mbs.AddObject(CoordinateConstraint(markerNumbers=[mg, mk]))
    end_a, end_b, sensors = (_exudyn_beam(mbs, elements, B, Rr) if data is None else _exudyn_modal(mbs, data, mesh, B, Rr))
    sn = mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(C) + [1.0, 0, 0, 0]))
    slider_b = mbs.AddObject(ObjectRigidBody(nodeNumber=sn, physicsMass=ms, physicsInertia=[1e-6, 1e-6, 1e-6, 0, 0, 0]))
    mbs.AddObject(SphericalJoint(markerNumbers=[mbs.AddMarker(MarkerBodyPosition(bodyNumber=crank_b, localPosition=[0, 0, CRANK])),
                                                end_a]))
    ex_, ey_, ez_ = np.eye(3)
    mbs.AddObject(GenericJoint(markerNumbers=[mbs.AddMarker(MarkerBodyRigid(bodyNumber=slider_b)), end_b],
                               constrainedAxes=[1, 1, 1, 1, 0, 0], rotationMarker0=np.column_stack([ey_, ex_, -ez_]),
                               rotationMarker1=np.column_stack([ez_, ex_, ey_])))
    mbs.AddObject(GenericJoint(markerNumbers=[mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=list(C))),
                                              mbs.AddMarker(MarkerBodyRigid(bodyNumber=slider_b))], constrainedAxes=[0, 1, 1, 1, 1, 1]))
    sensors.append(mbs.AddSensor(SensorNode(nodeNumber=sn, outputVariableType=exu.OutputVariableType.Position, storeInternal=True)))
    mbs.Assemble()
    # Newton's absolute goal in N: its default 1e-10 lies below the residual's round-off here
    # (EA = 1.3e7 N; the residual stalls at 2e-8 and the solver stops at the first step)
    dt = xb.solve(mbs, xb.settings(float(t[-1]), steps, spectral_radius, newton_atol=NEWTON_ABS))
    a, m, b, sl = (xb.history(mbs, s, t) for s in sensors)
    return {"slider": sl[:, 0], "deflection": _chord(a, b, m), "ends": np.stack([a, b])}, dt


def errors(o: Dict[str, np.ndarray], ref: Dict[str, np.ndarray]) -> Tuple[float, float]:
    """(slider, deflection) errors of ``o`` against ``ref`` (module docs)."""
    amp = np.max(np.abs(ref["slider"] - ref["slider"][0]))
    e_s = np.max(np.abs(o["slider"] - ref["slider"])) / amp
    e_d = np.max(np.linalg.norm(o["deflection"] - ref["deflection"], axis=1)) / np.max(np.linalg.norm(ref["deflection"], axis=1))
    return float(e_s), float(e_d)


def _log(msg: str) -> None:
    print(f"[spatial-flexible-crank {time.perf_counter() - _T0:7.1f} s] {msg}", file=sys.stderr, flush=True)


_T0 = time.perf_counter()
TIGHT = dict(method="RADAU5", rtol=1e-9, atol=1e-11)


def _table(rows: List[Tuple[str, Dict[str, np.ndarray], float]], refs: Dict[str, Dict[str, np.ndarray]]) -> List[str]:
    head = "| model | run | max \\|d\\| [mm] | " + " | ".join(f"slider / deflection to {k}" for k in refs) + " | wall time [s] |"
    out = [head, "|" + "---|" * (3 + len(refs) + 1)]
    for name, o, dt in rows:
        errs = " | ".join("{:.2e} / {:.2e}".format(*errors(o, r)) for r in refs.values())
        out.append(f"| {name} | {1e3 * np.max(np.linalg.norm(o['deflection'], axis=1)):.4f} | {errs} | {dt:.2f} |")
    return out


def main(argv: Optional[List[str]] = None) -> int:
    """Three tables: the two ukflex models converged and compared; the beam-modal gap against the
    crank speed; ukflex against Exudyn, error against wall time (medians of 3 interleaved
    repetitions). ``--quick``: fewer meshes, no speed table, one repetition; ``--gap``: the
    beam-modal gap against the crank speed alone; ``--default-rod``: the builder's default modal
    rod before and after its rule (:func:`default_rod_table`)."""
    args = list(argv or [])
    if "-h" in args or "--help" in args:
        print(__doc__)
        return 0
    unknown = [a for a in args if a not in ("--quick", "--gap", "--default-rod")]
    if unknown:
        print(f"python -m studies spatial-flexible-crank: unknown arguments {unknown} (options: --quick, --gap, --default-rod)",
              file=sys.stderr)
        return 2
    if "--gap" in args:
        print("\n".join(gap_table()))
        return 0
    if "--default-rod" in args:
        print("\n".join(default_rod_table()))
        return 0
    quick = "--quick" in args
    reps = 1 if quick else 3
    t = times()
    _log("ukflex beam3 32 elements, RADAU5 rtol 1e-9 (the reference)")
    ref, _ = ukflex_run("beam", t, elements=32, **TIGHT)
    modal_ref_data = sps.slider_crank_rod_data((32, 2, 2), 8, quadratic_strain=False)
    _log("ukflex flexible3 (32, 2, 2), 8 modes, RADAU5 rtol 1e-9 (the modal reference)")
    mref, _ = ukflex_run("modal", t, data=modal_ref_data, **TIGHT)
    refs = {"beam3 32": ref, "flexible3 (32,2,2) 8": mref}
    rows: List[Tuple[str, Dict[str, np.ndarray], float]] = []
    for n in (8,) if quick else (8, 16):
        _log(f"ukflex beam3 {n}, RADAU5 rtol 1e-9")
        rows.append((f"beam3 {n} elements | RADAU5 rtol 1e-9", *ukflex_run("beam", t, elements=n, **TIGHT)))
    rows.append(("beam3 32 elements | RADAU5 rtol 1e-9", ref, float("nan")))
    for mesh, modes in (((16, 1, 1), 4),) if quick else (((16, 1, 1), 4), ((16, 1, 1), 8), ((32, 2, 2), 4)):
        _log(f"ukflex flexible3 {mesh}, {modes} modes")
        rows.append((f"flexible3 {mesh}, {modes} modes | RADAU5 rtol 1e-9",
                     *ukflex_run("modal", t, data=sps.slider_crank_rod_data(mesh, modes, quadratic_strain=False), **TIGHT)))
    rows.append(("flexible3 (32, 2, 2), 8 modes | RADAU5 rtol 1e-9", mref, float("nan")))
    for mesh, modes in (((16, 1, 1), 4),) if quick else (((16, 1, 1), 4), ((32, 2, 2), 8)):
        _log(f"ukflex flexible3 {mesh}, {modes} modes, quadratic strain")
        rows.append((f"flexible3 {mesh}, {modes} modes, quadratic strain | RADAU5 rtol 1e-9",
                     *ukflex_run("modal", t, data=sps.slider_crank_rod_data(mesh, modes, quadratic_strain=True), **TIGHT)))
    _log("ukflex flexible3, the builder's default rod (sps.ROD_DEFAULTS)")
    rows.append(("flexible3, the builder's default rod | RADAU5 rtol 1e-9", *ukflex_run("modal", t, **TIGHT)))
    print(f"crank {OMEGA} rad/s after a {SPIN_UP} s spin-up, {t[-1]:.4f} s; rod clamped-clamped modes (Hz): "
          f"{np.round(modal_ref_data.info['frequencies'][:4], 1).tolist()}")
    print("error = max |x - x_ref| / max |x_ref - x_ref(0)| (slider), max |d - d_ref| / max |d_ref| (deflection)\n")
    print("\n".join(_table(rows, refs)))
    if not quick:
        print("\n".join(gap_table(modal_ref_data)))
    meshes = (8, 16) if quick else (8, 16, 24)
    runs = [(f"ukflex beam3 {n}, default simulate()", (lambda n=n: ukflex_run("beam", t, elements=n))) for n in meshes]
    runs += [(f"ukflex beam3 {n}, RADAU5M rtol 1e-6", (lambda n=n: ukflex_run("beam", t, elements=n, method="RADAU5M", rtol=1e-6)))
             for n in meshes]
    runs += [("ukflex flexible3 (16, 1, 1), 4 modes, default simulate()",
              lambda: ukflex_run("modal", t, data=sps.slider_crank_rod_data((16, 1, 1), 4, quadratic_strain=False))),
             ("ukflex flexible3, the builder's default rod, default simulate()", lambda: ukflex_run("modal", t))]
    runs += [(f"Exudyn {n} elements, {k} steps", (lambda n=n, k=k: exudyn_run(t, k, n)))
             for n, k in (((8, 1000), (32, 1000)) if quick else ((8, 1000), (16, 1000), (32, 500), (32, 1000), (32, 2000), (64, 2000)))]
    timed: Dict[str, List[Tuple[Dict[str, np.ndarray], float]]] = {name: [] for name, _ in runs}
    for r in range(reps):
        for name, f in runs:
            _log(f"repetition {r + 1}/{reps}: {name}")
            try:
                timed[name].append(f())
            except Exception as exc:  # Exudyn stopping: reported
                timed[name].append(({}, float("nan")))
                _log(f"{name} failed: {exc}")
    print(f"\nerror against the converged answer (ukflex beam3 32 elements, RADAU5 rtol 1e-9) and wall time of the whole "
          f"solve call (median of {reps} interleaved runs):\n")
    print("| run | slider error | deflection error | wall time [s] |\n|---|---:|---:|---:|")
    for name, _ in runs:
        o = timed[name][-1][0]
        dt = float(np.median([x[1] for x in timed[name]]))
        if not o:
            print(f"| {name} | failed | | |")
            continue
        e_s, e_d = errors(o, ref)
        print(f"| {name} | {e_s:.2e} | {e_d:.2e} | {dt:.2f} |")
    print("\n".join(modal_table(t, reps)))
    return 0


def gap_table(modal_ref_data: Any = None) -> List[str]:
    """The beam-modal gap against the crank speed: beam3 16 elements against flexible3
    (32, 2, 2), 8 modes, linear, and with the quadratic strain at 8 and 16 modes (RADAU5 rtol
    1e-9)."""
    global OMEGA
    if modal_ref_data is None:
        modal_ref_data = sps.slider_crank_rod_data((32, 2, 2), 8, quadratic_strain=False)
    models = [("8 modes", modal_ref_data), ("8 modes, quadratic strain", sps.slider_crank_rod_data((32, 2, 2), 8, quadratic_strain=True)),
              ("16 modes, quadratic strain", sps.slider_crank_rod_data((32, 2, 2), 16, quadratic_strain=True))]
    out = ["\nbeam3 16 elements against flexible3 (32, 2, 2), linear and with the quadratic strain, by crank speed (RADAU5 rtol "
           "1e-9); each modal rod: max |d| [mm], slider gap, deflection gap:\n",
           "| crank speed [rad/s] | max \\|d\\| beam [mm] | " + " | ".join(name for name, _ in models) + " |",
           "|---:|---:|" + "---|" * len(models)]
    for om in (150.0, 75.0, 37.5):
        OMEGA = om
        tt = times(SPIN_UP + 4 * np.pi / om)
        _log(f"speed {om} rad/s")
        ob, _ = ukflex_run("beam", tt, elements=16, **TIGHT)
        cells = [f"{1e3 * np.max(np.linalg.norm(ob['deflection'], axis=1)):.4f}"]
        for _, d in models:
            om_, _ = ukflex_run("modal", tt, data=d, **TIGHT)
            cells.append(f"{1e3 * np.max(np.linalg.norm(om_['deflection'], axis=1)):.4f}, " + ", ".join("{:.2e}".format(e) for e in errors(om_, ob)))
        out.append(f"| {om} | " + " | ".join(cells) + " |")
    OMEGA = 150.0
    return out


def default_rod_table(reps: int = 3) -> List[str]:
    """The builder's default modal rod before (the (16, 1, 1) mesh, the 4 lowest modes, linear)
    and after its rule (``sps.ROD_DEFAULTS``: (32, 2, 2), the 8 lowest modes and the first axial
    one, the quadratic strain): errors against the converged beam (beam3 32 elements, RADAU5
    rtol 1e-9) and the cost, the modal data built from scratch (the cache cleared) and the whole
    default ``simulate()`` on a fresh System, medians of ``reps`` interleaved repetitions."""
    t = times()
    _log("ukflex beam3 32 elements, RADAU5 rtol 1e-9 (the reference)")
    ref, _ = ukflex_run("beam", t, elements=32, **TIGHT)
    cases = {"before: (16, 1, 1), the 4 lowest modes, linear": lambda: sps.slider_crank_rod_data((16, 1, 1), 4, quadratic_strain=False),
             "after: the default, (32, 2, 2), the 8 lowest and the first axial mode, quadratic strain": sps.slider_crank_rod_data}
    runs: Dict[str, List[Tuple[Dict[str, np.ndarray], Any, float, float]]] = {name: [] for name in cases}
    for r in range(reps):
        for name, make in cases.items():
            _log(f"repetition {r + 1}/{reps}: {name}")
            sps.clear_rod_data_cache()
            t0 = time.perf_counter()
            data = make()
            build = time.perf_counter() - t0
            o, wall = ukflex_run("modal", t, data=data)
            runs[name].append((o, data, build, wall))
    out = [f"\nthe builder's default modal rod against beam3 32 elements (RADAU5 rtol 1e-9); cost: medians of {reps} interleaved "
           "runs of the data build (from scratch) and of the default simulate():\n",
           "| modal rod | fixed-interface modes kept | slider error | deflection error | max \\|d\\| [mm] | data build [s] | "
           "simulate() [s] | together [s] |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for name, rs in runs.items():
        o, data = rs[-1][0], rs[-1][1]
        e_s, e_d = errors(o, ref)
        build, wall = float(np.median([x[2] for x in rs])), float(np.median([x[3] for x in rs]))
        out.append(f"| {name} | {data.info['mode_numbers']} | {e_s:.2e} | {e_d:.2e} | "
                   f"{1e3 * np.max(np.linalg.norm(o['deflection'], axis=1)):.4f} | {build:.2f} | {wall:.2f} | {build + wall:.2f} |")
    return out


#: Exudyn's spectral radius for the modal rod: at 1 (no numerical damping) its answer wanders
#: with the step count (6e-3, 1.2e-2 at 1000, 2000 steps) and 4000 steps fail
FFRF_SPECTRAL_RADIUS = 0.8


def modal_table(t: np.ndarray, reps: int = 3, mesh: Tuple[int, int, int] = (16, 1, 1), modes: int = 4) -> List[str]:
    """The modal rod in ukflex (``flexible3``) and in Exudyn (``ObjectFFRFreducedOrder`` of the
    same FE model and mode basis): errors against ukflex RADAU5 at rtol 1e-10, wall times
    (medians of ``reps`` interleaved runs)."""
    data = sps.slider_crank_rod_data(mesh, modes, quadratic_strain=False)  # linear, as Exudyn's ObjectFFRFreducedOrder
    _log(f"modal rod {mesh}, {modes} modes: ukflex RADAU5 rtol 1e-10 (the reference)")
    ref, _ = ukflex_run("modal", t, data=data, method="RADAU5", rtol=1e-10, atol=1e-12)
    runs = [("ukflex flexible3, default simulate()", lambda: ukflex_run("modal", t, data=data)),
            ("ukflex flexible3, RADAU5M rtol 1e-8", lambda: ukflex_run("modal", t, data=data, method="RADAU5M", rtol=1e-8))]
    runs += [(f"Exudyn ObjectFFRFreducedOrder, {k} steps", (lambda k=k: exudyn_run(t, k, data=data, mesh=mesh, spectral_radius=FFRF_SPECTRAL_RADIUS)))
             for k in (1000, 2000, 4000)]
    timed: Dict[str, List[Tuple[Dict[str, np.ndarray], float]]] = {name: [] for name, _ in runs}
    for r in range(reps):
        for name, f in runs:
            _log(f"repetition {r + 1}/{reps}: {name}")
            timed[name].append(f())
    out = [f"\nthe modal rod ({mesh} mesh, {modes} modes) in both codes (Exudyn generalized-alpha at spectral radius "
           f"{FFRF_SPECTRAL_RADIUS}); error against ukflex RADAU5 rtol 1e-10, median of {reps} interleaved runs:\n",
           "| run | slider error | deflection error | wall time [s] |", "|---|---:|---:|---:|"]
    for name, _ in runs:
        e_s, e_d = errors(timed[name][-1][0], ref)
        out.append(f"| {name} | {e_s:.2e} | {e_d:.2e} | {float(np.median([x[1] for x in timed[name]])):.2f} |")
    return out


if __name__ == "__main__":
    raise SystemExit(main())
