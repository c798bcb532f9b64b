"""Spatial loads that are functions (issue 32; docs/loads.md, "In 3D"): ``SpatialScene.point_load``
and ``torque_load`` with components that are numbers, expressions of ``t`` and of coordinates, and
Python callables, against closed forms (a forced spring-mass along an inclined line, a torque's
angular acceleration), and the named errors."""

from __future__ import annotations

import numpy as np
import pytest

import ukflex
from ukflex.model.spatial import SpatialScene

M, K, C, W, F0 = 2.0, 200.0, 4.0, 7.0, 5.0
E = np.array([1.0, 2.0, 2.0]) / 3.0
X_CLOSED = F0 / np.hypot(K - M * W**2, C * W)


def _amplitude(system, method, t_end=14.0):
    t = np.linspace(t_end - 2 * np.pi / W * 3, t_end, 3001)
    res = ukflex.simulate(system, t_end, method=method, rtol=1e-9, t_eval=t)
    r = res.q[:3, :].T - E  # displacement from the spring's rest point
    along, across = r @ E, r - np.outer(r @ E, E)
    return 0.5 * (along.max() - along.min()), np.abs(across).max()


def test_forced_spring_mass_along_an_inclined_line_matches_the_closed_form():
    """``F0 sin(w t) e`` (an expression of ``t``) on a spring-damper along ``e``: the steady
    amplitude ``F0 / sqrt((k - m w^2)^2 + (c w)^2)`` (transients decay as ``exp(-c t / 2m)``)."""
    s = SpatialScene()
    m = s.point_mass("m", M, position=E)
    s.spring_damper(s.ground.marker((0, 0, 0)), m.marker(), K, C, rest_length=1.0)
    s.point_load(m.marker(), [f"{float(F0 * e)!r} * sin({W} * t)" for e in E])
    amp, across = _amplitude(ukflex.System(s), "DOPRI5")
    assert abs(amp / X_CLOSED - 1) < 1e-5, (amp, X_CLOSED)
    assert across < 1e-9


@pytest.mark.parametrize("method", ["RADAU5", "GENALPHA"])
def test_spring_and_damper_written_as_loads_of_coordinates_implicit(method):
    """The same oscillator with its spring and damper written as one ``point_load`` of the
    coordinates and their rates (``-k (m.x - ex) - c d:m.x + F0 ex sin(w t)``): the implicit
    methods' Newton matrices take the expressions' gradient; the amplitude is the closed form's."""
    s = SpatialScene()
    m = s.point_mass("m", M, position=E)
    comps = [f"-{K} * (m.{a} - {float(e)!r}) - {C} * d:m.{a} + {float(F0 * e)!r} * sin({W} * t)" for a, e in zip("xyz", E)]
    s.point_load(m.marker(), comps)
    amp, across = _amplitude(ukflex.System(s), method)
    tol = 1e-5 if method == "RADAU5" else 3e-5
    assert abs(amp / X_CLOSED - 1) < tol, (amp, X_CLOSED)


def _spinner(torque, frame="world", **kw):
    s = SpatialScene()
    b = s.rigid_body("b", 1.0, [1.0, 2.0, 3.0])
    s.torque_load(b, torque, frame=frame, **kw)
    return ukflex.System(s)


@pytest.mark.parametrize("torque", [[0, 0, "6 * t"], [0.0, 0.0, lambda t, state: 6.0 * t]], ids=["expression", "callable"])
def test_torque_load_gives_the_closed_form_angular_acceleration(torque):
    """``tau_z = 6 t`` on ``J_z = 3``: ``alpha = 2 t``, ``omega = t^2``, ``theta = t^3 / 3``."""
    system = _spinner(torque)
    t = np.linspace(0.0, 1.5, 7)
    res = ukflex.simulate(system, 1.5, method="DOPRI5", rtol=1e-10, t_eval=t)
    p = res.q[3:7, :]
    theta = 2 * np.arctan2(p[3], p[0])
    np.testing.assert_allclose(theta, t**3 / 3, atol=1e-8)
    qdd = system.qdd(1.5, res.q[:, -1], res.qd[:, -1])
    # p3'' = d/dt (omega/2 cos(theta/2)) = alpha/2 cos - omega^2/4 sin
    th, w, a = 1.5**3 / 3, 1.5**2, 3.0
    assert abs(qdd[6] - (a / 2 * np.cos(th / 2) - w**2 / 4 * np.sin(th / 2))) < 1e-6


def test_body_frame_torque_turns_with_the_body():
    """A torque about the body's x axis on a body spun 90 degrees about z is the world y torque."""
    s = SpatialScene()
    q = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]
    b = s.rigid_body("b", 1.0, [2.0, 2.0, 3.0], orientation=q)
    s.torque_load(b, ["4 * (1 + t)", 0, 0], frame="body")
    sw = SpatialScene()
    b2 = sw.rigid_body("b", 1.0, [2.0, 2.0, 3.0], orientation=q)
    sw.torque(b2, [0.0, 8.0, 0.0])
    sys1, sys2 = ukflex.System(s), ukflex.System(sw)
    q0, qd0 = np.asarray(sys1.q0), np.zeros(7)
    np.testing.assert_allclose(sys1.qdd(1.0, q0, qd0), sys2.qdd(1.0, q0, qd0), atol=1e-12)


def test_named_errors():
    s = SpatialScene()
    m = s.point_mass("m", 1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="3 components"):
        s.point_load(m.marker(), [1.0, 2.0])
    s.point_load(m.marker(), [0, "m.w + 1", 0])
    with pytest.raises(ukflex.ExpressionError, match="unknown state quantity 'm.w'"):
        ukflex.System(s)
    bad = SpatialScene()
    m = bad.point_mass("m", 1.0)
    d = bad.to_dict()
    d["forces"] = [{"kind": "point_load", "point": {"body": "m"}, "force": [1.0, 2.0]}]
    with pytest.raises(ukflex.InvalidSceneError, match="force must have 3 components, got 2"):
        ukflex.System(d)
    s = SpatialScene()
    m = s.point_mass("m", 1.0)
    s.point_load(m.marker(), [0, 0, lambda t, state: float("nan") if t > 0.1 else 0.0])
    with pytest.raises(ukflex.NonFiniteError, match="callable0' returned NaN"):
        ukflex.simulate(ukflex.System(s), 1.0, method="DOPRI5")
    s = SpatialScene()
    m = s.point_mass("m", 1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="rigid3"):
        s.torque_load(m, [0, 0, "t"])
        ukflex.System(s)


def test_beam_node_coordinates_are_read_by_callables_not_by_expressions():
    """A beam node's coordinates (``a[1].z``) cannot be spelled in an expression (an
    ``ExpressionError`` naming it), while an expression of ``t`` on a scene with a beam builds and a
    callable reads them through ``inputs``."""
    def scene(load, **kw):
        s = SpatialScene()
        sec = ukflex.CustomSection3(ea=1e6, ga_y=1e6, ga_z=1e6, gj=1e3, ei_y=1e3, ei_z=1e3, mass_per_length=1.0,
                                    rotary_inertia=(2.0, 1.0, 1.0))
        a = s.beam("a", (0, 0, 0), (1, 0, 0), sec, elements=2)
        s.fixed(s.ground.marker((0, 0, 0)), a.node(0))
        s.point_load(a.node(-1), [0, 0, load], **kw)
        return ukflex.System(s)

    seen = []
    system = scene(lambda t, state: seen.append(state["a[1].z"]) or 1.0, inputs=["a[1].z"])
    system.qdd(0.0, system.q0, np.zeros(len(system.q0)))
    assert seen and seen[-1] == 0.0
    scene("2 * t")
    with pytest.raises(ukflex.ExpressionError, match="unknown state quantity 'a'"):
        scene("a[1].z")
