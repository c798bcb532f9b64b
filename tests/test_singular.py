"""Singular configurations and no success on garbage (docs/integrators.md, "Singular
configurations").

Every run either follows the physical motion through a configuration where the constraint
Jacobian loses rank, or says loudly that it could not: the family below compares each
mechanism with its exact or independent reference.

* The N four-bar mechanism of the MBS benchmark library (A02, ``scenes.n_four_bar``): the exact
  motion is the parallelogram one, one pendulum equation in the crank angle.
* A slider-crank whose crank is as long as its coupler, driven through its dead centres (a
  bifurcation: the slider may stop at the pivot): exact kinematics ``x = 2 L cos(w t)``.
* A parallel-crank lattice (``scenes.lattice(beams="continuous", speed=...)``) whose hangers pass
  the horizontal: an independent reduced-coordinate model (one angle per level) in NumPy.
* A drifting scene (a prescribed motion the mechanism cannot follow): every method ends with
  status -1 naming the drift, never status 0.
"""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ukflex
from ukflex import Scene, SingularConfigurationWarning, scenes, simulate
from ukflex.run.simulate import branch_keeping

T_A02 = 20.0
OUT = np.linspace(0.0, T_A02, 401)  # the benchmark's 400 output steps
G = 9.81


# ----------------------------------------------------------------------------------- A02
def a02_exact(loops: int, t: np.ndarray, angle: float = math.pi / 4, velocity: float = 1.0):
    """B0 (x, y, vx, vy) of the parallelogram motion: every crank at angle th, the couplers
    translating; T = 1/2 ((N+1)/3 + N) th'^2, V = g ((N+1)/2 + N) sin th (unit rods)."""
    J, Gm = (loops + 1) / 3 + loops, G * ((loops + 1) / 2 + loops)
    sol = solve_ivp(lambda _, y: [y[1], -Gm * math.cos(y[0]) / J], (0.0, float(t[-1])),
                    [angle, -velocity / math.sin(angle)], method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    th, om = sol.y
    return np.array([np.cos(th), np.sin(th), -np.sin(th) * om, np.cos(th) * om])


def a02_crossings(loops: int) -> np.ndarray:
    """Times in (0, 20) s where the exact cranks pass the horizontal (sin th = 0)."""
    t = np.linspace(0.0, T_A02, 200001)
    th = np.arctan2(a02_exact(loops, t)[1], a02_exact(loops, t)[0])
    s = np.sin(th)
    k = np.flatnonzero(np.sign(s[1:]) != np.sign(s[:-1]))
    return t[k] - s[k] * (t[k + 1] - t[k]) / (s[k + 1] - s[k])


def b0(system, res) -> np.ndarray:
    sl = system.body_slice("crank0")
    q, qd = res.q[sl], res.qd[sl]
    th, om = q[2], qd[2]
    return np.array([q[0] + np.cos(th), q[1] + np.sin(th), qd[0] - np.sin(th) * om, qd[1] + np.cos(th) * om])


def a02_error(system, res, loops: int) -> float:
    return float(np.abs(b0(system, res) - a02_exact(loops, res.t)).max())


@pytest.mark.parametrize("loops", [1, 2, 10, 40])
def test_a02_default_follows_the_parallelogram_at_high_precision(loops):
    """The default (method="auto", rtol=1e-6) passes the benchmark's high precision, 1e-3 on
    B0's position and velocity at 400 outputs, at every N; it reports every passage (the
    exact motion's crossings), with the mobility gained there, and does not warn."""
    system = scenes.n_four_bar(loops=loops).build()
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularConfigurationWarning)
        res = simulate(system, T_A02, t_eval=OUT)
    assert res.status == 0, res.message
    err = a02_error(system, res, loops)
    assert err < 1e-3, err
    exact = a02_crossings(loops)
    passages = res.extra["singular"]
    assert len(passages) == len(exact), (len(passages), len(exact))
    t_found = np.array([p["t"] for p in passages])
    assert np.abs(t_found - exact).max() < 2e-3, np.abs(t_found - exact).max()
    for p in passages:
        # full rank on both sides; at the passage the mobility jumps from 1 to loops + 1
        assert p["rank_before"] == p["rank_after"] == system.n_constraints
        assert p["rank_before"] - p["rank_at"] == loops, p
        assert p["sigma_ratio"] < 1e-2 * p["sigma_ratio_ref"]


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12])
def test_a02_dopri5_error_falls_with_rtol(rtol):
    """DOPRI5 with its projection keeps the branch at every tolerance: before the filtered error
    estimate, tighter tolerances failed earlier (rtol 1e-9 left the branch at the first
    crossing, rtol 1e-12 collapsed its step size at 1.07 s). The error falls with rtol."""
    system = scenes.n_four_bar(loops=2).build()
    res = simulate(system, T_A02, method="DOPRI5", rtol=rtol, t_eval=OUT)
    assert res.status == 0, res.message
    # the branch: every crank at the same angle, the couplers level (the other branch folds them)
    th = [res.coordinate(f"crank{k}.theta") for k in range(3)]
    assert max(np.abs(th[k] - th[0]).max() for k in (1, 2)) < 1e-8
    assert max(np.abs(res.coordinate(f"coupler{k}.theta")).max() for k in (0, 1)) < 1e-8
    err = a02_error(system, res, 2)
    # measured: 0.69 (rtol 1e-4: the phase error of a loose tolerance over 7 swings; the exact
    # one-degree-of-freedom equation by scipy's RK45 at 1e-4 is as far), 8e-5, 7.2e-6, 8.9e-8;
    # at 1e-12 the passages' floor: the rounding of the right-hand side amplified by
    # 1 / kappa^2 where a step lands near a crossing (1.5e-8 .. 1.9e-6 at N = 2, up to 4e-4 at
    # N = 40, depending on where the steps land; docs/integrators.md); a lost branch gives 1-15
    bound = {1e-4: 2.0, 1e-6: 1e-3, 1e-8: 1e-4, 1e-10: 1e-6, 1e-12: 1e-4}[rtol]
    assert err < bound, err


SCIPY = ["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"]
NATIVE = ["DOPRI5", "RADAU5", "GENALPHA", "RADAU5M"]


@pytest.mark.parametrize("method", NATIVE + SCIPY)
def test_a02_every_method_passes_or_says_so(method):
    """Every method on A02 (N = 2): the branch-keeping ones (native DOPRI5 and scipy's explicit
    Runge-Kutta methods: projection after every step, error estimate filtered near singular
    configurations) pass at high precision without a warning; every other one warns
    (SingularConfigurationWarning) or fails by name -- never a silent status 0 off the branch."""
    system = scenes.n_four_bar(loops=2).build()
    rtol = 1e-8
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = simulate(system, 6.0, method=method, rtol=rtol, t_eval=np.linspace(0.0, 6.0, 121), max_steps=200000)
    warned = any(issubclass(w.category, SingularConfigurationWarning) for w in caught)
    err = a02_error(system, res, 2) if res.t.size else math.inf
    if branch_keeping(method):
        assert res.status == 0 and not warned, res.message
        assert err < 1e-3, err
    else:
        assert warned or res.status == -1, (res.status, err)
        assert res.status != 0 or warned
    assert res.extra["singular"], "the passages are reported for every method"


def test_a02_without_projection_is_not_branch_keeping():
    """DOPRI5 with the projection switched off (projection_tol=0) is an explicit method on the
    UK right-hand side alone: it may leave the branch, and says so."""
    system = scenes.n_four_bar(loops=1).build()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = simulate(system, 4.0, method="DOPRI5", rtol=1e-9, projection_tol=0)
    assert any(issubclass(w.category, SingularConfigurationWarning) for w in caught) or res.status == -1
    assert not branch_keeping("DOPRI5", {"projection_tol": 0})


def test_passages_are_located_by_the_monitor_from_any_trajectory():
    """System.singular_passages finds the same passages in states recorded elsewhere (here the
    exact motion sampled at 0.01 s) as the native run reports."""
    system = scenes.n_four_bar(loops=2).build()
    t = np.linspace(0.0, 4.0, 401)
    res = simulate(system, 4.0, method="DOPRI5", rtol=1e-10, t_eval=t)
    found = system.core.singular_passages(res.t, res.y)
    exact = a02_crossings(2)
    exact = exact[exact < 4.0]
    assert len(found) == len(exact)
    assert np.abs(np.array([p["t"] for p in found]) - exact).max() < 1e-4


# ------------------------------------------------------------------------- dead-centre slider-crank
def equal_slider_crank(omega: float = 4.0, length: float = 0.2) -> Scene:
    """Crank and coupler of the same length: at theta = +-pi/2 the slider sits on the pivot and
    the coupler may also turn with the crank (the slider then stays there): a bifurcation. The
    crank is driven at omega from theta = 0, slider on the X axis."""
    L, m = length, 0.5
    s = Scene(gravity=(0.0, -G))
    crank = s.rigid_body("crank", mass=m, inertia=m * L**2 / 12, com=(L / 2, 0.0), angular_velocity=omega)
    coupler = s.rigid_body("coupler", mass=m, inertia=m * L**2 / 12, com=(L / 2, 0.0), position=(L, 0.0),
                           angular_velocity=-omega, velocity=(0.0, omega * L))
    slider = s.point_mass("slider", mass=2 * m, position=(2 * L, 0.0))
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0))
    s.revolute(crank.point(L, 0.0), coupler.point(0.0, 0.0))
    s.revolute(coupler.point(L, 0.0), slider.point())
    s.point_on_line(slider.point(), s.ground.line((0.0, 0.0), angle=0.0))
    s.angle_driver(crank.frame(), ukflex.ConstantSpeed(omega))
    return s


def test_dead_centre_slider_crank_follows_the_moving_branch():
    """Through four dead centres the slider follows x = 2 L cos(omega t) (the branch where the
    slider moves), not the one where it stays at the pivot; every dead centre is a passage."""
    omega, L = 4.0, 0.2
    system = equal_slider_crank(omega, L).build()
    t = np.linspace(0.0, 3.0, 601)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularConfigurationWarning)
        res = simulate(system, 3.0, t_eval=t)
    assert res.status == 0, res.message
    x = res.coordinate("slider.x")
    assert np.abs(x - 2 * L * np.cos(omega * t)).max() < 1e-6
    dead = (np.arange(4) + 0.5) * math.pi / omega  # theta = pi/2 + k pi
    found = np.array([p["t"] for p in res.extra["singular"]])
    assert found.size == dead.size and np.abs(found - dead).max() < 1e-3


# ------------------------------------------------------------------------------ parallel-crank lattice
def lattice_reference(system, columns: int, rows: int, cell: float, mass: float, t: np.ndarray) -> np.ndarray:
    """Hanger angles a_r (from straight down, counterclockwise) of a continuous-beam lattice, from
    its reduced equations: level r's beam translates by P_r = sum_{k <= r} cell (sin a_k, -cos a_k);
    its columns + 1 hangers turn at a_r' about P_{r-1}. Written from the geometry alone; the
    initial angles and rates are read off the built system."""
    w, h, L = columns, rows, cell
    I_h, m_b = mass * L**2 / 12.0, mass * w
    a0 = np.array([system.q0[system.coordinate_index(f"hanger{r}_0.theta")] + math.pi / 2 for r in range(h)])
    w0 = np.array([system.qd0[system.coordinate_index(f"hanger{r}_0.theta")] for r in range(h)])

    def rhs(_, y):
        a, ad = y[:h], y[h:]
        M = np.zeros((h, h))
        Q = np.zeros(h)
        for r in range(h):
            # bodies of level r: w + 1 hangers (com at P_{r-1} + L/2 e_r) and the beam (at P_r)
            for coef_own, mass_b, count, rot in ((0.5, mass, w + 1, I_h), (1.0, m_b, 1, 0.0)):
                coef = np.zeros(h)
                coef[:r] = 1.0
                coef[r] = coef_own
                J = np.array([coef * L * np.cos(a), coef * L * np.sin(a)])  # d com / d a
                Jd = np.array([-(coef * L * np.sin(a) * ad**2).sum(), (coef * L * np.cos(a) * ad**2).sum()])
                M += count * mass_b * J.T @ J
                if rot:
                    M[r, r] += count * rot
                Q += count * mass_b * (J.T @ np.array([0.0, -G]) - J.T @ Jd)
        return np.concatenate([ad, np.linalg.solve(M, Q)])

    sol = solve_ivp(rhs, (0.0, float(t[-1])), np.concatenate([a0, w0]), method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=t)
    return sol.y[:h]


@pytest.mark.parametrize("rows", [1, 2])
def test_lattice_hangers_pass_the_horizontal_on_their_branch(rows):
    """Continuous beams (redundant rows) at a speed that takes the hangers over the top: every
    passage of the horizontal drops the rank further; the default follows the reduced model.
    (rows = 2 was an expected failure while auto ran DOPRI5 at the user's rtol: a stage met the
    horizontal so exactly that its accelerations left the double range at t = 1.98 s; at
    auto's 0.3 rtol the steps fall elsewhere. The fragility is not gone: docs/robustness.md.)"""
    columns, cell, mass = 3, 0.25, 0.1
    system = scenes.lattice(columns=columns, rows=rows, cell=cell, mass=mass, beams="continuous", speed=12.0).build()
    t = np.linspace(0.0, 2.0, 201)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SingularConfigurationWarning)
        res = simulate(system, 2.0, t_eval=t)
    assert res.status == 0, res.message
    ref = lattice_reference(system, columns, rows, cell, mass, t)
    for r in range(rows):
        a = np.unwrap(res.coordinate(f"hanger{r}_0.theta") + math.pi / 2)
        assert np.abs(a - ref[r]).max() < 1e-4, (r, np.abs(a - ref[r]).max())
        # every hanger of the level has the same angle (the parallel-crank branch)
        for i in range(1, columns + 1):
            assert np.abs(res.coordinate(f"hanger{r}_{i}.theta") - res.coordinate(f"hanger{r}_0.theta")).max() < 1e-6
    passages = res.extra["singular"]
    assert passages, "the hangers pass the horizontal"
    horizontal = np.flatnonzero(np.diff(np.sign(np.cos(ref[rows - 1] if rows == 1 else ref[0]))))
    assert len(passages) >= horizontal.size
    for p in passages:
        assert p["rank_at"] < p["rank_before"] < system.n_constraints  # redundant rows, and fewer at the passage


# ------------------------------------------------------------------------------------- no success on garbage
def impossible_pull() -> Scene:
    """A pendulum (length 1) whose bob is pulled along X to x = 1.5 by t = 1: beyond x = 1 no
    configuration satisfies the constraints, so every run drifts from there on."""
    s = Scene(gravity=(0.0, -G))
    bob = s.rigid_body("rod", mass=1.0, inertia=1.0 / 12, com=(0.5, 0.0), angle=-math.pi / 2)
    s.revolute(s.ground.point(0.0, 0.0), bob.point(0.0, 0.0))
    s.coordinate_driver(bob.point(1.0, 0.0), "x", ukflex.Polynomial([0.0, 0.0, 1.5]))
    return s


@pytest.mark.parametrize("method", NATIVE + SCIPY)
def test_drifting_scene_never_ends_with_status_zero(method):
    """Status 0 requires every accepted step within the drift bound: a run that cannot keep its
    constraints ends with status -1 (the drift, or the failure that comes first, by name) and
    keeps its partial result up to there."""
    system = impossible_pull().build()
    res = simulate(system, 1.0, method=method, rtol=1e-6, max_steps=20000)
    assert res.status == -1, (res.status, res.message)
    assert res.stop is not None and res.stop["cause"] in ("drift", "solver", "min_step", "non_finite", "max_steps"), res.stop
    assert res.t.size > 0 and res.t[-1] < 1.0
    # what it kept is within the bound (x = 1 is reached at t = 1/sqrt(1.5) = 0.816 s)
    assert res.max_residual("position") <= res.extra["drift_limit"]
    assert res.t[-1] < 0.9


@pytest.mark.parametrize("method", ["DOPRI5", "RADAU5", "BDF", "LSODA", "Radau"])
def test_methods_without_projection_stop_when_they_drift(method):
    """A double pendulum under 1000 m/s^2 at rtol 1e-3: without a projection the UK right-hand
    side lets the constraints drift to ||Phi|| = 0.8-21 m (DOPRI5) -- garbage. By default such
    a run stops at the first step beyond the bound; with the projection (the native default)
    DOPRI5 stays within it."""
    system = scenes.double_pendulum(gravity=1000.0).build()
    kw = {"projection_tol": 0} if method in ("DOPRI5", "RADAU5") else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularConfigurationWarning)
        res = simulate(system, 5.0, method=method, rtol=1e-3, **kw)
    if res.status == 0:  # a method that kept its constraints by itself
        assert res.max_residual("position") <= res.extra["drift_limit"]
    else:
        assert res.status == -1 and res.stop["cause"] == "drift", res.message
        assert "drifted" in res.message and res.max_residual("position") <= res.extra["drift_limit"]
    if method == "DOPRI5":
        assert res.status == -1  # measured: ||Phi|| = 21 m by t = 5 s without the projection
        projected = simulate(system, 5.0, method=method, rtol=1e-3)
        assert projected.status == 0 and projected.max_residual("position") < 1e-6


def test_drift_warn_goes_on_and_reports():
    system = scenes.double_pendulum(gravity=1000.0).build()
    with pytest.warns(ukflex.errors.DriftWarning):
        res = simulate(system, 5.0, method="DOPRI5", rtol=1e-3, on_drift="warn", projection_tol=0)
    assert res.status == 0 and res.t[-1] == 5.0
    d = res.extra["drift"]
    assert d["t_first"] < 1.0 and d["max_residual"] > res.extra["drift_limit"]
    assert "drifted" in d["message"]


def test_on_drift_is_checked():
    with pytest.raises(ukflex.InvalidArgumentError, match="on_drift"):
        simulate(scenes.pendulum(), 0.1, on_drift="ignore")


# ------------------------------------------------------------------------------------- continuous angles
def spun_cable(clamp: str, elements: int = 4) -> Scene:
    """A steel ANCF cable (1 m, d = 5 mm) clamped to a hub whose angle is driven as t^2 / 2, under
    gravity: by a weld (an angle row against the cable's root slope, whose angle is read off the
    slope and passes +-pi at 2.5 s) or by a revolute and a point on the cable's root line (no
    angle row)."""
    s = Scene(gravity=(0.0, -G))
    hub = s.rigid_body("hub", mass=1.0, inertia=0.01)
    s.revolute(s.ground.point(0.0, 0.0), hub.point(0.0, 0.0))
    s.angle_driver(hub.frame(), ukflex.Polynomial([0.0, 0.0, 0.5]))
    cable = s.cable("cable", length=1.0, elements=elements, section=ukflex.Circular(0.005), density=7850.0,
                   youngs_modulus=2.1e11)
    if clamp == "weld":
        s.weld(hub.frame(), cable.at(0.0))
    else:
        s.revolute(hub.point(0.0, 0.0), cable.at(0.0))
        s.point_on_line(hub.point(0.1, 0.0), cable.line(0.0))
    return s


def test_welded_cable_turns_five_times_as_the_clamped_one():
    """The weld's angle row is wrapped to the nearest turn: the welded cable follows the hub over
    five turns, its tip within 1e-3 of the cable's length of the same cable clamped without an
    angle row (before: auto stopped at 2.5 s, "Newton did not converge"; GENALPHA at a fixed
    step returned status 0 with the tip 2e17 m away)."""
    T = math.sqrt(20 * math.pi)  # t^2 / 2 = 5 turns
    t = np.linspace(0.0, T, 801)
    tips = {}
    for clamp in ("weld", "line"):
        system = spun_cable(clamp).build()
        res = simulate(system, T, t_eval=t)
        assert res.status == 0, (clamp, res.message)
        assert res.coordinate("hub.theta")[-1] == pytest.approx(10 * math.pi, rel=1e-9)
        tips[clamp] = np.array([system.beam_point("cable", 1.0, res.q[:, k])[:2] for k in range(t.size)])
    assert np.abs(tips["weld"] - tips["line"]).max() < 1e-3  # measured 1.3e-11
    # the tip really went round five times (unwrapped angle of the tip from the hub)
    ang = np.unwrap(np.arctan2(tips["weld"][:, 1], tips["weld"][:, 0]))
    assert ang[-1] - ang[0] == pytest.approx(10 * math.pi, abs=0.2)


def test_welded_cable_with_genalpha_at_a_fixed_step_is_right_or_says_so():
    T = math.sqrt(20 * math.pi)
    system = spun_cable("weld").build()
    res = simulate(system, T, method="GENALPHA", step=0.01)
    tip = np.array(system.beam_point("cable", 1.0, res.q[:, -1])[:2])
    if res.status == 0:
        assert np.linalg.norm(tip) == pytest.approx(1.0, abs=1e-2)
        assert res.max_residual("position") <= res.extra["drift_limit"]
    else:
        assert res.stop is not None


def test_torque_on_a_cable_does_work_over_many_turns():
    """A torque on an ANCF cable's root frame (angle read off its slope): the load's potential
    -tau phi is unwrapped from state to state, so its work grows with every turn instead of
    jumping back by 2 pi tau, and the energy balance closes."""
    s = Scene()
    cable = s.cable("cable", length=0.5, elements=2, section=ukflex.Circular(0.01), density=7850.0,
                   youngs_modulus=2.1e11)
    s.revolute(s.ground.point(0.0, 0.0), cable.at(0.0))
    s.torque(cable.at(0.0), 0.2)
    system = s.build()
    res = simulate(system, 3.0, t_eval=np.linspace(0.0, 3.0, 601))
    assert res.status == 0, res.message
    work = res.sensors.external_work()
    assert np.all(np.diff(work) > -1e-12)  # a constant torque turning one way only gains work
    root = np.array([system.beam_point("cable", 0.02, res.q[:, k])[:2] for k in range(res.t.size)])
    turns = np.unwrap(np.arctan2(root[:, 1], root[:, 0]))[-1] / (2 * math.pi)
    assert turns > 1.5
    assert work[-1] == pytest.approx(0.2 * 2 * math.pi * turns, rel=2e-2)
    assert res.sensors.energy_balance()["relative_error"] < 1e-3


def test_the_suite_wide_check_catches_status_zero_beyond_the_bound():
    """conftest.no_success_on_garbage checks every run of the suite; here it is shown to fail
    on a result that claims success beyond its bound."""
    from conftest import check_no_success_on_garbage

    system = scenes.double_pendulum(gravity=1000.0).build()
    with pytest.warns(ukflex.errors.DriftWarning):
        res = simulate(system, 5.0, method="DOPRI5", rtol=1e-3, on_drift="warn", projection_tol=0)
    check_no_success_on_garbage(res)  # reported: allowed
    claimed = copy.copy(res)  # the same result claiming success without the report
    claimed.extra = {k: v for k, v in res.extra.items() if k != "drift"}
    with pytest.raises(AssertionError, match="beyond the drift bound"):
        check_no_success_on_garbage(claimed)
