"""Issue-15 robustness at the API: absurd but finite properties, hostile arrays and inputs that
overflow double precision end in a named error, never in NaN or garbage."""
import warnings

import numpy as np
import pytest

import ukflex
from ukflex import InvalidSceneError, NonFiniteError, scenes
from ukflex.analysis.stability import DriftWarning


@pytest.mark.parametrize("kwargs, match", [
    (dict(youngs_modulus=1e300), "elastic frequencies"),         # was: "mass matrix is not positive definite" mid-run
    (dict(youngs_modulus=1e-300), "bending stiffness"),
    (dict(shear_factor=1e308), "elastic frequencies"),
    (dict(coupler_length=1e-200), "out of double-precision range"),
    (dict(diameter=1e100), "second_moment"),
    (dict(omega=1e200), "accelerations at the initial guess are not finite"),
])
def test_absurd_beam_scene_properties_are_refused_at_build(kwargs, match):
    with pytest.raises(InvalidSceneError, match=match):
        ukflex.System(scenes.slider_crank(**kwargs))


@pytest.mark.parametrize("kwargs", [dict(mass=1e308), dict(angular_velocity=1e200), dict(length=1e200)])
def test_absurd_rigid_scene_properties_are_refused_at_build(kwargs):
    with pytest.raises(InvalidSceneError):
        ukflex.System(scenes.pendulum(**kwargs))


def test_plausible_extremes_still_build():
    # a soft rubber-like rod of many short elements and a very stiff short one stay legal
    ukflex.System(scenes.slider_crank(youngs_modulus=1e6, elements=8))
    ukflex.System(scenes.slider_crank(youngs_modulus=1e13, coupler_length=0.05))


@pytest.fixture(scope="module")
def crank():
    return ukflex.System(scenes.slider_crank(elements=2))


@pytest.mark.parametrize("bad, what", [
    (lambda q: np.ma.masked_array(q), "masked array"),
    (lambda q: q + 0j, "complex"),
    (lambda q: [str(x) for x in q], "strings"),
    (lambda q: None, "None"),
    (lambda q: q > 0, "booleans"),
])
def test_hostile_arrays_are_refused_naming_the_argument(crank, bad, what):
    with pytest.raises(ValueError, match=what) as info:
        crank.phi(0.0, bad(crank.q0))
    assert any("'q'" in n for n in getattr(info.value, "__notes__", [])), info.value


@pytest.mark.parametrize("method", ["M", "Q", "qdd", "multipliers", "kinetic_energy", "potential_energy", "jac"])
def test_inputs_beyond_double_range_give_non_finite_error_not_nan(crank, method):
    q, qd = crank.q0.copy(), crank.qd0.copy()
    q[3] = 1e200
    qd[4] = 1e200
    args = {"M": (q,), "Q": (0.0, q, qd), "qdd": (0.0, q, qd), "multipliers": (0.0, q, qd),
            "kinetic_energy": (q, qd), "potential_energy": (q,), "jac": (0.0, np.concatenate([q, qd]))}[method]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            out = getattr(crank, method)(*args)
        except NonFiniteError as exc:
            assert "result" in str(exc)
            return
    assert np.all(np.isfinite(out))


@pytest.mark.parametrize("pivot_x", [1e17, 1e8])
def test_mechanism_far_from_the_origin_fails_loudly(pivot_x):
    # at 1e17 m positions move in steps of 16 m: the constraints read zero whatever happens and a
    # run used to "succeed" with garbage (issue 15); 1e8 m still resolves only 1.5e-8 m
    s = ukflex.Scene(gravity=(0.0, -9.81))
    link = s.rigid_body("link", mass=1.0, inertia=0.1)
    s.revolute(s.ground.point(pivot_x, 0.0), link.point(-0.5, 0.0))
    with pytest.raises(InvalidSceneError, match="length scale 0.5 m"):
        s.build()


def test_mechanism_at_a_resolvable_offset_builds():
    s = ukflex.Scene(gravity=(0.0, -9.81))
    link = s.rigid_body("link", mass=1.0, inertia=0.1)
    s.revolute(s.ground.point(1e5, 0.0), link.point(-0.5, 0.0))
    system = s.build()
    assert system.q0[0] == pytest.approx(1e5 + 0.5)


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(coupler_length=0.0), InvalidSceneError, r"slider_crank\(coupler_length=0.0\)"),   # was ZeroDivisionError
    (dict(coupler_length="abc"), TypeError, "coupler_length must be a real number"),
    (dict(crank_length={"a": 1}), TypeError, "crank_length must be a real number"),
    (dict(elements=1.5), TypeError, "elements must be an integer"),
    (dict(omega=float("nan")), ValueError, "omega must be finite"),
])
def test_builtin_scene_arguments_are_checked_by_name(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        scenes.slider_crank(**kwargs)


@pytest.mark.parametrize("field, value, match", [
    ("elements", 10 ** 30, "elements: expected a whole number >= 0 .*got 1e\\+30"),  # was "invalid type: floating point"
    ("density", "x", 'density: expected a number, got string "x"'),
    ("density", True, "density: expected a number, got true"),
])
def test_type_errors_in_the_description_speak_the_users_words(field, value, match):
    kwargs = dict(length=0.3, section=ukflex.Circular(0.006), density=7800.0, youngs_modulus=2e11, elements=2)
    kwargs[field] = value
    s = ukflex.Scene()
    with pytest.raises(InvalidSceneError, match=match):
        s.beam("b", **kwargs)
        s.build()


def test_an_angle_double_precision_cannot_resolve_fails_loudly():
    with pytest.raises(InvalidSceneError, match="rod.theta = 1e\\+200 rad"):
        ukflex.System(scenes.pendulum(angle=1e200))


def test_a_budget_stop_before_the_first_step_still_has_a_message():
    # the stop message used to format the step size of a solver that had none yet (TypeError)
    res = ukflex.simulate(scenes.pendulum(), 1e200, method="BDF", rtol=1e-300, t_eval=np.array([0.0, 5e8, 1e9]),
                          max_wall_time=5.0, atol=[0.43, 1.0, 0.68, 0.68, 1.45e-226, 2.6e-124])
    assert res.status in (-1, 0) and res.message


@pytest.mark.parametrize("crank_length", [1e-30, 1e-12])
def test_masses_too_disparate_for_the_uk_solve_fail_loudly(crank_length):
    # a 1e-12 m crank (1e-37 kg m^2 next to a 0.08 kg coupler) used to build and then run with the
    # UK solve dropping 3 of 6 independent constraints as "redundant": max |Phi| 2e-3 m, status 0
    with pytest.raises(InvalidSceneError, match=r"masses span too many orders.*independent \(rank 6 of A"):
        ukflex.System(scenes.slider_crank(crank_length=crank_length, coupler_length=0.381))


def test_a_small_but_resolvable_crank_still_builds_and_runs():
    system = ukflex.System(scenes.slider_crank(crank_length=1e-6, coupler_length=0.381))
    res = ukflex.simulate(system, 0.02, method="DOPRI5", rtol=1e-8)
    assert res.status == 0
    assert max(np.abs(system.phi(t, q)).max() for t, q in zip(res.t, res.q.T)) < 1e-9


def test_redundant_constraints_of_the_scene_itself_are_not_mistaken_for_conditioning():
    # a parallelogram four-bar with a redundant coupler-parallel link: rank deficient by design
    s = ukflex.Scene()
    bars = [s.rigid_body(f"b{i}", mass=1.0, inertia=0.1, position=(x, 0.5), angle=np.pi / 2) for i, x in enumerate((0.0, 1.0, 2.0))]
    top = s.rigid_body("top", mass=1.0, inertia=0.5, position=(1.0, 1.0))
    for i, b in enumerate(bars):
        s.revolute(s.ground.point(float(i), 0.0), b.point(-0.5, 0.0))
        s.revolute(b.point(0.5, 0.0), top.point(float(i) - 1.0, 0.0))
    system = s.build()
    assert system.rank_info(system.t0, system.q0, system.qd0)["rank"] < system.n_constraints


def test_subnormal_properties_are_refused_by_name():
    s = ukflex.Scene()
    bob = s.point_mass("bob", mass=1.0, position=(0.0, -0.5))
    with pytest.raises(InvalidSceneError, match=r"length .*= 5e-324 is a subnormal number"):
        s.distance(s.ground.point(0.0, 0.0), bob.point(), length=5e-324)


@pytest.mark.parametrize("length", [1e-300, 1e-30])
def test_a_distance_below_the_scenes_resolution_fails_loudly(length):
    # a point pendulum of 1e-30 m used to be "corrected" onto its pivot (the absolute position
    # tolerance 1e-12 m accepted it) and then fell freely: status 0
    s = ukflex.Scene(gravity=(0.0, -9.81))
    bob = s.point_mass("bob", mass=1.0, position=(0.0, -0.5), velocity=(0.285, 0.0))
    s.distance(s.ground.point(0.0, 0.0), bob.point(), length=length)
    with pytest.raises(ukflex.UkflexError, match="degenerate|cannot be corrected"):
        ukflex.System(s)
    s.rigid_body("plate", mass=1.0, inertia=0.1, com=(0.5, 0.0))
    with pytest.raises(InvalidSceneError, match="below what the scene resolves"):
        ukflex.System(s)


def test_a_run_that_loses_its_constraints_says_so():
    # gravity 1e30 m/s^2 on a 1 m pendulum: the UK correction cancels 1e30 to its rounding (1e14
    # m/s^2) and the bob flies off by 3e10 m; the run used to end with status 0 and nothing said
    s = ukflex.Scene(gravity=(0.0, -1e30))
    bob = s.point_mass("bob", mass=2.8524188109448385, position=(2.8216492434996586e-298, -0.5),
                       velocity=(-1.3678032781104694e-269, 0.0))
    s.distance(s.ground.point(0.0, 0.0), bob.point(), length=1.0)
    system = s.build()
    # by default (projection after every step, on_drift="stop") it ends with status -1, named
    res = ukflex.simulate(system, 0.02, method="DOPRI5", rtol=1e-8, max_steps=20000)
    assert res.status == -1 and res.stop["cause"] in ("max_steps", "drift", "min_step"), res.stop
    # without the projection and told to go on, it warns and reports the drift
    with pytest.warns(DriftWarning, match="the constraints drifted"):
        res = ukflex.simulate(system, 0.02, method="DOPRI5", rtol=1e-8, max_steps=20000, projection_tol=0,
                              on_drift="warn")
    assert res.extra["drift"]["max_residual"] > 1.0


def test_an_ordinary_run_does_not_warn_about_drift():
    with warnings.catch_warnings():
        warnings.simplefilter("error", DriftWarning)
        res = ukflex.simulate(scenes.slider_crank(), 0.05, method="DOPRI5", rtol=1e-6)
    assert "drift" not in res.extra


def test_a_run_that_cannot_finish_within_its_budget_stops_early():
    # scipy paths cost ~0.1 ms per step: 1e9 s of pendulum used to grind 2 min towards the budget
    res = ukflex.simulate(scenes.pendulum(), 1e9, method="RK45")
    assert res.status == -1 and res.stop["cause"] == "max_steps"
    assert "cannot suffice" in res.message and res.t.size > 100 and res.t[-1] < 1e9


def test_a_scene_beyond_the_double_range_of_squares_is_refused():
    # a pendulum of 1.8e308 m built (its energies were still finite) and overflowed at the first motion
    s = ukflex.Scene(gravity=(0.0, -1.7))
    bob = s.point_mass("bob", mass=0.22, position=(0.03, -0.5))
    s.distance(s.ground.point(0.0, 0.0), bob.point(), length=1.7976931348623157e308)
    with pytest.raises(InvalidSceneError, match="length scale 1.8e\\+308 m is beyond 1e\\+150 m"):
        ukflex.System(s)
