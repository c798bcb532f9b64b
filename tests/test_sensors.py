"""Sensors (reactions, energies, work, beam internal forces) and the drivers from expressions and
tables (issue 14), checked against closed forms and the augmented (Lagrange multiplier) model."""

import json
import math
import warnings

import numpy as np
import pytest

import ukflex
from ukflex import ExpressionError, InvalidSceneError, Scene, scenes
from ukflex import _core
from ukflex.results.outputs import evaluate, validate
from ukflex.reference import ReferenceModel
from ukflex.reference.uk import augmented_qdd, correct_initial_state


def motion(m, t):
    return np.asarray(_core.motion_values(json.dumps(m.to_dict()), np.asarray(t, dtype=float)))


# ---------------------------------------------------------------------------------- drivers
def test_expression_derivatives_are_exact():
    """x_b = sqrt(L^2 - y_b^2), y_b = a sin(w t): the closed-form f', f'' and finite differences."""
    L, a, w = 0.5, 0.2, 3.0
    e = ukflex.Expression(f"sqrt({L}^2 - ({a} * sin({w}*t))^2)")
    t = np.linspace(0.0, 2.0, 41)
    f, d1, d2 = motion(e, t)
    y, yd, ydd = a * np.sin(w * t), a * w * np.cos(w * t), -a * w * w * np.sin(w * t)
    x = np.sqrt(L**2 - y**2)
    xd = -y * yd / x
    xdd = -(yd**2 + y * ydd) / x - (y * yd) ** 2 / x**3
    np.testing.assert_allclose(f, x, rtol=1e-15)
    np.testing.assert_allclose(d1, xd, rtol=0, atol=1e-14)
    np.testing.assert_allclose(d2, xdd, rtol=0, atol=1e-13)
    h = 1e-5
    fp, fm = motion(e, t + h), motion(e, t - h)
    np.testing.assert_allclose(d1, (fp[0] - fm[0]) / (2 * h), atol=1e-9)
    np.testing.assert_allclose(d2, (fp[1] - fm[1]) / (2 * h), atol=1e-8)
    # every supported function, against central differences of f and f'
    g = ukflex.Expression("-t^2/2 + 3*tan(t/4) * exp(-t) + log(2+t) - abs(t-1)^3 + tanh(t) * cosh(t) "
                          "- sinh(t/3) + atan(t) + cos(pi*t) ** 2 + 1e-1 * (1+t)^t")
    t = np.linspace(0.23, 1.93, 18)  # not at the kink of abs(t - 1)^3's f'' (t = 1)
    f, d1, d2 = motion(g, t)
    fp, fm = motion(g, t + h), motion(g, t - h)
    np.testing.assert_allclose(d1, (fp[0] - fm[0]) / (2 * h), rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(d2, (fp[1] - fm[1]) / (2 * h), rtol=1e-7, atol=1e-7)


def test_expression_parse_errors_name_the_position():
    with pytest.raises(ExpressionError, match="position 9") as exc:
        motion(ukflex.Expression("2 * sin(t"), [0.0])
    assert exc.value.position == 9 and exc.value.expression == "2 * sin(t"
    s = Scene()
    p = s.point_mass("p", mass=1.0)
    with pytest.raises(InvalidSceneError, match="unknown name 'foo'") as exc:
        s.coordinate_driver(p.point(), "x", "1 + foo(t)", name="dx")
    assert isinstance(exc.value, ExpressionError) and exc.value.position == 4
    for bad, pos in [("", 0), ("t +", 3), ("(t))", 3), ("t t", 2), ("1e+", 1)]:
        with pytest.raises(ExpressionError) as exc:
            s.coordinate_driver(p.point(), "x", bad)
        assert exc.value.position == pos, bad
    with pytest.raises(InvalidSceneError, match="not finite at t = 0"):
        s.coordinate_driver(p.point(), "x", "sqrt(t - 1)")


def test_spline_motion_is_c2_and_exact_for_cubics():
    c = lambda t: 0.3 - t + 0.5 * t**2 + 0.2 * t**3  # noqa: E731
    ts = np.array([0.0, 0.2, 0.5, 1.1, 1.5])
    sp = ukflex.Spline(ts, c(ts), slopes=(-1.0, -1.0 + 1.5 + 0.6 * 1.5**2))
    t = np.linspace(-0.1, 1.6, 35)
    f, d1, d2 = motion(sp, t)
    np.testing.assert_allclose(f, c(t), atol=1e-13)
    np.testing.assert_allclose(d1, -1 + t + 0.6 * t**2, atol=1e-12)
    np.testing.assert_allclose(d2, 1 + 1.2 * t, atol=1e-11)
    nat = motion(ukflex.Spline(ts, np.sin(ts)), [0.0, 0.2 - 1e-12, 0.2 + 1e-12, 1.5])
    assert abs(nat[2, 0]) < 1e-14 and abs(nat[2, -1]) < 1e-14
    np.testing.assert_allclose(nat[:, 1], nat[:, 2], atol=1e-9)  # C2 across a knot
    s = Scene()
    p = s.point_mass("p", mass=1.0)
    with pytest.raises(InvalidSceneError, match="increase strictly"):
        s.coordinate_driver(p.point(), "x", ukflex.Spline([0.0, 1.0, 1.0], [0, 1, 2]))
    with pytest.raises(InvalidSceneError, match="same length"):
        s.coordinate_driver(p.point(), "x", ukflex.Spline([0.0, 1.0], [0.0]))


def _driven_particle(m=0.7, g=9.81, L=0.5, a=0.2, w=3.0):
    s = Scene(gravity=(0.0, -g))
    p = s.point_mass("p", mass=m, position=(L, 0.0))
    s.coordinate_driver(p.point(), "x", f"sqrt({L}^2 - ({a} * sin({w}*t))^2)", name="dx")
    s.coordinate_driver(p.point(), "y", ukflex.Harmonic(amplitude=a, frequency=w), name="dy")
    return s


def test_expression_driver_in_a_run_and_its_reactions_and_power():
    """A particle moved on a circle of radius L by two drivers: the drivers' forces are
    m r'' - m g (Newton), their power F . r', and their work the change of T + V."""
    m, g, L, a, w = 0.7, 9.81, 0.5, 0.2, 3.0
    system = _driven_particle(m, g, L, a, w).build()
    assert system.description["drivers"][0]["motion"]["kind"] == "expression"
    t_eval = np.linspace(0.0, 1.0, 401)
    res = ukflex.simulate(system, 1.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    y = a * np.sin(w * t_eval)
    np.testing.assert_allclose(res.coordinate("p.x"), np.sqrt(L**2 - y**2), atol=1e-9)
    np.testing.assert_allclose(res.coordinate("p.y"), y, atol=1e-9)
    f, d1, d2 = motion(ukflex.Expression(f"sqrt({L}^2 - ({a} * sin({w}*t))^2)"), t_eval)
    rx, ry = res.sensors.reaction("dx"), res.sensors.reaction("dy")
    assert rx["body"] == "p"
    np.testing.assert_allclose(rx["fx"], m * d2, atol=1e-6)
    np.testing.assert_allclose(ry["fy"], m * (-a * w * w * np.sin(w * t_eval)) + m * g, atol=1e-6)
    np.testing.assert_allclose(rx["power"], rx["fx"] * d1, atol=1e-6)
    bal = res.sensors.energy_balance()
    assert bal["relative_error"] < 1e-7
    assert np.max(np.abs(bal["driver_work"])) > 0.1


# ---------------------------------------------------------------------------------- reactions
def test_reactions_match_the_augmented_multipliers_on_the_paper_scene():
    """The paper's slider-crank: reactions from the UK multipliers equal the ones from the
    saddle-point (Lagrange multiplier) solve of the NumPy reference, joint by joint."""
    d = scenes.slider_crank().to_dict()
    system, ref = ukflex.System(d), ReferenceModel(d)
    rng = np.random.default_rng(14)
    names = system.constraint_names
    for t in (0.0, 0.013, 0.041):
        q0, qd0 = system.q0.copy(), system.qd0.copy()
        q0[3:] += 1e-4 * rng.standard_normal(q0.size - 3)
        q, qd = correct_initial_state(ref, q0, qd0 + 0.1 * rng.standard_normal(qd0.size), t0=t)
        M, Q, A, b = ref.terms(t, q, qd)
        _, lam = augmented_qdd(M, Q, A, b)
        raw = system.core.sensors(np.array([t]), q[None, :], qd[None, :])
        r = dict(zip(raw["reaction_names"], np.asarray(raw["reactions"])[0]))
        lam_of = {n: lam[i] for i, n in enumerate(names)}
        for joint in ("crank_pivot", "crank_coupler"):  # revolute: -lambda on marker a
            np.testing.assert_allclose(r[joint][:2], [-lam_of[joint + ".x"], -lam_of[joint + ".y"]],
                                       rtol=1e-9, atol=1e-9 * np.abs(lam).max())
        # slider: -lambda n on the point, n the line's normal (line along the ground's x)
        np.testing.assert_allclose(r["slider"][:2], [0.0, -lam_of["slider"]], atol=1e-9 * np.abs(lam).max())
        np.testing.assert_allclose(r["slider"][4], -lam_of["slider"], atol=1e-9 * np.abs(lam).max())
        # the driver's torque and its power -lambda f'
        np.testing.assert_allclose(r["crank_speed"][2], -lam_of["crank_speed"], rtol=1e-9)
        np.testing.assert_allclose(r["crank_speed"][5], -lam_of["crank_speed"] * 124.8, rtol=1e-8)
        # joints do no work
        assert abs(r["crank_pivot"][5]) < 1e-9 * abs(r["crank_speed"][5])


def test_pendulum_pivot_reaction_is_newtons_law():
    """Rigid rod pendulum released at an angle with a speed: the force on the rod at the pivot is
    m a_c - m g; the pivot's first marker is the ground, so the reported force is its opposite."""
    m, L, g, th, om = 1.3, 0.9, 9.81, -0.6, 2.0
    system = scenes.pendulum(length=L, mass=m, angle=th, angular_velocity=om).build()
    h, J = L / 2, m * L**2 / 3
    alpha = -m * g * h * math.cos(th) / J
    ac = h * alpha * np.array([-math.sin(th), math.cos(th)]) - h * om**2 * np.array([math.cos(th), math.sin(th)])
    res = ukflex.simulate(system, 1e-9, method="DOPRI5", rtol=1e-12, t_eval=[0.0])
    r = res.sensors.reaction("pivot")
    assert r["body"] is None
    np.testing.assert_allclose(-np.array([r["fx"][0], r["fy"][0]]), m * ac - m * np.array([0.0, -g]), rtol=1e-10)
    # in the joint frame (marker a: the ground, angle 0) the components are the same
    np.testing.assert_allclose([r["fx_local"][0], r["fy_local"][0]], [r["fx"][0], r["fy"][0]])


# ---------------------------------------------------------------------------------- energy
def test_slider_crank_energy_balance_closes_with_the_driver_work():
    """DOPRI5 at rtol 1e-10: T + V grows by exactly what the crank driver puts in; the default
    run (method auto: RADAU5M, L-stable) shows the damped axial mode in the residual."""
    system = scenes.slider_crank().build()
    t_eval = np.linspace(0.0, 0.07, 7001)  # the powers are integrated over these samples: O(h^4)
    res = ukflex.simulate(system, 0.07, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    bal = res.sensors.energy_balance()
    assert bal["change"][-1] > 1.0                       # the driver does work ...
    assert bal["relative_error"] < 2e-7                   # ... and the balance closes with it
    assert np.all(bal["dissipated"] == 0.0) and np.all(bal["external_work"] == 0.0)
    line = ukflex.results.sensors.energy_line(res)
    assert "driver work +1.789e+00" in line and "balance closes" in line
    ga = ukflex.simulate(system, 0.07, method="auto", t_eval=t_eval)
    gbal = ga.sensors.energy_balance()
    # the default damps the unresolved high modes: the residual is an energy loss, far above DOPRI5's
    assert gbal["residual"][-1] < 0 and abs(gbal["residual"][-1]) > 100 * np.max(np.abs(bal["residual"]))
    assert "integrator lost energy" in ga.sensors.energy_line()


def test_generalized_alpha_balance_residual_is_the_unresolved_axial_mode_not_the_output_sampling():
    """Under GENALPHA at h = 1.36e-4 (the former default, omega_max h ~ 4) the balance misses ~2 J
    of driver work. It is not the cubic-Hermite outputs: the sensors at the step ends (no t_eval)
    give the same residual as at 7001 interpolated outputs. It is the 29 krad/s axial mode the step
    does not resolve: the crank's reaction torque at the step ends carries it aliased (mean driver
    power ~2x DOPRI5's), with rho_inf = 1 (no numerical dissipation) as well; at h = 2e-5
    (omega_max h ~ 0.6) the same method closes the balance to 0.5 % of the driver work. The
    default (RADAU5M, h = 3.1e-4, L-stable) misses 0.04 J at its step ends (2.6 % of the driver
    work) and 0.015 J at 7001 outputs."""
    system = scenes.slider_crank().build()
    ga = dict(method="GENALPHA", step=1.36e-4)
    ends = ukflex.simulate(system, 0.07, **ga).sensors.energy_balance()
    dense = ukflex.simulate(system, 0.07, t_eval=np.linspace(0.0, 0.07, 7001), **ga).sensors.energy_balance()
    assert ends["residual"][-1] < -1.0                     # the default misses about 2 J ...
    assert abs(dense["residual"][-1] - ends["residual"][-1]) < 0.01 * abs(ends["residual"][-1])  # ... either way
    for rho_inf in (1.0, 0.9):
        coarse = ukflex.simulate(system, 0.07, method="GENALPHA", step=1.36e-4, rho_inf=rho_inf).sensors.energy_balance()
        assert coarse["residual"][-1] < -1.0
        fine = ukflex.simulate(system, 0.07, method="GENALPHA", step=2e-5, rho_inf=rho_inf).sensors.energy_balance()
        assert abs(fine["residual"][-1]) < 5e-3 * fine["driver_work"][-1], (rho_inf, fine["residual"][-1])
    default = ukflex.simulate(system, 0.07).sensors.energy_balance()
    assert abs(default["residual"][-1]) < 0.05 * default["driver_work"][-1]


def test_damping_is_measured_as_dissipation():
    """Spring-damper on the slider and a damped coupler: what damping removes closes the balance."""
    system = scenes.slider_crank(damping=1e-4).build()
    t_eval = np.linspace(0.0, 0.03, 1501)
    res = ukflex.simulate(system, 0.03, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    bal = res.sensors.energy_balance()
    assert bal["dissipated"][-1] > 1e-4 and np.all(np.diff(bal["dissipated"]) > -1e-12)
    assert bal["relative_error"] < 1e-6
    e = res.sensors.energies()
    per_body = sum(res.sensors.body_energies(b)["kinetic"] for b in system.body_names)
    np.testing.assert_allclose(per_body, e["kinetic"])
    np.testing.assert_allclose(e["kinetic"] + e["strain"] + e["gravity"] + e["springs"] + e["loads"], res.energy(),
                               rtol=1e-12)


# ---------------------------------------------------------------------------------- beams
@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_cantilever_internal_forces_match_statics(theory):
    """Tip load P: M(x) = P (L - x), V = P; pulled by H: N = H, eps = H / (E a)."""
    L, P, H = 1.0, -2.0, 3.0e3
    system = scenes.cantilever(length=L, elements=4, theory=theory, gravity=False, tip_force=(H, P),
                               strain="linear").build()
    eq = system.equilibrium()
    xi = np.linspace(0.0, 1.0, 9)
    f = np.asarray(system.core.beam_internal_forces("beam", xi, eq.q))[0]
    info = system.body_info("beam")
    EA = info["youngs_modulus"] * info["area"]
    np.testing.assert_allclose(f[:, 2], P * L * (1 - xi), rtol=0, atol=1e-8 * abs(P) * L)
    np.testing.assert_allclose(f[:, 1], P, rtol=1e-8)
    np.testing.assert_allclose(f[:, 0], H, rtol=1e-8)
    np.testing.assert_allclose(f[:, 3], H / EA, rtol=1e-8)


def _ancf_cantilever(tip, solve=True):
    s = Scene()
    b = s.cable("beam", length=1.0, elements=4, section=ukflex.Rectangular(0.02, 0.01),
               density=7850.0, youngs_modulus=2.1e11)
    s.weld(s.ground.point(0, 0), b.at(0.0), name="clamp")
    s.point_force(b.at(1.0), tip, name="tip")
    system = s.build()
    return system, (system.equilibrium() if solve else None)


def test_ancf_internal_forces_follow_the_strain_measures():
    """A cable placed on a cubic curve r(x) (which its Hermite elements represent exactly):
    eps = |r'| - 1, K = r' x r'' / |r'|^2, N = E A eps, M = E I K, V = -E I K'; and a cable
    pulled by H at its tip: N = H, eps = H / (E A) in equilibrium."""
    system, _ = _ancf_cantilever((50.0, 0.0), solve=False)
    info = system.body_info("beam")
    EA, EI = info["youngs_modulus"] * info["area"], info["youngs_modulus"] * info["second_moment"]
    a, b, c = 1.001, 0.02, -0.03  # r(x) = (a x, b x^2 + c x^3)
    r = lambda x: np.array([a * x, b * x**2 + c * x**3])  # noqa: E731
    r1 = lambda x: np.array([a, 2 * b * x + 3 * c * x**2])  # noqa: E731
    q = np.concatenate([np.r_[r(x), r1(x)] for x in np.linspace(0.0, 1.0, 5)])
    xi = np.linspace(0.0, 1.0, 13)
    f = np.asarray(system.core.beam_internal_forces("beam", xi, q))[0]
    y1, y2, y3 = 2 * b * xi + 3 * c * xi**2, 2 * b + 6 * c * xi, 6 * c
    g = a**2 + y1**2
    K = a * y2 / g
    dK = a * y3 / g - 2 * K * (y1 * y2) / g
    eps = np.sqrt(g) - 1
    np.testing.assert_allclose(f[:, 3], eps, rtol=1e-10)
    np.testing.assert_allclose(f[:, 4], K, rtol=1e-10)
    np.testing.assert_allclose(f[:, 0], EA * eps, rtol=1e-10)
    np.testing.assert_allclose(f[:, 2], EI * K, rtol=1e-10)
    np.testing.assert_allclose(f[:, 1], -EI * dK, rtol=1e-9)
    system, eq = _ancf_cantilever((50.0, 0.0))
    f = np.asarray(system.core.beam_internal_forces("beam", xi, eq.q))[0]
    np.testing.assert_allclose(f[:, 0], 50.0, rtol=1e-8)
    np.testing.assert_allclose(f[:, 3], 50.0 / EA, rtol=1e-8)
    np.testing.assert_allclose(f[:, 1:3], 0.0, atol=1e-8)


# ---------------------------------------------------------------------------------- outputs
def test_sensor_expressions_in_outputs_and_npz(tmp_path):
    system = scenes.slider_crank().build()
    res = ukflex.simulate(system, 0.005, method="DOPRI5", rtol=1e-8, t_eval=np.linspace(0, 0.005, 51))
    for expr in ("reaction(crank_pivot).fx", "reaction(crank_speed).torque", "work(crank_speed)", "energy.kinetic",
                 "energy(coupler).strain", "work.drivers", "dissipated", "balance", "N(coupler, 0.5)",
                 "M(coupler, 0.25)", "eps(coupler, 0.5)"):
        validate(system, expr)
        label, v = evaluate(res, expr)
        assert v.shape == res.t.shape and np.all(np.isfinite(v)), expr
    np.testing.assert_allclose(evaluate(res, "work(crank_speed)")[1], evaluate(res, "work.drivers")[1])
    for bad, msg in [("reaction(crank_pivot).fz", "reaction columns"), ("M(crank, 0.5)", "not a beam"),
                     ("energy(nobody).kinetic", "unknown body"), ("N(coupler, 2)", r"\[0, 1\]")]:
        with pytest.raises(ValueError, match=msg):
            validate(system, bad)
    path = tmp_path / "s.npz"
    res.sensors.save_npz(str(path))
    with np.load(path) as z:
        assert "reaction(slider).fy" in z.files and z["t"].shape == res.t.shape


def test_spring_damper_keywords():
    s = Scene()
    r = s.rigid_body("r", mass=1.0, inertia=0.1, position=(1.0, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s.spring_damper(s.ground.point(0, 0), r.point(0, 0), stiffness=10.0, damping=0.5, rest_length=2.0, name="k")
    s = Scene()
    r = s.rigid_body("r", mass=1.0, inertia=0.1, position=(1.0, 0.0))
    with pytest.raises(TypeError, match="stiffness"):
        s.spring_damper(s.ground.point(0, 0), r.point(0, 0))
    # the default rest length is the initial distance (recorded in the description)
    s.spring_damper(s.ground.point(0, 0), r.point(0, 0), stiffness=1.0)
    assert s.to_dict()["forces"][-1]["rest_length"] == pytest.approx(1.0)


def test_toml_drivers_from_an_expression_and_a_table():
    from ukflex.model.scenefile import loads

    text = """
gravity = [0.0, -9.81]

[[bodies]]
kind = "point_mass"
name = "p"
mass = 0.5
position = [0.5, 0.0]

[[drivers]]
kind = "coordinate"
name = "dx"
point = { body = "p" }
axis = "x"
motion = "sqrt(0.25 - (0.2 * sin(3*t))^2)"

[[drivers]]
kind = "coordinate"
name = "dy"
point = { body = "p" }
axis = "y"
motion = { kind = "spline", times = [0.0, 0.5, 1.0, 1.5], values = [0.0, 0.1, 0.0, -0.1] }
"""
    sf = loads(text)
    d = sf.scene.to_dict()
    assert d["drivers"][0]["motion"] == {"kind": "expression", "expression": "sqrt(0.25 - (0.2 * sin(3*t))^2)"}
    assert d["drivers"][1]["motion"]["kind"] == "spline"
    res = ukflex.simulate(sf.scene.build(), 1.0, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 1, 11))
    np.testing.assert_allclose(res.coordinate("p.y")[[0, 5, 10]], [0.0, 0.1, 0.0], atol=1e-9)
    with pytest.raises(InvalidSceneError, match="drivers"):
        loads(text.replace("sqrt(0.25", "sqrt(0.25 +* "))


def test_cli_reports_the_driver_work_and_writes_sensor_outputs(tmp_path):
    import csv
    import os
    import subprocess
    import sys

    env = dict(os.environ, MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, "-m", "ukflex", "run", "slider_crank", "--t-end", "0.01", "--method", "DOPRI5",
                        "--rtol", "1e-9", "--out", str(tmp_path), "--no-plot", "--plot", "reaction(crank_speed).torque",
                        "--plot", "M(coupler, 0.5)", "--plot", "work.drivers"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert "energy T + V: 6.83958231 ->" in r.stdout and "driver work +" in r.stdout and "balance" in r.stdout
    with open(tmp_path / "slider_crank_outputs.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", "reaction(crank_speed).torque", "M(coupler, 0.5)", "work.drivers"]
    assert len(rows) > 3 and all(np.isfinite(float(x)) for x in rows[-1])


def test_reactions_of_weld_prismatic_and_distance_are_the_statics():
    """Each joint kind against Newton at a state from rest: a welded overhanging rod carries its
    weight and moment; a block on a prismatic guide its weight; a particle on a rod released at
    angle th pulls with the tension m g cos(th) (no speed yet)."""
    m, g, h, th, L = 2.0, 9.81, 0.4, 0.5, 0.8
    s = Scene(gravity=(0.0, -g))
    rod = s.rigid_body("rod", mass=m, inertia=0.1, position=(h, 0.0))
    s.weld(rod.point(-h, 0.0), s.ground.point(0.0, 0.0), name="clamp")
    block = s.rigid_body("block", mass=m, inertia=0.1, position=(0.0, 1.0), angle=0.3)
    s.prismatic(block.frame(), s.ground.frame(angle=0.3), name="guide")  # a guide tilted by 0.3 rad
    bob = s.point_mass("bob", mass=m, position=(L * math.sin(th), -1.0 - L * math.cos(th)))
    s.distance(bob.point(), s.ground.point(0.0, -1.0), name="string")
    res = ukflex.simulate(s.build(), 1e-9, method="DOPRI5", rtol=1e-12, t_eval=[0.0])
    sn = res.sensors
    r = {k: {c: v[0] if isinstance(v, np.ndarray) else v for c, v in sn.reaction(k).items()} for k in
         ("clamp", "guide", "string")}
    assert r["clamp"]["body"] == "rod"
    np.testing.assert_allclose([r["clamp"]["fx"], r["clamp"]["fy"], r["clamp"]["torque"]], [0, m * g, m * g * h],
                               atol=1e-9)
    # the block slides freely along the tilted guide: the guide carries the normal part of its
    # weight, in the joint frame (the guide's axis) all in fy_local, and no torque
    np.testing.assert_allclose([r["guide"]["fx_local"], r["guide"]["fy_local"], r["guide"]["torque"]],
                               [0, m * g * math.cos(0.3), 0], atol=1e-9)
    # the string: tension m g cos(th) pulling the bob to the pivot; fx_local = -tension
    np.testing.assert_allclose(r["string"]["fx_local"], -m * g * math.cos(th), rtol=1e-10)
    np.testing.assert_allclose(np.hypot(r["string"]["fx"], r["string"]["fy"]), m * g * math.cos(th), rtol=1e-10)
    for k in r:
        assert abs(r[k]["power"]) < 1e-12
