"""Loads that are functions of time and state, motors and force elements (docs/loads.md), each
against a closed form, through the public API."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import LoadTable, Scene
from ukflex.model.scene import dc_motor_torque

# forced oscillator: m x'' + c x' + k x = F0 sin(w t)
M, K, C, F0, W = 2.0, 200.0, 4.0, 3.0, 7.0


def _steady(t):
    """The closed-form steady state of the forced oscillator at times ``t``."""
    amp = F0 / math.hypot(K - M * W**2, C * W)
    phase = math.atan2(C * W, K - M * W**2)
    return amp, amp * np.sin(W * t - phase)


def _oscillator(state_expression):
    s = Scene()
    s.point_mass("m", mass=M, position=(1.0, 0.0))
    forcing = f"{F0} * sin({W} * t)"
    if state_expression:
        # spring and damper written in the load's expression, of the state quantities m.x, d:m.x
        s.point_load(s["m"].point(), fx=f"{forcing} - {K} * (m.x - 1) - {C} * d:m.x", name="load")
    else:
        s.spring_damper(s.ground.point(0, 0), s["m"].point(), stiffness=K, damping=C)
        s.point_load(s["m"].point(), fx=forcing, name="load")
    return s.build()


@pytest.mark.parametrize("state_expression, method", [(False, "DOPRI5"), (True, "DOPRI5"), (True, "RADAU5M")])
def test_forced_oscillator_reaches_the_closed_form_steady_state(state_expression, method):
    system = _oscillator(state_expression)
    # transient decays as exp(-C t / (2 M)) = exp(-t): gone to 2e-7 by t = 15
    t = np.linspace(15.0, 15.0 + 4 * math.pi / W, 201)
    kw = dict(rtol=1e-10, atol=1e-12) if method == "DOPRI5" else dict(rtol=1e-8, atol=1e-10)
    res = ukflex.simulate(system, t[-1], method=method, t_eval=np.concatenate([[0.0], t]), **kw)
    amp, x = _steady(t)
    err = np.max(np.abs(res.coordinate("m.x")[1:] - 1.0 - x)) / amp
    assert err < 1e-5, err
    assert np.max(np.abs(res.coordinate("m.y"))) == 0.0


def test_table_load_of_a_state_quantity_is_a_spring():
    # a force tabulated against m.x (linear data: the spline is the line) makes a spring
    s = Scene()
    s.point_mass("m", mass=M, position=(0.05, 0.0))
    xs = np.linspace(-0.2, 0.2, 9)
    s.point_load(s["m"].point(), fx=LoadTable(of="m.x", x=xs, y=-K * xs))
    res = ukflex.simulate(s.build(), 1.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=np.linspace(0, 1, 101))
    wn = math.sqrt(K / M)
    assert np.max(np.abs(res.coordinate("m.x") - 0.05 * np.cos(wn * res.t))) < 1e-9


def test_periodic_table_of_time():
    # a periodic table of t (one period of sin sampled finely) forces like the expression
    s = Scene()
    s.point_mass("m", mass=1.0)
    period = 2 * math.pi / W
    x = np.linspace(0.0, period, 401)
    s.point_load(s["m"].point(), fx=LoadTable(of="t", x=x, y=F0 * np.sin(W * x), period=period))
    t_end = 2.5 * period
    res = ukflex.simulate(s.build(), t_end, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=[t_end])
    # free mass: x = F0/(m w^2) (w t - sin w t)
    exact = F0 / W**2 * (W * t_end - math.sin(W * t_end))
    assert res.coordinate("m.x")[-1] == pytest.approx(exact, rel=1e-6)


def _flywheel(torque, inertia=0.02, rotor=0.0):
    s = Scene()
    wheel = s.rigid_body("wheel", mass=3.0, inertia=inertia)
    s.revolute(wheel.point(0, 0), s.ground.point(0, 0), name="bearing")
    s.motor(wheel.frame(), torque, rotor_inertia=rotor, name="motor")
    return s.build()


def test_dc_motor_spins_a_flywheel_up_as_the_closed_form():
    k, R, V, J, Jr = 0.05, 0.8, 12.0, 0.02, 0.004
    system = _flywheel(dc_motor_torque(k, R, V), J, Jr)
    t = np.linspace(0.0, 40.0, 201)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    tau = (J + Jr) * R / k**2  # the rotor inertia counts
    exact = V / k * (1.0 - np.exp(-t / tau))
    assert np.max(np.abs(res.velocity("wheel.theta") - exact)) < 1e-7 * V / k
    # the motor's work is external work: the energy balance closes
    bal = res.sensors.energy_balance()
    assert bal["relative_error"] < 1e-6, bal["relative_error"]


def test_motor_torque_speed_table():
    # a linear torque-speed table is the DC motor's line: tau = T0 (1 - w / w0)
    T0, w0, J = 2.0, 50.0, 0.05
    system = _flywheel(LoadTable(of="w", x=[0.0, 25.0, 60.0], y=[T0, T0 / 2, T0 * (1 - 60 / w0)]), J)
    t = np.linspace(0.0, 3.0, 31)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    exact = w0 * (1.0 - np.exp(-t * T0 / (w0 * J)))
    assert np.max(np.abs(res.velocity("wheel.theta") - exact)) < 1e-6 * w0


def test_pi_speed_controller_as_an_expression():
    # tau = Kp (w_ref - w) + Ki (w_ref t - angle): the integral of the speed error is the angle
    # error, so no extra state is needed. e = w_ref t - angle obeys J e'' + Kp e' + Ki e = 0.
    J, Kp, Ki, wr = 0.05, 0.4, 2.0, 30.0
    system = _flywheel(f"{Kp} * ({wr} - w) + {Ki} * ({wr} * t - angle)", J)
    t = np.linspace(0.0, 2.0, 81)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    sigma, wd = Kp / (2 * J), math.sqrt(Ki / J - (Kp / (2 * J)) ** 2)
    e_dot = wr * np.exp(-sigma * t) * (np.cos(wd * t) - sigma / wd * np.sin(wd * t))
    assert np.max(np.abs(res.velocity("wheel.theta") - (wr - e_dot))) < 1e-6 * wr


def test_motor_drives_a_slider_crank_from_rest_to_its_steady_speed():
    # rigid slider-crank, DC motor on the crank, viscous load on the slider: the mean speed
    # settles where the motor's mean power equals the damper's
    s = Scene()
    L, Lb = 0.15, 0.3
    crank = s.rigid_body("crank", mass=1.0, inertia=0.01, com=(L / 2, 0.0))
    coupler = s.rigid_body("coupler", mass=1.0, inertia=0.0075, com=(Lb / 2, 0.0), position=(L, 0.0), angle=math.pi)
    slider = s.point_mass("slider", mass=0.5, position=(L + Lb, 0.0))
    s.revolute(crank.point(0, 0), s.ground.point(0, 0))
    s.revolute(crank.point(L, 0), coupler.point(0, 0))
    s.revolute(coupler.point(Lb, 0), slider.point())
    s.point_on_line(slider.point(), s.ground.line((0, 0), angle=0.0))
    k, R, V, c = 0.1, 1.0, 6.0, 8.0
    s.motor(crank.frame(), dc_motor_torque(k, R, V), rotor_inertia=0.002)
    s.point_load(slider.point(), fx=f"-{c} * d:slider.x")
    system = s.build()
    t = np.linspace(0.0, 12.0, 6001)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-9, atol=1e-11, t_eval=t)
    theta, w, v = res.coordinate("crank.theta"), res.velocity("crank.theta"), res.velocity("slider.x")
    assert w[0] == 0.0 and np.all(np.isfinite(w))
    # the last two revolutions: mean speed as the power balance has it
    last = theta >= theta[-1] - 4 * math.pi
    tl = t[last]
    tau = k * (V - k * w[last]) / R
    p_motor = np.trapezoid(tau * w[last], tl)
    p_damper = np.trapezoid(c * v[last] ** 2, tl)
    kinetic = res.sensors.energies()["kinetic"][last]
    # over the window the kinetic energy changes by its periodic part only
    assert abs(p_motor - p_damper - (kinetic[-1] - kinetic[0])) < 1e-4 * p_motor
    # steady: the mean speed of the last revolution equals the one before to 0.1 %
    half = theta[last] >= theta[-1] - 2 * math.pi
    w1, w2 = np.mean(w[last][~half]), np.mean(w[last][half])
    assert abs(w1 - w2) < 1e-3 * w2 and w2 > 0.5 * V / k * 0.2


def test_pendulum_with_viscous_hinge_friction_decays_at_the_closed_form_rate():
    m, L, g, c, th0 = 0.8, 0.5, 9.81, 0.02, 0.01
    s = Scene(gravity=(0.0, -g))
    rod = s.rigid_body("rod", mass=m, inertia=m * L**2 / 12, com=(L / 2, 0.0), angle=-math.pi / 2 + th0)
    s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="hinge")
    s.rotational_spring_damper(rod.frame(), damping=c, name="friction")
    J = m * L**2 / 3
    wn, sigma = math.sqrt(m * g * L / 2 / J), c / (2 * J)
    wd = math.sqrt(wn**2 - sigma**2)
    t = np.linspace(0.0, 10.0, 501)
    res = ukflex.simulate(s.build(), t[-1], method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    exact = th0 * np.exp(-sigma * t) * (np.cos(wd * t) + sigma / wd * np.sin(wd * t))
    theta = res.coordinate("rod.theta") + math.pi / 2
    # linearized closed form: the sin(theta) ~ theta error is theta0^2 / 16 of the frequency
    assert np.max(np.abs(theta - exact)) < 2e-3 * th0
    # the energy lost is what the friction dissipated
    assert res.sensors.energy_balance()["relative_error"] < 1e-6


def test_rotational_spring_frequency():
    J, k = 0.03, 1.2
    s = Scene()
    wheel = s.rigid_body("wheel", mass=1.0, inertia=J, angular_velocity=0.5)
    s.revolute(wheel.point(0, 0), s.ground.point(0, 0))
    s.rotational_spring_damper(wheel.frame(), stiffness=k)
    t = np.linspace(0, 2, 41)
    res = ukflex.simulate(s.build(), 2.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    w = math.sqrt(k / J)
    assert np.max(np.abs(res.coordinate("wheel.theta") - 0.5 / w * np.sin(w * t))) < 1e-9
    assert s.to_dict()["forces"][0]["rest_angle"] == 0.0


def test_bushing_modes_are_decoupled_at_the_centre_of_mass():
    m, J, kx, ky, kp = 2.0, 0.05, 800.0, 200.0, 3.0
    s = Scene()
    body = s.rigid_body("b", mass=m, inertia=J, position=(0.3, 0.1), angle=0.4, velocity=(0.2, -0.1), angular_velocity=0.3)
    s.bushing(body.point(0, 0), s.ground.point(0.3, 0.1, angle=0.4), stiffness=(kx, ky, kp))
    t = np.linspace(0, 1, 51)
    res = ukflex.simulate(s.build(), 1.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    # offsets in the ground marker's frame (rotated by 0.4): each axis its own oscillator
    c, sn = math.cos(0.4), math.sin(0.4)
    vx, vy = c * 0.2 + sn * -0.1, -sn * 0.2 + c * -0.1
    dx, dy = res.coordinate("b.x") - 0.3, res.coordinate("b.y") - 0.1
    lx, ly = c * dx + sn * dy, -sn * dx + c * dy
    for got, v0, k_, mm in [(lx, vx, kx, m), (ly, vy, ky, m), (res.coordinate("b.theta") - 0.4, 0.3, kp, J)]:
        w = math.sqrt(k_ / mm)
        assert np.max(np.abs(got - v0 / w * np.sin(w * t))) < 1e-8


def test_bushing_balances_forces_and_moments_between_two_bodies():
    # two free bodies joined by a bushing with damping: momentum and angular momentum stay
    s = Scene()
    a = s.rigid_body("a", mass=1.0, inertia=0.1, velocity=(0.3, 0.0), angular_velocity=1.0)
    b = s.rigid_body("b", mass=2.0, inertia=0.2, position=(0.5, 0.2), angle=0.3)
    s.bushing(a.point(0.2, 0.1), b.point(-0.1, -0.05), stiffness=(50, 80, 2), damping=(0.5, 0.3, 0.1))
    res = ukflex.simulate(s.build(), 2.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=[0.0, 2.0])

    def momenta(k):
        p = np.zeros(2)
        h = 0.0
        for name, mass, inertia in [("a", 1.0, 0.1), ("b", 2.0, 0.2)]:
            x, y = res.coordinate(f"{name}.x")[k], res.coordinate(f"{name}.y")[k]
            vx, vy = res.velocity(f"{name}.x")[k], res.velocity(f"{name}.y")[k]
            p += mass * np.array([vx, vy])
            h += mass * (x * vy - y * vx) + inertia * res.velocity(f"{name}.theta")[k]
        return p, h

    (p0, h0), (p1, h1) = momenta(0), momenta(1)
    assert np.max(np.abs(p1 - p0)) < 1e-9 and abs(h1 - h0) < 1e-9
    assert res.sensors.energies()["springs"][-1] > 0.0


def test_bad_input_is_named():
    s = Scene()
    s.point_mass("m", mass=1.0)
    with pytest.raises(ukflex.ExpressionError, match="unknown state quantity 'm.z'") as e:
        s.point_load(s["m"].point(), fx="2 * m.z")
    assert e.value.position == 4
    with pytest.raises(ukflex.InvalidSceneError, match="unknown state quantity 'w'"):
        s.point_load(s["m"].point(), fx=LoadTable(of="w", x=[0, 1], y=[0, 1]))
    with pytest.raises(ukflex.InvalidSceneError, match="period"):
        s.point_load(s["m"].point(), fx=LoadTable(of="t", x=[0, 2], y=[0, 1], period=1.0))
    with pytest.raises(ukflex.InvalidSceneError, match="increase"):
        s.point_load(s["m"].point(), fx=LoadTable(of="t", x=[0, 0], y=[0, 1]))
    with pytest.raises(ukflex.InvalidSceneError, match="table .*missing field 'y'"):
        s.point_load(s["m"].point(), fx={"of": "t", "x": [0, 1]})
    with pytest.raises(ukflex.InvalidSceneError, match="expected a number, an expression string, a table"):
        s.point_load(s["m"].point(), fx=[1.0, 2.0])
    w = s.rigid_body("w", mass=1.0, inertia=0.1)
    with pytest.raises(ukflex.InvalidSceneError, match="damping"):
        s.rotational_spring_damper(w.frame(), damping=-1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="rotor_inertia"):
        s.motor(w.frame(), 1.0, rotor_inertia=-1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="no orientation"):
        s.motor(s["m"].point(), 1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="stiffness"):
        s.bushing(w.frame(), s.ground.point(0, 0), stiffness=(1.0, -1.0, 0.0))
    # a load whose value is undefined stops the run there (status -1, saying why), not NaN
    s2 = Scene()
    s2.point_mass("m", mass=1.0)
    s2.point_load(s2["m"].point(), fx="log(1 - t)")
    res = ukflex.simulate(s2.build(), 2.0, method="DOPRI5")
    assert res.status == -1 and "non-finite" in res.message and res.t[-1] < 1.0
    assert np.all(np.isfinite(res.coordinate("m.x")))
    with pytest.raises(ukflex.NonFiniteError):
        s2.build().rhs(1.5, np.zeros(4))


def test_point_quantities_of_a_beam_read_the_slider_of_the_paper_scene():
    # x(coupler, 1), d:x(coupler, 1): the slider's position and speed, as the outputs spell them
    from ukflex import scenes

    def scene(fx):
        s = scenes.slider_crank()
        s.point_load(s["coupler"].at(1.0), fx=fx)
        return s.build(correct=False)

    a = scene("-100 * x(coupler, 1) - 3 * d:x(coupler, 1)")
    zero = scene(0.0)
    rng = np.random.default_rng(1)
    q, qd = a.q0 + 1e-3 * rng.standard_normal(a.n_coords), rng.standard_normal(a.n_coords)
    h = 1e-6
    x = a.core.beam_point("coupler", 1.0, q)[0]
    v = (a.core.beam_point("coupler", 1.0, q + h * qd)[0] - a.core.beam_point("coupler", 1.0, q - h * qd)[0]) / (2 * h)
    f = -100 * x - 3 * v
    const = scenes.slider_crank()
    const.point_force(const["coupler"].at(1.0), (f, 0.0))
    b = const.build(correct=False)
    got = a.core.Q(0.0, q, qd) - zero.core.Q(0.0, q, qd)
    want = b.core.Q(0.0, q, qd) - zero.core.Q(0.0, q, qd)
    assert np.max(np.abs(got - want)) < 1e-7 * np.max(np.abs(want))


def test_python_callable_load_matches_the_expression():
    calls = []

    def forcing(t, state):
        calls.append(state)
        return F0 * math.sin(W * t) - K * (state["m.x"] - 1) - C * state["d:m.x"]

    s = Scene()
    s.point_mass("m", mass=M, position=(1.0, 0.0))
    s.point_load(s["m"].point(), fx=forcing, inputs=["m.x", "d:m.x"])
    assert s.to_dict()["forces"][0]["fx"] == {"callable": "callable0", "inputs": ["m.x", "d:m.x"]}
    t = np.linspace(0.0, 2.0, 21)
    res = ukflex.simulate(s.build(), 2.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    ref = ukflex.simulate(_oscillator(True), 2.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    assert np.max(np.abs(res.coordinate("m.x") - ref.coordinate("m.x"))) < 1e-12
    assert calls and set(calls[-1]) == {"m.x", "d:m.x"}


def test_python_callable_errors_are_raised_by_name():
    def build(f):
        s = Scene()
        s.point_mass("m", mass=1.0)
        s.point_load(s["m"].point(), fx=f, inputs=["m.x"])
        return s.build()

    class Boom(Exception):
        pass

    def boom(t, state):
        if t > 0.1:
            raise Boom("no")
        return 1.0

    with pytest.raises(Boom):
        ukflex.simulate(build(boom), 1.0, method="DOPRI5")
    with pytest.raises(ukflex.NonFiniteError, match="callable0' returned NaN"):
        ukflex.simulate(build(lambda t, s: float("nan") if t > 0.1 else 0.0), 1.0, method="DOPRI5")
    with pytest.raises(ukflex.NonFiniteError, match="returned inf at t = 1"):
        build(lambda t, s: float("inf") if t > 0.5 else 0.0).rhs(1.0, np.zeros(4))
    # at the initial guess the build says so
    with pytest.raises(ukflex.InvalidSceneError, match="returned inf at t = 0"):
        build(lambda t, s: float("inf"))
    # a description naming a callable the System was not given
    s = Scene()
    s.point_mass("m", mass=1.0)
    s.point_load(s["m"].point(), fx=lambda t, st: 0.0)
    with pytest.raises(ukflex.InvalidSceneError, match="callable0' was not given"):
        ukflex.System(s.to_dict())
    with pytest.raises(ukflex.InvalidSceneError, match="unknown state quantity 'm.q'"):
        s.point_load(s["m"].point(), fx=lambda t, st: 0.0, inputs=["m.q"])


def test_scene_files_take_the_new_kinds():
    from ukflex.model.scenefile import loads

    text = """
[[bodies]]
name = "wheel"
kind = "rigid"
mass = 3.0
inertia = 0.02

[[joints]]
kind = "revolute"
a = { body = "wheel", point = [0.0, 0.0] }
b = { body = "ground", point = [0.0, 0.0] }

[[forces]]
kind = "motor"
a = { body = "wheel" }
torque = "0.05 * (12 - 0.05 * w) / 0.8"
rotor_inertia = 0.004

[[forces]]
kind = "torque_load"
frame = { body = "wheel" }
torque = { of = "wheel.theta", x = [0.0, 6.283185307179586], y = [0.0, 0.0], period = 6.283185307179586 }

[[forces]]
kind = "rotational_spring_damper"
a = { body = "wheel" }
stiffness = 0.0
damping = 0.001
"""
    system = loads(text).scene.build()
    assert [f["kind"] for f in system.description["forces"]] == ["motor", "torque_load", "rotational_spring_damper"]
    # the DC motor against a hinge damper: w_inf = k V / (k^2 + c R)
    res = ukflex.simulate(system, 120.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=[120.0])
    assert res.velocity("wheel.theta")[-1] == pytest.approx(0.05 * 12 / (0.05**2 + 0.001 * 0.8), rel=1e-6)


def test_elastic_elements_forces_are_their_potentials_gradients():
    # Q = -dV/dq for the undamped bushing (its moment term included) and rotational spring, on
    # two rigid bodies and a beam marker, at a state away from the rest one
    s = Scene()
    a = s.rigid_body("a", mass=1.0, inertia=0.1, angle=0.2)
    b = s.rigid_body("b", mass=2.0, inertia=0.2, position=(0.5, 0.2), angle=-0.3)
    s.bushing(a.point(0.2, 0.1, angle=0.1), b.point(-0.1, -0.05, angle=0.4), stiffness=(50.0, 80.0, 2.0))
    s.rotational_spring_damper(a.frame(), b.frame(), stiffness=3.0)
    system = s.build()
    rng = np.random.default_rng(3)
    q = system.q0 + 0.1 * rng.standard_normal(system.n_coords)
    zero = np.zeros(system.n_coords)
    Q = system.core.Q(0.0, q, zero)
    h = 1e-6
    grad = np.array([(system.core.potential_energy(q + h * e) - system.core.potential_energy(q - h * e)) / (2 * h)
                     for e in np.eye(system.n_coords)])
    assert np.max(np.abs(Q + grad)) < 1e-7 * np.max(np.abs(Q))
    assert np.max(np.abs(Q)) > 1.0


def _tip_cantilever(fy, elements=8):
    """A clamped Euler-Bernoulli FFRF cantilever (1 m steel strip 20 x 10 mm) with a tip load
    ``fy`` (an expression of its tip deflection: a spring, a damper)."""
    s = Scene()
    b = s.beam("bar", length=1.0, section={"rectangular": {"width": 0.02, "height": 0.01}}, density=7800.0,
               youngs_modulus=2e11, elements=elements, theory="euler-bernoulli", strain="linear", frame="clamped",
               rotary_inertia=False)
    s.weld(s.ground.frame(), b.at(0.0), name="clamp")
    s.point_load(b.at(1.0), fx=0.0, fy=fy)
    return s.build()


@pytest.mark.parametrize("kappa", [3.0, 30.0])
def test_tip_deflection_spring_raises_the_first_frequency_as_the_closed_form(kappa):
    # cantilever with a tip spring k: (bL)^3 (1 + cos bL cosh bL) + kappa (sin bL cosh bL -
    # cos bL sinh bL) = 0, kappa = k L^3 / EI (kappa -> inf: clamped-pinned, bL = 3.9266)
    from scipy.optimize import brentq

    EI, rhoA, L = 2e11 * 0.02 * 0.01**3 / 12, 7800.0 * 0.02 * 0.01, 1.0
    f = lambda b: b**3 * (1 + math.cos(b) * math.cosh(b)) + kappa * (math.sin(b) * math.cosh(b) - math.cos(b) * math.sinh(b))
    bl = brentq(f, 1.0, 3.9)
    closed = bl**2 * math.sqrt(EI / (rhoA * L**4))
    free = math.sqrt(EI / (rhoA * L**4)) * 1.8751**2
    omega = np.sort(_tip_cantilever(f"-{kappa * EI / L**3!r} * v(bar, 1)").frequencies())[0]
    assert closed > 1.3 * free
    assert abs(omega / closed - 1) < 1e-4, (omega, closed)


def test_velocity_feedback_on_the_tip_deflection_damps_the_first_mode_as_the_closed_form():
    # fy = -c d:v(bar, 1): single-mode model of the cantilever's first mode (phi(L) = 2 for
    # int phi^2 dx = L): sigma = c phi(L)^2 / (2 rho A L) = 2 c / (rho A L), at light damping
    # (zeta = 1 %); the eigenvalue of the linearized motion (System.jac) nearest i w_1
    EI, rhoA, L, c = 2e11 * 0.02 * 0.01**3 / 12, 7800.0 * 0.02 * 0.01, 1.0, 0.4
    system = _tip_cantilever(f"-{c!r} * d:v(bar, 1)")
    ev = np.linalg.eigvals(np.asarray(system.jac(0.0, system.y0)))
    w1 = 1.8751041**2 * math.sqrt(EI / (rhoA * L**4))
    lam = ev[np.argmin(np.abs(ev.imag - w1))]
    sigma = 2 * c / (rhoA * L)
    assert abs(lam.imag / w1 - 1) < 1e-4 and abs(-lam.real / sigma - 1) < 1e-3, (lam, sigma)


def test_beam_deflection_input_of_the_paper_scene_runs_and_is_the_output():
    # the example: a force on the slider that reads the coupler's midpoint deflection
    from ukflex import scenes

    def scene(fx):
        s = scenes.slider_crank()
        s.point_load(s["coupler"].at(1.0), fx=fx)
        return s

    a = scene("-(2000 * (1 + cos(crank.theta))^2 + 1e6 * v(coupler, 0.5) + 1e3 * d:psi(coupler, 1))").build(correct=False)
    zero = scene(0.0).build(correct=False)
    rng = np.random.default_rng(2)
    q, qd = a.q0 + 1e-3 * rng.standard_normal(a.n_coords), rng.standard_normal(a.n_coords)
    h = 1e-6
    v = a.core.beam_point("coupler", 0.5, q)[3]
    psid = (a.core.beam_point("coupler", 1.0, q + h * qd)[4] - a.core.beam_point("coupler", 1.0, q - h * qd)[4]) / (2 * h)
    f = -(2000 * (1 + math.cos(q[a.coordinate_names.index("crank.theta")])) ** 2 + 1e6 * v + 1e3 * psid)
    const = scenes.slider_crank()
    const.point_force(const["coupler"].at(1.0), (f, 0.0))
    want = const.build(correct=False).core.Q(0.0, q, qd) - zero.core.Q(0.0, q, qd)
    got = a.core.Q(0.0, q, qd) - zero.core.Q(0.0, q, qd)
    assert abs(v) > 1e-5 and np.max(np.abs(got - want)) < 1e-7 * np.max(np.abs(want))
    res = ukflex.simulate(scene("-2000 * (1 + cos(crank.theta))^2 - 1e5 * v(coupler, 0.5)").build(), 0.02, method="RADAU5M")
    assert res.success and np.all(np.isfinite(res.q))


def test_beam_quantity_inputs_bad_input_is_named():
    from ukflex import scenes

    s = scenes.slider_crank()
    p = s["coupler"].at(1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="unknown body 'rod'"):
        s.point_load(p, fx="v(rod, 0.5)")
    with pytest.raises(ukflex.ExpressionError, match=r"XI must be a number in \[0, 1\]") as e:
        s.point_load(p, fx="2 * v(coupler, 1.5)")
    assert e.value.position == 4
    with pytest.raises(ukflex.ExpressionError, match="body 'crank' \\(rigid\\) has no beam axis"):
        s.point_load(p, fx="v(crank, 0.5)")
    with pytest.raises(ukflex.ExpressionError, match="algebraic loop.*joint_friction"):
        s.point_load(p, fx="0.1 * reaction(slider).fx")
