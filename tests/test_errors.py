"""Every bad input raises the right exception, and the message names the item."""

import copy
import json
import math

import numpy as np
import pytest

import ukflex
from ukflex import Scene, scenes, simulate
from ukflex.model.scene import Marker


@pytest.fixture(scope="module")
def crank():
    return scenes.slider_crank().build()


def test_hierarchy():
    for cls in (
        ukflex.InvalidSceneError,
        ukflex.SingularMassError,
        ukflex.SolverError,
        ukflex.NonFiniteError,
        ukflex.InconsistentInitialStateError,
    ):
        assert issubclass(cls, ukflex.UkflexError)
    assert not issubclass(ukflex.UkflexError, ValueError)


# ----------------------------------------------------------------------------------- properties
@pytest.mark.parametrize(
    "path,value,pattern",
    [
        (("bodies", 1, "length"), 0.0, r"coupler.*length"),
        (("bodies", 1, "length"), -0.3, r"coupler.*length"),
        (("bodies", 0, "mass"), 0.0, r"crank.*mass"),
        (("bodies", 0, "mass"), -1.0, r"crank.*mass"),
        (("bodies", 1, "youngs_modulus"), 0.0, r"coupler.*youngs_modulus"),
        (("bodies", 1, "density"), -7800.0, r"coupler.*density"),
        (("bodies", 1, "section", "diameter"), 0.0, r"coupler.*diameter"),
        (("bodies", 1, "elements"), 0, r"coupler.*elements"),
    ],
)
def test_non_physical_property(path, value, pattern):
    d = scenes.slider_crank().to_dict()
    target = d
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    # Python validation (System / Scene.from_dict) ...
    with pytest.raises(ukflex.InvalidSceneError, match=pattern):
        ukflex.System(d)
    # ... and the Rust core on its own reject it, naming the item
    import ukflex._core as core

    with pytest.raises(ukflex.InvalidSceneError, match=pattern):
        core.System(json.dumps(d))


def test_nan_property_rejected():
    d = scenes.slider_crank().to_dict()
    d["bodies"][1]["youngs_modulus"] = float("nan")
    with pytest.raises(ukflex.InvalidSceneError, match="coupler.*youngs_modulus.*finite"):
        ukflex.System(d)


def test_unknown_body_in_joint():
    d = scenes.slider_crank().to_dict()
    d["joints"][1]["b"]["body"] = "conrod"
    with pytest.raises(ukflex.InvalidSceneError, match="crank_coupler.*conrod"):
        ukflex.System(d)
    import ukflex._core as core

    with pytest.raises(ukflex.InvalidSceneError, match="conrod"):
        core.System(json.dumps(d))


def test_duplicate_body_names():
    d = scenes.double_pendulum().to_dict()
    d["bodies"][1]["name"] = "rod1"
    with pytest.raises(ukflex.InvalidSceneError, match="rod1.*duplicate"):
        ukflex.System(d)
    import ukflex._core as core

    with pytest.raises(ukflex.InvalidSceneError, match="rod1"):
        core.System(json.dumps(d))


def test_malformed_json_in_core():
    import ukflex._core as core

    with pytest.raises(ukflex.InvalidSceneError):
        core.System("{not json")
    with pytest.raises(ukflex.InvalidSceneError, match="bodies"):
        core.System(json.dumps({"joints": []}))


# ----------------------------------------------------------------------------------- arrays
def test_wrong_shapes_raise_value_error(crank):
    n = crank.n_coords
    q, qd = crank.q0, crank.qd0
    with pytest.raises(ValueError):
        crank.M(np.zeros(n + 1))
    with pytest.raises(ValueError):
        crank.qdd(0.0, q, np.zeros(n - 1))
    with pytest.raises(ValueError):
        crank.rhs(0.0, np.zeros(n))
    with pytest.raises(ValueError):
        simulate(crank, 0.01, q0=np.zeros(n + 2))
    with pytest.raises(ValueError):
        simulate(crank, 0.01, atol=np.ones(3))


@pytest.mark.parametrize("bad", [np.zeros((9, 1)), np.zeros((3, 3)), np.array(["a"] * 9)], ids=["2d-column", "2d", "strings"])
def test_wrong_dimension_or_type_raises_value_error_naming_the_argument(crank, bad):
    with pytest.raises(ValueError, match="1-D array of floats") as info:
        crank.phi(0.0, bad)
    # pyo3 attaches the argument name as an exception note (shown in every traceback)
    assert any("'q'" in note for note in getattr(info.value, "__notes__", [])), info.value


def test_integer_and_list_inputs_are_converted_like_numpy(crank):
    q = crank.q0
    as_int = np.round(q * 1000).astype(np.int64)
    np.testing.assert_array_equal(crank.phi(0.0, as_int), crank.phi(0.0, as_int.astype(float)))
    np.testing.assert_array_equal(crank.phi(0.0, list(q)), crank.phi(0.0, q))


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_non_finite_arrays(crank, bad):
    q, qd = crank.q0.copy(), crank.qd0.copy()
    q_bad = q.copy()
    q_bad[4] = bad
    qd_bad = qd.copy()
    qd_bad[7] = bad
    with pytest.raises(ukflex.NonFiniteError, match="4"):
        crank.qdd(0.0, q_bad, qd)
    with pytest.raises(ukflex.NonFiniteError, match="7"):
        crank.Q(0.0, q, qd_bad)
    with pytest.raises(ukflex.NonFiniteError):
        crank.rhs(0.0, np.concatenate([q_bad, qd]))
    with pytest.raises(ukflex.NonFiniteError):
        crank.M(q_bad)
    with pytest.raises(ukflex.NonFiniteError):
        crank.qdd(bad, q, qd)
    with pytest.raises(ukflex.NonFiniteError, match="q0"):
        simulate(crank, 0.01, q0=q_bad)
    with pytest.raises(ukflex.NonFiniteError, match="t_eval"):
        simulate(crank, 0.01, t_eval=[0.0, bad])


# ----------------------------------------------------------------------------------- simulate args
@pytest.mark.parametrize(
    "kwargs,exc,pattern",
    [
        (dict(t_end=0.0), ValueError, "t_end"),
        (dict(t_end=-1.0), ValueError, "t_end"),
        (dict(t_end=float("nan")), ValueError, "t_end"),
        (dict(t_end=float("inf")), ValueError, "t_end"),
        (dict(t_end=0.1, method="Euler"), ValueError, "Euler"),
        (dict(t_end=0.1, formulation="lagrange"), ValueError, "lagrange"),
        (dict(t_end=0.1, rtol=0.0), ValueError, "rtol"),
        (dict(t_end=0.1, rtol=float("nan")), ValueError, "rtol"),
        (dict(t_end=0.1, atol=-1.0), ValueError, "atol"),
        (dict(t_end=0.1, t_eval=[0.0, 0.2]), ValueError, "t_eval"),
        (dict(t_end=0.1, t_eval=[0.05, 0.01]), ValueError, "t_eval"),
    ],
)
def test_simulate_argument_validation(crank, kwargs, exc, pattern):
    with pytest.raises(exc, match=pattern):
        simulate(crank, **kwargs)


def test_simulate_rejects_other_objects():
    with pytest.raises(TypeError):
        simulate("slider_crank", 0.1)


# ----------------------------------------------------------------------------------- initial state
def test_inconsistent_geometry_cannot_be_corrected():
    """A 1 m rod pinned at both ends to ground points 2 m apart cannot be assembled."""
    s = Scene()
    rod = s.rigid_body("rod", mass=1.0, inertia=1.0 / 12, position=(1.0, 0.0))
    s.revolute(s.ground.point(0, 0), rod.point(-0.5, 0), name="left")
    s.revolute(s.ground.point(2, 0), rod.point(0.5, 0), name="right")
    with pytest.raises(ukflex.InconsistentInitialStateError, match="left|right") as info:
        s.build()
    err = info.value
    assert isinstance(err, ukflex.UkflexError)
    assert err.rows and all(("left" in r or "right" in r) for r in err.rows)
    assert err.residuals.shape == (4,)
    assert np.abs(err.residuals).max() > 0.1
    # without correction the system builds (and reports the residual)
    sys_ = s.build(correct=False)
    assert sys_.initial_correction.position_residual_after > 0.4


def test_velocity_that_needs_elastic_rates():
    """A clamped cantilever whose tip height is driven: the prescribed tip velocity can only come
    from elastic rates, so with elastic coordinates held the projection fails; with hold=None it
    succeeds."""
    s = scenes.cantilever(gravity=False, elements=2)
    s.coordinate_driver(s["beam"].at(1.0), "y", ukflex.ConstantSpeed(0.01), name="tip_lift")
    with pytest.raises(ukflex.InconsistentInitialStateError, match="tip_lift") as info:
        s.build()
    assert any("tip_lift" in r for r in info.value.rows)
    sys_ = s.build(hold=None)
    assert np.abs(sys_.A(sys_.q0) @ sys_.qd0 + sys_.phi_t(0.0)).max() < 1e-10
    assert np.abs(sys_.qd0[sys_.elastic_slice("beam")]).max() > 0.0


def test_singular_mass_matrix():
    """Positive but negligible inertia about a centre of mass 1 m from the body frame:
    M = [[1, 0, 0], [0, 1, 1], [0, 1, 1 + 1e-30]] is singular in floating point."""
    s = Scene()
    s.rigid_body("dot", mass=1.0, inertia=1e-30, com=(1.0, 0.0))
    with pytest.raises(ukflex.SingularMassError):
        s.build()


def test_zero_inertia_rejected_by_python_and_by_core():
    d = scenes.pendulum().to_dict()
    d["bodies"][0]["inertia"] = 0.0
    with pytest.raises(ukflex.InvalidSceneError, match="rod.*inertia"):
        ukflex.System(d)
    import ukflex._core as core

    with pytest.raises((ukflex.InvalidSceneError, ukflex.SingularMassError), match="rod"):
        c = core.System(json.dumps(d))
        c.qdd(0.0, *c.initial_guess())
