"""Loads of a joint's state (docs/loads.md, "Load values"): ``angle(J)``, ``d:angle(J)`` of a
revolute joint and ``s(J)``, ``d:s(J)`` of a prismatic joint, against the built-in rotational
spring-damper and closed forms."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Scene

M, L, G, TH0 = 0.8, 0.5, 9.81, 0.01
KT, CT = 1.5, 0.02


def _pendulum(kind):
    """A rod hanging from the ground by the revolute ``hinge``, with a torsional spring-damper
    about the hanging position: built in, a ``torque_load`` or a ``motor`` of the hinge's angle."""
    s = Scene(gravity=(0.0, -G))
    rod = s.rigid_body("rod", mass=M, inertia=M * L**2 / 12, com=(L / 2, 0.0), angle=-math.pi / 2 + TH0)
    s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="hinge")
    torque = f"-{KT} * (angle(hinge) + {math.pi / 2!r}) - {CT} * d:angle(hinge)"
    if kind == "builtin":
        s.rotational_spring_damper(rod.frame(), stiffness=KT, damping=CT, rest_angle=-math.pi / 2)
    elif kind == "torque_load":
        s.torque_load(rod.frame(), torque)
    else:
        s.motor(rod.frame(), torque)
    return s.build()


@pytest.mark.parametrize("method", ["DOPRI5", "RADAU5M"])
def test_torsional_spring_of_the_hinge_angle_is_the_builtin_and_the_closed_form(method):
    t = np.linspace(0.0, 5.0, 251)
    runs = {k: ukflex.simulate(_pendulum(k), t[-1], method=method, rtol=1e-11, atol=1e-13, t_eval=t) for k in ("builtin", "torque_load", "motor")}
    theta = {k: r.coordinate("rod.theta") + math.pi / 2 for k, r in runs.items()}
    for k in ("torque_load", "motor"):
        assert np.max(np.abs(theta[k] - theta["builtin"])) < 1e-10
    # linearized closed form: J th'' + c th' + (k + m g L / 2) th = 0
    J = M * L**2 / 3
    wn, sigma = math.sqrt((KT + M * G * L / 2) / J), CT / (2 * J)
    wd = math.sqrt(wn**2 - sigma**2)
    exact = TH0 * np.exp(-sigma * t) * (np.cos(wd * t) + sigma / wd * np.sin(wd * t))
    # the sin(theta) ~ theta error (theta0^2 / 16 of the gravity's share of the frequency)
    assert np.max(np.abs(theta["torque_load"] - exact)) < 1e-4 * TH0  # measured 3.3e-5


@pytest.mark.parametrize("method", ["DOPRI5", "RADAU5M"])
def test_slider_held_by_its_slide_and_rate_is_the_closed_form(method):
    m, k, c, s0, a = 1.5, 600.0, 3.0, 0.02, 0.5
    s = Scene()
    # the block's centre on an axis through the ground's (0.1, -0.2), turned by a; started at s0
    base = np.array([0.1, -0.2])
    e = np.array([math.cos(a), math.sin(a)])
    block = s.rigid_body("block", mass=m, inertia=0.01, position=tuple(base + s0 * e), angle=a)
    s.prismatic(block.frame(), s.ground.point(0.1, -0.2, angle=a), name="slide")
    f = f"(-{k} * s(slide) - {c} * d:s(slide))"
    s.point_load(block.point(0, 0), fx=f"{f} * {math.cos(a)!r}", fy=f"{f} * {math.sin(a)!r}")
    t = np.linspace(0.0, 1.0, 101)
    res = ukflex.simulate(s.build(), t[-1], method=method, rtol=1e-11, atol=1e-13, t_eval=t)
    wn, sigma = math.sqrt(k / m), c / (2 * m)
    wd = math.sqrt(wn**2 - sigma**2)
    exact = s0 * np.exp(-sigma * t) * (np.cos(wd * t) + sigma / wd * np.sin(wd * t))
    along = (res.coordinate("block.x") - base[0]) * e[0] + (res.coordinate("block.y") - base[1]) * e[1]
    assert np.max(np.abs(along - exact)) < 1e-8 * s0  # measured 4e-11 (DOPRI5), 2e-13 (RADAU5M)
    assert np.max(np.abs(along)) > 0.5 * s0


def test_joint_inputs_bad_input_is_named():
    s = Scene()
    w = s.rigid_body("w", mass=1.0, inertia=0.1)
    s.revolute(w.point(0, 0), s.ground.point(0, 0), name="pin")
    with pytest.raises(ukflex.ExpressionError, match=r"unknown joint 'hinge'; the joints are: pin"):
        s.torque_load(w.frame(), "-angle(hinge)")
    with pytest.raises(ukflex.ExpressionError, match=r"'pin' is a revolute joint; angle\(JOINT\) reads a revolute joint, s\(JOINT\) a prismatic joint"):
        s.torque_load(w.frame(), "-s(pin)")
