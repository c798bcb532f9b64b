"""Regularized Coulomb and viscous friction in revolute and prismatic joints, closed with the
reactions (docs/loads.md, "Joint friction"), against closed forms and an independent NumPy
solution of the coupled equations."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import ukflex
from ukflex import Scene

G = 9.81
V_EPS = 1e-3  # the core's default, read back from the description below


def _incline(theta, mu, v0=0.0):
    """A block on a prismatic joint along an incline of angle theta (axis pointing down it)."""
    s = Scene(gravity=(0.0, -G))
    d = (math.cos(theta), -math.sin(theta))
    blk = s.rigid_body("blk", mass=2.0, inertia=0.1, velocity=(v0 * d[0], v0 * d[1]))
    s.prismatic(blk.frame(), s.ground.frame(angle=-theta), name="slide")
    s.joint_friction("slide", mu=mu, name="friction")
    return s


def _speed_down(res, theta):
    return res.velocity("blk.x") * math.cos(theta) - res.velocity("blk.y") * math.sin(theta)


@pytest.mark.parametrize("ratio", [0.5, 0.99, 1.01, 2.0])
def test_block_on_an_incline_sticks_below_and_slides_above_the_threshold(ratio):
    # tan(theta) = ratio mu: the prismatic joint's reaction is the normal force m g cos(theta)
    mu = 0.4
    theta = math.atan(ratio * mu)
    s = _incline(theta, mu)
    assert s.to_dict()["forces"][0]["v_eps"] == V_EPS
    t = np.linspace(0.0, 0.5, 11)
    res = ukflex.simulate(s.build(), t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    v = _speed_down(res, theta)
    # below v_eps the force is the ramp mu N v / v_eps: v(t) = v_inf (1 - exp(-t / tau)),
    # v_inf = v_eps tan(theta) / mu, tau = v_eps / (mu g cos(theta))
    v_inf, tau = V_EPS * ratio, V_EPS / (mu * G * math.cos(theta))
    if ratio < 1.0:
        # sticks: creeps at v_inf < v_eps (the regularization's bound), from t = 0.05 on
        assert np.all(np.abs(v) <= V_EPS)
        np.testing.assert_allclose(v[1:], v_inf, rtol=1e-7)
    else:
        # slides: Coulomb exactly once v > v_eps, reached at t1 = -tau ln(1 - v_eps / v_inf)
        a = G * (math.sin(theta) - mu * math.cos(theta))
        t1 = -tau * math.log(1.0 - 1.0 / ratio)
        np.testing.assert_allclose(v[1:], V_EPS + a * (t[1:] - t1), rtol=1e-7)
        assert a > 0.0 and v[-1] > 10 * V_EPS


def test_slider_length_carries_the_reaction_moment():
    # a block sliding on a horizontal guide, pushed by P at the height h above its axis: the
    # guide's normal force is m g, its moment P h; a slider of length L carried at its ends
    # presses with N_eff = max(m g, 2 P h / L)
    m, P, h, mu = 2.0, 30.0, 0.1, 0.3

    def accel(**kw):
        s = Scene(gravity=(0.0, -G))
        blk = s.rigid_body("blk", mass=m, inertia=0.1, velocity=(0.5, 0.0))
        s.prismatic(blk.frame(), s.ground.frame(), name="slide")
        s.point_force(blk.point(0.0, h), (P, 0.0))
        s.joint_friction("slide", mu=mu, **kw)
        system = s.build()
        y = np.concatenate([system.q0, system.qd0])
        return system.rhs(0.0, y)[len(system.q0) + system.coordinate_index("blk.x")]

    assert accel() == pytest.approx((P - mu * m * G) / m, rel=1e-12)
    assert accel(length=0.5) == pytest.approx((P - mu * m * G) / m, rel=1e-12)  # 2 P h / L = 12 < m g
    assert accel(length=0.1) == pytest.approx((P - mu * 2 * P * h / 0.1) / m, rel=1e-12)  # 60 > m g


# The pendulum with a friction pin: rod of mass m, length L, pinned at its end; phi the rod's
# angle from the x axis. The pin's reaction R = m a_c - m g depends on the angular
# acceleration, which depends on the friction torque -mu r |R| sat(w / v_eps) - c w.
M_ROD, L_ROD, MU, R_PIN, C_VISC = 1.0, 0.4, 0.5, 0.05, 0.002
J_O = M_ROD * L_ROD**2 / 3


def _pendulum(phi0=0.0, w0=0.0, mu=MU, radius=R_PIN, damping=C_VISC):
    s = Scene(gravity=(0.0, -G))
    rod = s.rigid_body("rod", mass=M_ROD, inertia=M_ROD * L_ROD**2 / 12, com=(L_ROD / 2, 0.0), angle=phi0, angular_velocity=w0)
    s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="pin")
    s.joint_friction("pin", mu=mu, radius=radius, damping=damping, name="pin_friction")
    return s


def _reaction(phi, w, alpha):
    """|R| on the rod at the pin for the angular acceleration alpha."""
    l = L_ROD / 2
    ax = l * (-math.sin(phi) * alpha - math.cos(phi) * w * w)
    ay = l * (math.cos(phi) * alpha - math.sin(phi) * w * w)
    return math.hypot(M_ROD * ax, M_ROD * ay + M_ROD * G)


def _alpha(phi, w, closed=True, radius=R_PIN):
    """The angular acceleration from J_O alpha = -m g l cos(phi) + T(|R(alpha)|), solved for
    alpha (closed) or with |R| of the frictionless alpha (a single pass); ``radius`` the pin's."""
    s = max(-1.0, min(1.0, w / V_EPS))
    gravity = -M_ROD * G * L_ROD / 2 * math.cos(phi)

    def torque(alpha):
        return -MU * radius * _reaction(phi, w, alpha) * s - C_VISC * w

    if not closed:
        return (gravity + torque(gravity / J_O)) / J_O
    f = lambda a: J_O * a - gravity - torque(a)  # noqa: E731
    a0 = gravity / J_O
    return brentq(f, a0 - 100.0, a0 + 100.0, xtol=1e-14, rtol=1e-15)


@pytest.mark.parametrize("phi,w", [(0.0, 3.0), (-0.7, -5.0), (-2.0, 0.0004), (1.0, 8.0)])
def test_pin_friction_closes_the_reaction_loop_at_a_state(phi, w):
    system = _pendulum(phi, w).build()
    y = np.concatenate([system.q0, system.qd0])
    i = len(system.q0) + system.coordinate_index("rod.theta")
    alpha = system.rhs(0.0, y)[i]
    exact, single = _alpha(phi, w), _alpha(phi, w, closed=False)
    assert alpha == pytest.approx(exact, rel=1e-11, abs=1e-11)
    # a single pass (friction from the reaction without friction) is measurably wrong
    assert abs(single - exact) > 1e-6 * abs(exact) + 1e-4


def _pendulum_reference(t, w0=0.0, radius=R_PIN):
    sol = solve_ivp(lambda _, y: [y[1], _alpha(y[0], y[1], radius=radius)], (0.0, t[-1]), [0.0, w0], method="DOP853",
                    rtol=1e-12, atol=1e-13, t_eval=t)
    return sol.y[0]


@pytest.mark.parametrize("method,opts", [("DOPRI5", {}), ("DOPRI5", {"projection_tol": 1e-13}), ("RADAU5", {}),
                                         ("RADAU5M", {}), ("Radau", {}), ("LSODA", {})])
def test_pendulum_with_pin_friction_follows_the_coupled_equations_with_every_method(method, opts):
    # released horizontal: swings down to the bottom and up the other side with friction (and
    # with DOPRI5's projections after the steps that drift)
    t = np.linspace(0.0, 0.6, 13)
    res = ukflex.simulate(_pendulum().build(), t[-1], method=method, t_eval=t, rtol=1e-9, atol=1e-11, **opts)
    np.testing.assert_allclose(res.coordinate("rod.theta"), _pendulum_reference(t), atol=1e-6)


def test_pendulum_with_pin_friction_converges_with_genalpha():
    # released from rest: the joint sticks for ~3e-5 s, then the friction torque sets in at
    # once (the ramp is v_eps = 1e-3 rad/s wide): a jump of the acceleration within a step,
    # which generalized-alpha integrates at first order (its acceleration-like variable
    # carries the jump; docs/loads.md): measured 9.4e-6 at h = 1e-4, 2.9e-6 at 5e-5, 1.5e-6
    # at 2e-5 (7.5e-8, 1.9e-8, 3e-9 without friction)
    t = np.linspace(0.0, 0.6, 13)
    ref = _pendulum_reference(t)
    err = []
    for h in (1e-4, 2e-5):
        res = ukflex.simulate(_pendulum().build(), t[-1], method="GENALPHA", t_eval=t, step=h, rtol=1e-12, atol=1e-14)
        err.append(np.max(np.abs(res.coordinate("rod.theta") - ref)))
    assert err[0] < 1.5e-5 and err[1] < 2e-6 and err[1] < err[0] / 4


def test_genalpha_newton_matrix_holds_the_friction_of_the_multipliers():
    """A pin of radius 0.2 m (mu r = 0.1, ten times the pendulum's above) swinging from 3 rad/s
    until it sticks: the friction's dependence on the reaction, -dQ_f/dlambda, is in GENALPHA's
    Newton matrix (the top-right block A^T - dQ_f/dlambda), so its Newton iteration converges
    and the error falls at second order (measured 1.5e-5, 3.7e-6, 7.6e-7 at h = 2e-3, 1e-3,
    5e-4). Without the block the simplified Newton iteration diverges here: the run at
    h = 2e-3 fails, and the others halve their steps hundreds of thousands of times with
    errors of 1e-6 to 5e-6 that do not fall with h."""
    t = np.linspace(0.0, 0.3, 7)
    ref = _pendulum_reference(t, w0=-3.0, radius=0.2)
    err = []
    for h in (2e-3, 1e-3, 5e-4):
        res = ukflex.simulate(_pendulum(w0=-3.0, radius=0.2).build(), t[-1], method="GENALPHA", t_eval=t, step=h,
                              rtol=1e-10, atol=1e-12)
        assert res.status == 0 and res.extra["nreject"] == 0
        err.append(np.max(np.abs(res.coordinate("rod.theta") - ref)))
    assert err[0] < 3e-5 and err[1] < err[0] / 3.5 and err[2] < err[1] / 3.5, err
    # the band LU's form of the same matrices (`sparse_newton::fill_multiplier_terms`), with
    # RADAU5M too
    for method, opts in (("GENALPHA", dict(step=1e-3)), ("RADAU5M", {})):
        a, b = (ukflex.simulate(_pendulum(w0=-3.0, radius=0.2).build(), t[-1], method=method, t_eval=t, rtol=1e-10,
                                atol=1e-12, linear_solver=ls, **opts) for ls in ("dense", "sparse"))
        np.testing.assert_allclose(b.coordinate("rod.theta"), a.coordinate("rod.theta"), atol=1e-9)
        assert np.max(np.abs(a.coordinate("rod.theta") - ref)) < 1e-5


def test_friction_work_closes_the_energy_balance():
    # the friction power -T w is ~ |w| with a kink where the pendulum turns: the spline
    # quadrature of the sampled power converges as h^2 there (relative error 1.5e-6 with 601
    # samples, 3.7e-7 with 1501, 5.5e-8 with 3001)
    t = np.linspace(0.0, 1.5, 3001)
    res = ukflex.simulate(_pendulum().build(), t[-1], method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t)
    bal = res.sensors.energy_balance()
    # the friction dissipated a sizeable part of the energy, and the balance closes
    assert bal["dissipated"][-1] > 0.05 * M_ROD * G * L_ROD / 2
    assert bal["relative_error"] < 1e-6


def test_projections_do_not_see_the_friction():
    """The projections onto the constraints (after each native step, `System.core.project_step`;
    the full one, `project`) are kinematic, in the mass metric: the same with and without the
    friction element, to the bit, at a drifted, moving state (the closure lives in the
    acceleration calls, not in the UK solve these projections call with the forces zeroed)."""
    a = _pendulum(0.4, 2.0).build()
    s = Scene(gravity=(0.0, -G))
    rod = s.rigid_body("rod", mass=M_ROD, inertia=M_ROD * L_ROD**2 / 12, com=(L_ROD / 2, 0.0), angle=0.4,
                       angular_velocity=2.0)
    s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="pin")
    b = s.build()
    q = np.asarray(a.q0) + np.array([1e-4, -2e-4, 3e-4])
    qd = np.asarray(a.qd0) + np.array([0.01, -0.02, 0.0])
    assert abs(a.qdd(0.0, a.q0, a.qd0)[2] - b.qdd(0.0, b.q0, b.qd0)[2]) > 1e-3  # the friction acts
    for project in (lambda sy: sy.core.project_step(0.0, q, qd, 1e-12, 10)[:2], lambda sy: sy.core.project(0.0, q, qd)[:2]):
        (qa, va), (qb, vb) = project(a), project(b)
        assert np.abs(qa - q).max() > 1e-5  # it moved
        np.testing.assert_array_equal(qa, qb)
        np.testing.assert_array_equal(va, vb)


def test_viscous_part_equals_the_rotational_damper():
    # mu = 0: the joint friction is the hinge's viscous damper (tests/test_loads.py checks its
    # decay rate against the closed form)
    t = np.linspace(0.0, 1.0, 11)
    a = ukflex.simulate(_pendulum(mu=0.0, damping=0.05).build(), 1.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    s = Scene(gravity=(0.0, -G))
    rod = s.rigid_body("rod", mass=M_ROD, inertia=M_ROD * L_ROD**2 / 12, com=(L_ROD / 2, 0.0))
    s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="pin")
    s.rotational_spring_damper(rod.frame(), damping=0.05)
    b = ukflex.simulate(s.build(), 1.0, method="DOPRI5", rtol=1e-11, atol=1e-13, t_eval=t)
    np.testing.assert_allclose(a.coordinate("rod.theta"), b.coordinate("rod.theta"), atol=1e-10)


def test_bad_input_is_named():
    def scene():
        s = Scene()
        rod = s.rigid_body("rod", mass=1.0, inertia=0.1)
        blk = s.rigid_body("blk", mass=1.0, inertia=0.1, position=(1.0, 0.0))
        pm = s.point_mass("pm", mass=1.0, position=(2.0, 0.0))
        s.revolute(rod.point(0, 0), s.ground.point(0, 0), name="pin")
        s.prismatic(blk.frame(), s.ground.frame(), name="slide")
        s.revolute(pm.point(), s.ground.point(2.0, 0.0), name="pm_pin")
        return s

    bad = [
        (dict(joint="pin", mu=-0.1, radius=0.01), "mu must be >= 0"),
        (dict(joint="pin", mu=float("nan"), radius=0.01), "mu must be (>= 0 and )?finite"),
        (dict(joint="pin", mu=0.1, radius=-0.01), "radius must be >= 0"),
        (dict(joint="pin", mu=0.1), "needs the pin radius"),
        (dict(joint="pin", mu=0.1, radius=0.01, v_eps=0.0), "v_eps must be positive"),
        (dict(joint="pin", mu=0.1, radius=0.01, v_eps=-1e-3), "v_eps must be positive"),
        (dict(joint="pin", mu=0.1, radius=0.01, damping=-1.0), "damping must be >= 0"),
        (dict(joint="pin", mu=0.1, radius=0.01, length=0.2), "'pin' is a revolute joint"),
        (dict(joint="slide", mu=0.1, radius=0.01), "'slide' is a prismatic joint"),
        (dict(joint="slide", mu=0.1, length=0.0), "length must be positive"),
        (dict(joint="pm_pin", mu=0.1, radius=0.01), "a point mass has no orientation"),
    ]
    for kw, msg in bad:
        with pytest.raises(ukflex.InvalidSceneError, match=msg):
            scene().joint_friction(**kw)
    s = scene()
    s.distance(s["rod"].point(1.0, 0.0), s["blk"].point(0.5, 0.0), name="link")
    with pytest.raises(ukflex.InvalidSceneError, match="revolute and prismatic joints; 'link' is a distance joint"):
        s.joint_friction("link", mu=0.1)
    with pytest.raises(ukflex.UnknownNameError, match="'hinge'"):
        scene().joint_friction("hinge", mu=0.1, radius=0.01)


def test_scene_files_carry_joint_friction():
    from ukflex.model import scenefile

    scene = _pendulum()
    text = scenefile.dumps(scene, name="friction_pendulum", solver={"t_end": 0.5, "method": "DOPRI5"})
    assert 'kind = "joint_friction"' in text
    sf = scenefile.loads(text, path="friction_pendulum.toml")
    assert sf.scene.to_dict() == scene.to_dict()
    # a plain description dict builds the same System
    a, b = scene.build(), ukflex.System(scene.to_dict())
    y = np.concatenate([a.q0, a.qd0 + 1.0])
    np.testing.assert_array_equal(a.rhs(0.0, y), b.rhs(0.0, y))



def _chain(links, friction, drift=0.0):
    """A chain of ``links`` rigid links (0.1 m) hanging in a row along x from a pin at the
    origin, each pin with friction (``friction``), the guess off the constraints by ``drift``
    and moving."""
    s = Scene(gravity=(0.0, -G))
    rng = np.random.default_rng(3)
    prev = s.ground.point(0, 0)
    for i in range(links):
        dx, dy, da = drift * rng.standard_normal(3)
        link = s.rigid_body(f"l{i}", mass=0.2, inertia=2e-4, com=(0.05, 0.0), position=(0.1 * i + dx, dy), angle=da,
                            velocity=tuple(rng.standard_normal(2)), angular_velocity=float(rng.standard_normal()))
        s.revolute(prev, link.point(0, 0), name=f"pin{i}")
        if friction:
            s.joint_friction(f"pin{i}", mu=0.3, radius=0.01, damping=1e-3)
        prev = link.point(0.1, 0)
    return s


def test_initial_correction_on_the_sparse_path_does_not_see_the_friction():
    """The initial-state correction's minimum-mass-norm steps (`correct::initial::metric_step`)
    take the sparse UK path when no coordinate is held and the workspace has it (the plain UK
    solve with `Q = 0`). A chain of 12 links with friction in every pin (24 constraint rows;
    the sparse path asked for), its guess off by 3 mm and moving: the corrected state with the
    friction elements on the sparse path equals the one on the dense path and the ones without
    friction. (The correction evaluates its mass blocks at zero velocity, where the friction's
    slip rates and forces vanish: a friction closure put into the sparse branch leaves this
    test unchanged, which I checked; it guards the branch with friction elements present, not
    the closure's place.)"""
    systems = {(fr, solver): _chain(12, fr, drift=3e-3).build(uk_solver=solver, hold=None)
               for fr in (True, False) for solver in ("sparse", "dense")}
    ref = systems[(True, "dense")]
    assert ref.initial_correction.iterations > 0 and ref.initial_correction.position_residual_before > 1e-3
    assert ref.initial_correction.velocity_residual_before > 0.1
    for key, sy in systems.items():
        np.testing.assert_allclose(sy.q0, ref.q0, rtol=0, atol=1e-12, err_msg=str(key))
        np.testing.assert_allclose(sy.qd0, ref.qd0, rtol=0, atol=1e-10, err_msg=str(key))
    sp = systems[(True, "sparse")]
    assert sp.core.uk_solver == ("sparse", "sparse") and ref.core.uk_solver[1] == "dense"
    # the friction acts in this scene's dynamics
    y = np.concatenate([sp.q0, sp.qd0])
    plain = systems[(False, "sparse")]
    assert np.abs(sp.rhs(0.0, y) - plain.rhs(0.0, y)).max() > 1e-3
