"""Fuzz categories: how a case is drawn (a hypothesis strategy) and what counts as wrong for it.

A case is plain data (tuples, dicts, numbers, arrays), so its ``repr`` is the reproducer.  The
checker of a category runs the case and returns the findings, each ``(kind, detail)``:

* ``unnamed-exception`` -- an exception that is neither a :class:`ukflex.UkflexError` nor a
  ``TypeError``/``ValueError`` naming the argument the case made hostile (``OverflowError``,
  ``ZeroDivisionError``, ``AttributeError``, ``RecursionError``, ``MemoryError``, a bare
  "must be real number, not str", ...).
* ``silent-nonfinite`` -- a call that returned NaN/inf, or accepted NaN/inf/masked/complex input,
  without an error.
* ``wrong`` -- a finite answer that breaks an invariant: constraint residuals beyond a tolerance
  relative to the scene's length scale, energy drift of a conservative scene, disagreement with
  the NumPy reference, a threaded result that differs from the serial one.
* ``cli-traceback`` -- the CLI exited with a status other than 0/2, printed a traceback, or wrote
  outside its output folder.

Hangs (a case running longer than the watchdog's limit) and crashes (the worker process dies)
are found by :mod:`fuzz.runner`, not here.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import shutil
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Dict, List, Tuple

import numpy as np
from hypothesis import strategies as st

from .common import (Category, Finding, _exc, _finite, _is_bad_input, _max_abs, _named, _quiet, _short, _system,
                     _ukflex)
from .surfaces import SURFACE_WEIGHTS, SURFACES
from .values import WRONG_TYPES, hostile, hostile_array, maybe_hostile, scaled


# ----------------------------------------------------------------------------------- scenes
#: templates: plausible parameters (hypothesis strategies) and the length scale of the scene
_TEMPLATES: Dict[str, Dict[str, st.SearchStrategy]] = {
    "rigid_pendulum": dict(mass=scaled(0.1, 10.0), inertia=scaled(1e-3, 1.0), length=scaled(0.1, 2.0),
                           angle=st.floats(-3.0, 3.0), angular_velocity=st.floats(-5.0, 5.0),
                           gravity=scaled(1.0, 20.0), position=st.floats(-1.0, 1.0), pivot_x=st.one_of(st.floats(-10.0, 10.0), st.sampled_from([1e5, -1e8, 1e12, 1e17]))),
    "point_pendulum": dict(mass=scaled(0.1, 10.0), length=scaled(0.1, 2.0),
                           gravity=scaled(1.0, 20.0), position=st.floats(-1.0, 1.0),
                           velocity=st.floats(-2.0, 2.0)),
    "beam": dict(length=scaled(0.1, 1.0), diameter=scaled(2e-3, 2e-2), density=scaled(1e3, 1e4),
                 youngs_modulus=scaled(1e9, 3e11), elements=st.integers(1, 2),
                 formulation=st.sampled_from(["ffrf", "ancf"]), strain=st.sampled_from(["linear", "nonlinear"]),
                 damping=st.sampled_from([0.0, 1e-4]), angular_velocity=st.floats(-5.0, 5.0)),
    "slider_crank": dict(omega=scaled(1.0, 200.0), elements=st.integers(1, 2), diameter=scaled(3e-3, 2e-2),
                         crank_length=scaled(0.05, 0.2), coupler_length=scaled(0.25, 0.5),
                         shear_factor=st.floats(0.5, 1.0), poisson_ratio=st.floats(0.0, 0.45)),
    "spring": dict(mass=scaled(0.1, 10.0), stiffness=scaled(1.0, 1e4), damping=st.floats(0.0, 1.0),
                   rest_length=scaled(0.1, 1.0), position=st.floats(0.2, 2.0)),
}

#: the argument names an error message may use for a template field
_ALIASES = {"length": ["length", "x", "point", "offset", "rest_length"], "diameter": ["diameter", "section"],
            "gravity": ["gravity", "g"], "position": ["position", "x", "y"], "pivot_x": ["x", "point"], "velocity": ["velocity"],
            "angle": ["angle"], "omega": ["omega", "motion", "speed"]}


def _build_template(name: str, p: Dict[str, Any]):
    uk = _ukflex()
    if name == "rigid_pendulum":
        s = uk.Scene(gravity=(0.0, -p["gravity"]) if isinstance(p["gravity"], (int, float)) else p["gravity"])
        rod = s.rigid_body("rod", mass=p["mass"], inertia=p["inertia"], position=(p["position"], 0.0),
                           angle=p["angle"], angular_velocity=p["angular_velocity"])
        s.revolute(s.ground.point(p["pivot_x"], 0.0), rod.point(p["length"], 0.0))
        return s
    if name == "point_pendulum":
        s = uk.Scene(gravity=(0.0, -p["gravity"]) if isinstance(p["gravity"], (int, float)) else p["gravity"])
        bob = s.point_mass("bob", mass=p["mass"], position=(p["position"], -0.5), velocity=(p["velocity"], 0.0))
        s.distance(s.ground.point(0.0, 0.0), bob.point(), length=p["length"])
        return s
    if name == "beam":
        s = uk.Scene()
        common = dict(length=p["length"], section=uk.Circular(p["diameter"]), density=p["density"],
                      youngs_modulus=p["youngs_modulus"], elements=p["elements"], damping=p["damping"],
                      angular_velocity=p["angular_velocity"])
        if p["formulation"] == "ancf":  # the cable: its own builder, without the FFRF beam's strain
            s.cable("b", **common)
        else:
            s.beam("b", strain=p["strain"], **common)
        return s
    if name == "slider_crank":
        return uk.scenes.slider_crank(**p)
    if name == "spring":
        s = uk.Scene()
        m = s.point_mass("m", mass=p["mass"], position=(p["position"], 0.0))
        s.point_on_line(m.point(), s.ground.line())
        s.spring_damper(s.ground.point(0.0, 0.0), m.point(), stiffness=p["stiffness"], damping=p["damping"],
                        rest_length=p["rest_length"])
        return s
    raise AssertionError(name)


def _length_scale(name: str, p: Dict[str, Any]) -> float:
    """The template's own size (a 1e-30 m pendulum is judged at 1e-30 m, not at 1 m); 1 m if it
    has none."""
    keys = ["length", "coupler_length", "crank_length", "rest_length"] + (["position"] if name == "spring" else [])
    vals = [abs(float(p[k])) for k in keys if isinstance(p.get(k), (int, float, np.floating))
            and not isinstance(p.get(k), bool) and math.isfinite(float(p[k]))]
    vals = [v for v in vals if v > 0.0]
    return max(vals) if vals else 1.0


@st.composite
def _scene_case(draw):
    name = draw(st.sampled_from(sorted(_TEMPLATES)))
    fields = _TEMPLATES[name]
    p = {k: draw(v) for k, v in fields.items()}
    field = draw(st.sampled_from(sorted(f for f in fields if f != "formulation")))  # a builder choice, not a field
    p[field] = draw(maybe_hostile(fields[field], 1))
    return dict(template=name, field=field, params=p)


def _check_scene(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    name, field, p = case["template"], case["field"], case["params"]
    names = [field] + _ALIASES.get(field, [])
    text_field = field in ("strain",)  # fields whose plausible values are strings
    no_gravity = field == "gravity" and p[field] is None  # Scene(gravity=None): a scene without gravity
    # None means "the distance at the initial guess" for a distance constraint and a spring's rest length
    no_gravity = no_gravity or (field in ("length", "rest_length") and name in ("point_pendulum", "spring")
                                and p[field] is None)
    hostile_input = not text_field and not no_gravity and (_is_bad_input(p[field]) if not isinstance(p[field], (list, tuple)) else True)
    with _quiet():
        try:
            system = uk.System(_build_template(name, p))
        except RecursionError as exc:
            return [("unnamed-exception", _exc(exc))]
        except Exception as exc:  # noqa: BLE001 - the point of the check
            return [] if _named(exc, names) else [("unnamed-exception", "build: " + _exc(exc))]
        findings: List[Finding] = []
        if hostile_input and not isinstance(p[field], (int, float)):
            # wrong types that survived: acceptable only if they coerce exactly (np.float32, np.int64)
            if isinstance(p[field], (str, bytes, dict, complex, np.ma.MaskedArray)) or p[field] is None:
                findings.append(("wrong", f"build accepted {field}={p[field]!r}"))
        if not _finite(system.q0, system.qd0):
            return findings + [("silent-nonfinite", "build: q0/qd0 not finite")]
        L = _length_scale(name, p)
        phi = _max_abs(system.phi(system.t0, system.q0))
        if phi > 1e-9 * L:
            findings.append(("wrong", f"build: max|Phi(q0)| = {phi:.3g} > 1e-9 L (L = {L:g})"))
        # the state must resolve the mechanism: a motion of 1e-6 L shows up in Phi as A d does
        # (at 1e17 m from the origin positions move in steps of 16 m and Phi reads 0 whatever)
        translation = np.array([c.endswith((".x", ".y")) for c in system.coordinate_names])
        d = 1e-6 * np.where(translation, L, 1.0) * np.cos(np.arange(system.n_coords) + 1.0)
        expected = system.A(system.q0) @ d
        actual = system.phi(system.t0, system.q0 + d) - system.phi(system.t0, system.q0)
        # slack: rounding, and the second-order term |d|^2 / L ~ 1e-12 L of curved constraints
        # (a distance probed nearly across its rod: A d is small, the curvature is not)
        if _max_abs(actual - expected) > 1e-3 * _max_abs(expected) + 1e-11 * L:
            findings.append(("wrong", f"build: the state does not resolve a 1e-6 L motion (dPhi {_max_abs(actual):.3g} "
                                      f"vs A d {_max_abs(expected):.3g}): positions too far from the origin"))
        try:
            res = uk.simulate(system, system.t0 + 0.02, method="DOPRI5", rtol=1e-8, max_steps=20000)
        except Exception as exc:  # noqa: BLE001
            return findings + ([] if _named(exc, names) else [("unnamed-exception", "simulate: " + _exc(exc))])
        t = np.asarray(res.t)
        if t.size == 0:  # allowed only for a run that failed at its first step and says so
            if res.status < 0 and " at t = " in str(res.message):
                return findings
            return findings + [("wrong", f"simulate: empty result (status {res.status}: {res.message})")]
        if res.status < 0:
            if not str(res.message).strip():
                findings.append(("wrong", "simulate failed without a message"))
            return findings
        if "drift" in res.extra:  # the run said it lost the constraints (DriftWarning): not silent
            return findings if str(res.extra["drift"].get("message", "")).strip() else \
                findings + [("wrong", "simulate: a drift report without a message")]
        q = np.array([res.coordinate(c) for c in system.coordinate_names])
        qd = np.array([res.velocity(c) for c in system.coordinate_names])
        if not _finite(q, qd):
            return findings + [("silent-nonfinite", "simulate: status 0 with non-finite states")]
        rp = max(_max_abs(system.phi(ti, q[:, k])) for k, ti in enumerate(t))
        # 1e-6 of the scene (or of the elastic motion, when a driver strains a beam far beyond
        # its length: the drift follows rtol x the state), or the global-error bound of the run's
        # own steps (a local error of rtol L per step, accumulated: a 1e7 m/s^2 pendulum takes 870
        # steps in 20 ms and drifts 1.4e-6 L, converging with rtol: 138 / 58 / 23 x rtol L at
        # rtol 1e-8 / 1e-10 / 1e-12), or 1000 x the run's absolute tolerance (atol = 1e-11 m)
        elastic = np.asarray(system.elastic_mask(), dtype=bool)
        L_run = max(L, _max_abs(q[elastic]) if elastic.any() else 0.0)
        steps = int(res.extra.get("naccept") or res.nfev // 6 or 1)
        limit = max(1e-6, steps * 1e-8) * L_run + 1e-8
        if rp > limit:
            findings.append(("wrong", f"simulate: max|Phi| = {rp:.3g} > max(1e-6, {steps} steps x rtol) L + 1e-8 m "
                                      f"(L = {L_run:g})"))
        conservative = name in ("rigid_pendulum", "point_pendulum") or (name == "beam" and p["damping"] == 0.0)
        if conservative:
            e = np.array([system.kinetic_energy(q[:, k], qd[:, k]) + system.potential_energy(q[:, k])
                          for k in range(t.size)])
            kin = max(abs(system.kinetic_energy(q[:, k], qd[:, k])) for k in range(t.size))
            m = p.get("mass", 1.0) if isinstance(p.get("mass"), float) else 1.0
            g = p.get("gravity", 0.0) if isinstance(p.get("gravity"), float) else 0.0
            scale = kin + abs(m * g * L) + 1e-12
            # floor: the kinetic energy of velocity errors the run's atol allows per step,
            # accumulated over its steps, 0.5 trace(M) (steps atol)^2 (a 7-tonne ANCF beam at rest
            # "drifts" by 1e-16 J: its energy scale is then 0, not the drift)
            floor = 0.5 * float(np.trace(np.asarray(system.M(q[:, 0])))) * (steps * 1e-11) ** 2
            drift = float(np.max(np.abs(e - e[0])))
            if not math.isfinite(drift) or drift > 1e-4 * scale + floor:
                findings.append(("wrong", f"conservative scene: energy drift {drift:.3g} > 1e-4 x {scale:.3g} + {floor:.3g}"))
        return findings


# ----------------------------------------------------------------------------------- TOML
_TOML_BASE = """\
gravity = [0.0, -9.81]

[scene]
name = "{name}"

[[bodies]]
name = "rod"
kind = "rigid"
mass = {mass}
inertia = {inertia}
position = [0.5, 0.0]

[[joints]]
kind = "revolute"
a = {{ body = "ground", point = [0.0, 0.0] }}
b = {{ body = "rod", point = [-0.5, 0.0] }}

[solver]
t_end = {t_end}
"""

_TOML_LITERALS = ["1e400", "-1e400", "nan", "inf", "1" + "0" * 400, "0", "-1", '"1"', "[]", "{}", "true",
                  "[1, 2, 3]", "1e-320", "0x7fffffffffffffff", "9223372036854775808"]


@st.composite
def _toml_case(draw):
    fields = dict(name=draw(st.sampled_from(["pend", "my scene", "..", "../../escape", "a/b", "", "x" * 300])),
                  mass=draw(st.sampled_from(["1.0", "2.5"] * 4 + _TOML_LITERALS)),
                  inertia=draw(st.sampled_from(["0.1"] * 8 + _TOML_LITERALS)),
                  t_end=draw(st.sampled_from(["0.01"] * 8 + _TOML_LITERALS)))
    text = _TOML_BASE.format(**fields)
    mutation = draw(st.sampled_from(["none", "none", "deep", "drop_line", "dup_key", "kind_list", "garbage",
                                     "many_bodies", "truncate"]))
    if mutation == "deep":
        depth = draw(st.sampled_from([50, 1000, 20000]))
        text += "\n[extra]\nx = " + "[" * depth + "]" * depth + "\n"
    elif mutation == "drop_line":
        lines = text.splitlines()
        del lines[draw(st.integers(0, len(lines) - 1))]
        text = "\n".join(lines)
    elif mutation == "dup_key":
        text = text.replace("mass = ", "mass = 1.0\nmass = ", 1)
    elif mutation == "kind_list":
        text = text.replace('kind = "rigid"', "kind = []")
    elif mutation == "garbage":
        text = text[: draw(st.integers(0, len(text)))] + draw(st.text(max_size=40))
    elif mutation == "many_bodies":
        k = draw(st.sampled_from([300, 3000]))
        extra = "".join(f'\n[[bodies]]\nname = "b{i}"\nkind = "rigid"\nmass = 1.0\ninertia = 0.1\n' for i in range(k))
        text += extra + '\n[[bodies]]\nname = "bad"\nkind = "rigid"\nmass = -1.0\ninertia = 0.1\n'
    elif mutation == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    return dict(mutation=mutation, fields=fields, text=text)


def _check_toml(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    from ukflex.model import scenefile

    with _quiet():
        try:
            sf = scenefile.loads(case["text"], path="fuzz.toml")
        except RecursionError as exc:
            return [("unnamed-exception", "loads: " + _exc(exc))]
        except Exception as exc:  # noqa: BLE001
            if isinstance(exc, uk.UkflexError) and "fuzz.toml" not in str(exc):
                return [("unnamed-exception", "loads: error does not name the file: " + _exc(exc))]
            return [] if _named(exc, ["fuzz.toml"]) else [("unnamed-exception", "loads: " + _exc(exc))]
        try:
            uk.System(sf.scene)
        except Exception as exc:  # noqa: BLE001
            return [] if isinstance(exc, uk.UkflexError) else [("unnamed-exception", "build: " + _exc(exc))]
    return []


# ----------------------------------------------------------------------------------- core
@st.composite
def _core_case(draw):
    uk = _ukflex()
    base = draw(st.sampled_from(["pendulum", "slider_crank", "every_joint"]))
    d = getattr(uk.scenes, base)().to_dict()
    section = draw(st.sampled_from([k for k in ("bodies", "joints", "drivers", "forces") if d.get(k)]))
    items = d[section]
    i = draw(st.integers(0, len(items) - 1))
    keys = sorted(items[i])
    key = draw(st.sampled_from(keys + ["__new__"]))
    value = draw(st.one_of(hostile(), st.sampled_from([[[[]]], {"body": "nope"}, "unknown", -1, 2 ** 64,
                                                      10 ** 30, [1e308, 1e308], [float("nan"), 0.0]])))
    return dict(base=base, section=section, index=i, key=key, value=value, description=d)


def _jsonable(v: Any) -> Any:
    if isinstance(v, np.ma.MaskedArray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, complex):
        return [v.real, v.imag]
    if isinstance(v, bytes):
        return v.decode("latin-1")
    return v


def _check_core(case: Dict[str, Any]) -> List[Finding]:
    import json

    uk = _ukflex()
    d = case["description"]
    d[case["section"]][case["index"]][case["key"]] = _jsonable(case["value"])
    try:
        text = json.dumps(d)
    except (TypeError, ValueError):
        return []
    with _quiet():
        try:
            core = uk._core.System(text)
        except Exception as exc:  # noqa: BLE001
            return [] if isinstance(exc, uk.UkflexError) else [("unnamed-exception", "core: " + _exc(exc))]
        try:
            q, qd = core.initial_guess()
            out = core.qdd(0.0, np.asarray(q), np.asarray(qd))
        except Exception as exc:  # noqa: BLE001
            return [] if isinstance(exc, uk.UkflexError) else [("unnamed-exception", "core qdd: " + _exc(exc))]
        if not _finite(out):
            return [("silent-nonfinite", "core: qdd at the initial guess is not finite")]
    return []


# ----------------------------------------------------------------------------------- arrays
_METHODS = {  # method -> argument names (t: scalar, q/qd: (n,), y: (2n,))
    "qdd": ("t", "q", "qd"), "rhs": ("t", "y"), "M": ("q",), "Q": ("t", "q", "qd"), "phi": ("t", "q"),
    "A": ("q",), "b": ("t", "q", "qd"), "multipliers": ("t", "q", "qd"), "residuals": ("t", "q", "qd"),
    "kinetic_energy": ("q", "qd"), "potential_energy": ("q",), "jac": ("t", "y"),
}


@st.composite
def _array_case(draw):
    sysname = draw(st.sampled_from(["slider_crank", "pendulum", "cantilever_ancf", "every_joint"]))
    n = _system(sysname).n_coords
    method = draw(st.sampled_from(sorted(_METHODS)))
    args = {}
    bad = draw(st.sampled_from(_METHODS[method]))
    for a in _METHODS[method]:
        size = 2 * n if a == "y" else n
        if a == "t":
            args[a] = draw(maybe_hostile(st.floats(0.0, 1.0), 1)) if a == bad else draw(st.floats(0.0, 1.0))
        elif a == bad:
            args[a] = draw(hostile_array(size))
        else:
            args[a] = np.array(draw(st.lists(st.floats(-1.0, 1.0), min_size=size, max_size=size)))
    return dict(system=sysname, method=method, bad=bad, args=args)


def _check_array(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    system = _system(case["system"])
    fn = getattr(system, case["method"])
    args = case["args"]
    bad = case["bad"]
    with _quiet():
        try:
            out = fn(*[args[a] for a in _METHODS[case["method"]]])
        except Exception as exc:  # noqa: BLE001
            return [] if _named(exc, [bad, f"'{bad}'"]) else [("unnamed-exception", _exc(exc))]
    v = args[bad]
    outs = out if isinstance(out, tuple) else (out,)
    # the per-call methods take t as a C double, like float(): a Python bool is 0.0 / 1.0 there
    # (simulate, the user-facing entry point, refuses booleans)
    if _is_bad_input(v) and not (bad == "t" and isinstance(v, bool)):
        if isinstance(v, (list, tuple)) and all(isinstance(x, float) for x in v):
            pass  # a plain list of floats is fine
        else:
            return [("wrong", f"{case['method']} accepted {bad} = {_short(v)}")]
    if not _finite(*outs):
        return [("silent-nonfinite", f"{case['method']} returned non-finite values for {bad} = {_short(v)}")]
    if case["method"] == "qdd" and np.asarray(v).shape == np.asarray(args.get("q", v)).shape:
        from ukflex.reference.uk import uk_qdd

        q = np.asarray(args["q"], dtype=float)
        qd = np.asarray(args["qd"], dtype=float)
        t = float(args["t"])
        if q.shape == (system.n_coords,) and qd.shape == (system.n_coords,) and _finite(q, qd):
            ref = uk_qdd(system.M(q), system.Q(t, q, qd), system.A(q), system.b(t, q, qd))
            err = _max_abs(np.asarray(out) - ref)
            scale = 1.0 + _max_abs(ref)
            if err > 1e-6 * scale:
                return [("wrong", f"qdd differs from the NumPy reference by {err:.3g} (scale {scale:.3g})")]
    return []


# ----------------------------------------------------------------------------------- simulate options
_OPTION_VALUES = {
    "max_step": maybe_hostile(scaled(1e-4, 1e-2), 1), "first_step": maybe_hostile(scaled(1e-6, 1e-3), 1),
    "max_steps": st.one_of(st.integers(1, 10 ** 5), st.sampled_from([0, -1, 1.5, 10 ** 30, "10", None])),
    "projection_tol": maybe_hostile(scaled(1e-12, 1e-6), 1), "rho_inf": maybe_hostile(st.floats(0.0, 1.0), 1),
    "step": maybe_hostile(scaled(1e-5, 1e-3), 1), "max_stpe": st.just(1e-3), "jacobian": st.sampled_from(
        ["analytic", "structured", "fd", "nope", 3]),
}


@st.composite
def _options_case(draw):
    method = draw(st.sampled_from(["auto", "RK45", "DOP853", "Radau", "BDF", "LSODA", "DOPRI5", "RADAU5", "GENALPHA",
                                   "dopri5", "genalpha", "rk45", "nope", "", 3]))
    t_end = draw(maybe_hostile(st.floats(0.005, 0.05), 2))
    rtol = draw(maybe_hostile(scaled(1e-9, 1e-3), 2))
    atol = draw(st.one_of(st.none(), maybe_hostile(scaled(1e-12, 1e-6), 2), hostile_array(6)))
    t_eval = draw(st.one_of(st.none(), st.none(), hostile_array(5),
                            st.just([0.0, 0.001, 0.002]), st.just([0.002, 0.001]), st.just([-1.0, 0.5]),
                            st.just(np.linspace(0.0, 1e9, 3))))
    keys = draw(st.lists(st.sampled_from(sorted(_OPTION_VALUES)), max_size=3, unique=True))
    options = {k: draw(_OPTION_VALUES[k]) for k in keys}
    return dict(method=method, t_end=t_end, rtol=rtol, atol=atol, t_eval=t_eval, options=options)


def _check_options(case: Dict[str, Any]) -> List[Finding]:
    uk = _ukflex()
    system = _system("pendulum")
    names = ["method", "t_end", "rtol", "atol", "t_eval"] + list(case["options"])
    with _quiet():
        try:
            # every case is bounded: a 5 s wall-time budget (the watchdog then checks it is kept)
            res = uk.simulate(system, case["t_end"], method=case["method"], rtol=case["rtol"], atol=case["atol"],
                              t_eval=case["t_eval"], **dict({"max_wall_time": 5.0}, **case["options"]))
        except Exception as exc:  # noqa: BLE001
            return [] if _named(exc, names) else [("unnamed-exception", _exc(exc))]
    findings: List[Finding] = []
    for k in ("t_end", "rtol"):
        if _is_bad_input(case[k]) or (isinstance(case[k], (int, float)) and not isinstance(case[k], bool)
                                      and case[k] <= 0):
            findings.append(("wrong", f"simulate accepted {k} = {_short(case[k])}"))
    for k, v in case["options"].items():
        if k == "max_steps" and not (isinstance(v, int) and not isinstance(v, bool) and v > 0):
            findings.append(("wrong", f"simulate accepted max_steps = {_short(v)}"))
        elif k != "max_steps" and k != "jacobian" and _is_bad_input(v):
            findings.append(("wrong", f"simulate accepted {k} = {_short(v)}"))
    if "max_stpe" in case["options"]:
        findings.append(("wrong", "simulate accepted the misspelt option max_stpe"))
    t = np.asarray(res.t)
    if res.status >= 0:
        if "drift" in res.extra:  # the run said it lost the constraints (DriftWarning): not silent
            return findings if str(res.extra["drift"].get("message", "")).strip() else \
                findings + [("wrong", "simulate: a drift report without a message")]
        q = np.array([res.coordinate(c) for c in system.coordinate_names])
        if not _finite(t, q):
            findings.append(("silent-nonfinite", "status >= 0 with non-finite states"))
        elif t.size and (case["atol"] is None or (isinstance(case["atol"], float) and case["atol"] <= 1e-6)):
            rp = max(_max_abs(system.phi(ti, q[:, k])) for k, ti in enumerate(t))
            if rp > 1e-5:
                findings.append(("wrong", f"max|Phi| = {rp:.3g} m on a 1 m pendulum"))
    elif not str(res.message).strip() or t.size == 0:
        findings.append(("wrong", f"failed run without message or partial result (t.size = {t.size})"))
    return findings


# ----------------------------------------------------------------------------------- CLI
@st.composite
def _cli_case(draw):
    target = draw(st.sampled_from(["pendulum", "examples/pendulum.toml", "fifo", "devzero", "dir", "missing",
                                   "spaces", "deep", "bigint", "empty", "binary", "dotdot_name", "kind_list"]))
    command = draw(st.sampled_from(["run", "run", "run", "export", "list"]))
    out = draw(st.sampled_from(["tmp", "tmp", "file", "proc", "dotdot", "dotdot_rel"]))
    samples = draw(st.sampled_from(["11", "11", "1e11", "-3", "0", "abc", "99999999999"]))
    t_end = draw(st.sampled_from(["0.01", "0.01", "-1", "nan", "1e300", "x"]))
    # output expressions: unknown joints and drivers must be refused before the run
    plot = draw(st.sampled_from([None, None, None, "reaction(nope).fx", "work(nope)", "reaction(pivot).fx", "rod.theta",
                                 "energy(nope).kinetic"]))
    param = draw(st.sampled_from([None, None, None, "gravity=nan", "gravity=inf", "gravity=abc", "mass=-1", "length=1e300"]))
    # a few runs plot in a separate process with an empty $HOME: nothing may be written there
    fresh = draw(st.sampled_from([False] * 9 + [True]))
    if draw(st.booleans()):  # half the runs are plausible but for the output, parameter and folder options
        target, command, samples, t_end = "pendulum", "run", "11", "0.01"
    if fresh:  # a run that plots, in its own process: what it writes outside its folder shows
        target, command, samples, t_end, out, param = "pendulum", "run", "11", "0.01", "tmp", None
        plot = draw(st.sampled_from([None, "rod.theta"]))
    return dict(target=target, command=command, out=out, samples=samples, t_end=t_end, plot=plot, param=param,
                fresh_process=fresh)


def _cli_subprocess(argv: List[str], work: str, home: str, repo: str) -> Tuple[int, str, str]:
    """``ukflex`` in a fresh process with an empty ``$HOME`` and no ``MPLCONFIGDIR`` (a seeded
    regression, named in ``FUZZ_REGRESSION``, is put back there too)."""
    import subprocess
    import sys

    os.makedirs(home, exist_ok=True)
    env = {k: v for k, v in os.environ.items() if k not in ("MPLCONFIGDIR", "XDG_CACHE_HOME", "XDG_CONFIG_HOME")}
    env.update(HOME=home, MPLBACKEND="Agg", PYTHONPATH=repo)
    code = ("import os, sys\nr = os.environ.get('FUZZ_REGRESSION')\nif r:\n    from fuzz import regressions\n"
            "    regressions.apply(r)\nfrom ukflex import cli\nsys.exit(cli.main(sys.argv[1:]))")
    p = subprocess.run([sys.executable, "-c", code] + argv, cwd=work, env=env, capture_output=True, text=True,
                       timeout=60)
    return p.returncode, p.stdout, p.stderr


def _cli_target(kind: str, work: str, repo: str) -> str:
    p = os.path.join(work, "in")
    os.makedirs(p, exist_ok=True)
    good = _TOML_BASE.format(name="pend", mass="1.0", inertia="0.1", t_end="0.01")
    files = {"spaces": ("my scene.toml", good), "deep": ("deep.toml", "x = " + "[" * 5000 + "]" * 5000),
             "bigint": ("big.toml", good.replace("mass = 1.0", "mass = 1" + "0" * 400)), "empty": ("empty.toml", ""),
             "binary": ("bin.toml", "\x00\xff\x01garbage"),
             "dotdot_name": ("dd.toml", good.replace('name = "pend"', 'name = "../../escaped"')),
             "kind_list": ("kl.toml", good.replace('kind = "rigid"', "kind = []"))}
    if kind in files:
        fname, text = files[kind]
        path = os.path.join(p, fname)
        with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        return path
    if kind == "fifo":
        path = os.path.join(p, "fifo.toml")
        if not os.path.exists(path):
            os.mkfifo(path)
        return path
    if kind == "devzero":
        return "/dev/zero"
    if kind == "dir":
        return p
    if kind == "missing":
        return os.path.join(p, "missing.toml")
    if kind == "examples/pendulum.toml":
        return os.path.join(repo, kind)
    return kind


def _check_cli(case: Dict[str, Any]) -> List[Finding]:
    from ukflex import cli

    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with tempfile.TemporaryDirectory() as root:
        work = os.path.join(root, "a", "b", "work")
        os.makedirs(work)
        target = _cli_target(case["target"], work, repo)
        outs = {"tmp": os.path.join(work, "out"), "file": os.path.join(work, "in"), "proc": "/proc/ukflex-fuzz",
                "dotdot": os.path.join(work, "..", ".."), "dotdot_rel": os.path.join(".", "x", "..", "out2")}
        out = outs[case["out"]]
        if case["out"] == "file":
            out = os.path.join(work, "a_file")
            open(out, "w").close()
        if case["command"] == "run":
            argv = ["run", target, "--t-end", case["t_end"], "--samples", case["samples"],
                    "--method", "DOPRI5", "--no-progress"] + ([] if case.get("fresh_process") else ["--no-plot"])
            if case["out"] != "tmp" or case["target"] != "dotdot_name":
                argv += ["--out", out]
            if case.get("plot"):
                argv += ["--plot", case["plot"]]
            if case.get("param") and case["target"] == "pendulum":
                argv += ["--param", case["param"]]
        elif case["command"] == "export":
            argv = ["export", case["target"] if case["target"] == "pendulum" else "pendulum", "-o",
                    out if case["out"] != "tmp" else os.path.join(work, "exp.toml")]
        else:
            argv = ["list"]
        before = {d: set(os.listdir(d)) for d in (root, os.path.join(root, "a"), os.path.join(root, "a", "b"))}
        err, stdout = io.StringIO(), io.StringIO()
        home = tempfile.mkdtemp(prefix="fuzz-home-")  # beside the watched folders, removed below
        if case.get("fresh_process"):
            code, out_text, text = _cli_subprocess(argv, work, home, repo)
            stdout.write(out_text)
            err.write(text)
        else:
            cwd = os.getcwd()
            os.chdir(work)
            try:
                with contextlib.redirect_stderr(err), contextlib.redirect_stdout(stdout), _quiet():
                    try:
                        code = cli.main(argv)
                    except SystemExit as exc:
                        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
            except Exception as exc:  # noqa: BLE001
                return [("cli-traceback", f"{argv[:2]}: {_exc(exc)}")]
            finally:
                os.chdir(cwd)
        findings: List[Finding] = []
        text = err.getvalue()
        written = [os.path.relpath(os.path.join(d, f), home) for d, _, fs in os.walk(home) for f in fs]
        shutil.rmtree(home, ignore_errors=True)
        if written:
            findings.append(("cli-traceback", f"{argv}: wrote under $HOME: {written[:3]}"))
        if os.path.isdir(os.path.join(work, "x")):
            findings.append(("cli-traceback", f"{argv}: left a stray folder x/ on the way to its --out"))
        if code == 2 and case["command"] == "run":  # a user error is found before the run: no results written
            for d in {out, os.path.join(work, "out2")}:
                if os.path.isdir(d):
                    results = [f for f in os.listdir(d) if f.endswith((".csv", ".npz"))]
                    if results:
                        findings.append(("cli-traceback", f"{argv}: exit 2 after the run (wrote {results})"))
        failed_run = code == 1 and "status -1" in stdout.getvalue()  # ran, failed (budget, NaN), said so
        if code not in (0, 2) and not failed_run:
            findings.append(("cli-traceback", f"{argv}: exit status {code}: {text[-300:]}"))
        if "Traceback" in text:
            findings.append(("cli-traceback", f"{argv}: traceback printed: {text[-300:]}"))
        if code == 2 and "error" not in text.lower():
            findings.append(("cli-traceback", f"{argv}: exit 2 without an error line: {text[-200:]!r}"))
        after = {d: set(os.listdir(d)) for d in before}
        explicit_out = "--out" in argv or "-o" in argv  # the user chose that folder: writing there is right
        for d in ([] if explicit_out else before):
            new = after[d] - before[d]
            if new:
                findings.append(("cli-traceback", f"{argv}: wrote outside its folder: {sorted(new)} in {d}"))
        return findings


# ----------------------------------------------------------------------------------- threads
@st.composite
def _thread_case(draw):
    return dict(system=draw(st.sampled_from(["slider_crank", "pendulum"])),
                rtols=draw(st.lists(st.sampled_from([1e-4, 1e-6, 1e-8]), min_size=2, max_size=4)),
                method=draw(st.sampled_from(["DOPRI5", "RADAU5", "GENALPHA"])),
                seed=draw(st.integers(0, 2 ** 16)),
                settings=draw(st.lists(st.sampled_from([None, "projection", ("baumgarte", 50.0, 50.0),
                                                        ("baumgarte", 500.0, 500.0)]), min_size=0, max_size=3)))


def _check_threads(case: Dict[str, Any]) -> List[Finding]:
    system = _system(case["system"])
    te = np.linspace(0.0, 0.003, 4)
    rng = np.random.default_rng(case["seed"])
    n = system.n_coords
    states = [(0.01 * k, system.y0 + np.concatenate([np.zeros(n), 1e-3 * rng.standard_normal(n)]))
              for k in range(4)]

    def run(rtol):
        r = system.integrate(0.0, system.y0, 0.003, case["method"], rtol, None, te)
        return np.asarray(r["y"])

    def calls(s):
        t, y = s
        return np.concatenate([system.rhs(t, y), system.multipliers(t, y[:n], y[n:])])

    def configured(st):  # per-run settings on the shared System (simulate's stabilization= must not leak them)
        import ukflex

        return np.asarray(ukflex.simulate(system, 0.002, "RK45", rtol=1e-6, t_eval=te[:3], stabilization=st or "none", raise_on_failure=True).y)

    jobs = ([lambda r=r: run(r) for r in case["rtols"]] + [lambda s=s: calls(s) for s in states]
            + [lambda st=st: configured(st) for st in case.get("settings", [])])
    serial = [j() for j in jobs]
    barrier = threading.Barrier(len(jobs))

    def job(k):
        barrier.wait()
        return jobs[k]()

    with ThreadPoolExecutor(len(jobs)) as ex:
        got = list(ex.map(job, range(len(jobs))))
    for k, ref in enumerate(serial):
        if not np.array_equal(ref, got[k]):
            return [("wrong", f"threaded result {k} differs from serial (max diff {_max_abs(ref - got[k]):.3g})")]
    return []


CATEGORIES: Dict[str, Category] = {
    c.name: c
    for c in [
        Category("scene", _scene_case, _check_scene,
                 "scenes through the Python API with one hostile property; build, correct, simulate 20 ms"),
        Category("toml", _toml_case, _check_toml, "TOML scene text with hostile values and broken structure"),
        Category("core", _core_case, _check_core, "description dicts with one hostile entry straight to the core"),
        Category("arrays", _array_case, _check_array, "System per-call methods with hostile arrays"),
        Category("options", _options_case, _check_options, "simulate with hostile options"),
        Category("cli", _cli_case, _check_cli, "the CLI with hostile files, paths and options"),
        Category("threads", _thread_case, _check_threads, "concurrent integrations and calls on one System"),
    ] + SURFACES
}

#: relative weights of the categories in a mixed run (the CLI and threads cases cost the most)
WEIGHTS = {"scene": 3, "toml": 2, "core": 3, "arrays": 4, "options": 2, "cli": 1, "threads": 1, **SURFACE_WEIGHTS}

__all__ = ["CATEGORIES", "WEIGHTS", "Category", "Finding", "WRONG_TYPES"]
