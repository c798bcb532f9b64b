"""Scene builder and description dict: structure, round trip, Python-side validation.

These tests need no compiled core.
"""

import copy
import json
import math

import pytest

import ukflex
from ukflex import Circular, ConstantSpeed, CustomSection, Harmonic, Polynomial, Rectangular, Scene
from ukflex import scenes
from ukflex.model.scene import Marker, elastic_dofs


def _beam_kwargs(**over):
    kw = dict(
        length=0.3,
        section=Circular(0.01),
        density=7800.0,
        youngs_modulus=2e11,
        poisson_ratio=0.3,
        shear_factor=0.8,
    )
    kw.update(over)
    return kw


def test_slider_crank_description_matches_paper(paper_data):
    d = scenes.slider_crank().to_dict()
    L, Lb, dia, rho = (paper_data[k] for k in ("crank_length", "coupler_length", "diameter", "density"))
    omega = paper_data["omega"]
    area = math.pi * dia**2 / 4
    assert d["gravity"] == [0.0, -9.81]
    crank, coupler = d["bodies"]
    assert crank["kind"] == "rigid" and coupler["kind"] == "beam"
    assert crank["mass"] == pytest.approx(rho * area * L, rel=1e-14)
    assert crank["inertia"] == pytest.approx(rho * area * L * L**2 / 12, rel=1e-14)
    assert crank["com"] == [L / 2, 0.0]
    assert crank["position"] == [0.0, 0.0] and crank["angle"] == 0.0
    assert crank["angular_velocity"] == omega
    assert coupler["length"] == Lb and coupler["elements"] == 1
    assert coupler["theory"] == "timoshenko" and coupler["frame"] == "pinned-pinned"
    assert coupler["section"] == {"shape": "circular", "diameter": dia}
    assert coupler["youngs_modulus"] == paper_data["youngs_modulus"]
    assert coupler["poisson_ratio"] == paper_data["poisson_ratio"]
    assert coupler["shear_factor"] == paper_data["shear_factor"]
    assert coupler["position"] == [L, 0.0]
    assert coupler["velocity"] == pytest.approx([0.0, L * omega], abs=1e-15)
    assert coupler["angular_velocity"] == pytest.approx(-L * omega / Lb, rel=1e-15)
    assert "elastic" not in coupler  # undeformed: core default zeros
    kinds = [j["kind"] for j in d["joints"]]
    assert kinds == ["revolute", "revolute", "point_on_line"]
    pol = d["joints"][2]
    assert pol["point"] == {"body": "coupler", "xi": 1.0, "angle": 0.0}
    assert pol["line"] == {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}
    (drv,) = d["drivers"]
    assert drv["kind"] == "angle" and drv["a"]["body"] == "crank"
    assert drv["motion"] == {"kind": "constant_speed", "initial": 0.0, "speed": omega}
    assert d["forces"] == []


def test_slider_crank_options():
    d = scenes.slider_crank(theory="euler-bernoulli", elements=4, gravity=False, omega=10.0).to_dict()
    assert "gravity" not in d
    coupler = d["bodies"][1]
    assert coupler["theory"] == "euler-bernoulli" and coupler["elements"] == 4
    assert "shear_factor" not in coupler
    assert d["drivers"][0]["motion"]["speed"] == 10.0
    s = scenes.slider_crank(elements=4)
    assert s.n_coords == 3 + 3 + 12 and s.n_constraints == 6


@pytest.mark.parametrize("name", sorted(scenes.SCENES))
def test_round_trip_every_builtin_scene(name):
    s = scenes.SCENES[name]()
    d = s.to_dict()
    text = json.dumps(d, allow_nan=False)  # JSON-compatible, no NaN
    d2 = Scene.from_dict(json.loads(text)).to_dict()
    assert d2 == d
    assert Scene.from_dict(d).n_coords == s.n_coords
    assert Scene.from_dict(d).n_constraints == s.n_constraints


def test_to_dict_is_a_copy():
    s = scenes.pendulum()
    d = s.to_dict()
    d["bodies"][0]["mass"] = -1.0
    d["joints"].clear()
    assert s.to_dict()["bodies"][0]["mass"] == 1.0
    assert len(s.to_dict()["joints"]) == 1


def test_every_joint_uses_every_kind():
    d = scenes.every_joint().to_dict()
    assert {j["kind"] for j in d["joints"]} == {"revolute", "point_on_line", "prismatic", "weld"}
    assert {x["kind"] for x in d["drivers"]} == {"angle", "coordinate"}
    assert {f["kind"] for f in d["forces"]} == {"point_force", "torque", "spring_damper"}
    assert {b["kind"] for b in d["bodies"]} == {"rigid", "beam"}
    assert {b["frame"] for b in d["bodies"] if b["kind"] == "beam"} == {"pinned-pinned", "clamped"}
    assert "gravity" in d
    s = scenes.every_joint()
    assert (s.n_coords, s.n_constraints) == (24, 14)


def test_markers_and_handles():
    s = Scene()
    r = s.rigid_body("r", mass=1.0, inertia=0.1, position=(1.0, 2.0), angle=0.5)
    b = s.beam("b", **_beam_kwargs(elements=3))
    assert r.point(1, 2) == Marker("r", point=(1.0, 2.0))
    assert r.point((1, 2), angle=0.3) == Marker("r", point=(1.0, 2.0), angle=0.3)
    assert r.frame(0.2).to_dict() == {"body": "r", "point": [0.0, 0.0], "angle": 0.2}
    assert s.ground.line((0.5, 0), angle=1.0).to_dict() == {"body": "ground", "point": [0.5, 0.0], "angle": 1.0}
    assert b.at(0.25).to_dict() == {"body": "b", "xi": 0.25, "angle": 0.0}
    assert b.n_f == 9 == elastic_dofs(3, "pinned-pinned") == elastic_dofs(3, "clamped")
    assert s["b"] == b and s.body("r") == r and s.body("ground") == s.ground
    assert s.body_names == ["r", "b"]
    assert r.description["position"] == [1.0, 2.0]
    # marker dicts are accepted as well as Marker objects
    s.revolute({"body": "ground", "point": [0, 0]}, {"body": "r", "point": [0, 0]})
    assert s.to_dict()["joints"][0]["a"] == {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}


def test_sections_and_motions_serialise():
    assert Rectangular(0.02, 0.01).to_dict() == {"shape": "rectangular", "width": 0.02, "height": 0.01}
    assert CustomSection(1e-4, 1e-9).to_dict() == {"shape": "custom", "area": 1e-4, "second_moment": 1e-9}
    assert ConstantSpeed(3.0, initial=1.0).to_dict() == {"kind": "constant_speed", "initial": 1.0, "speed": 3.0}
    assert Polynomial([1, 2]).to_dict() == {"kind": "polynomial", "coefficients": [1.0, 2.0]}
    assert Harmonic(amplitude=1.0, frequency=2.0, phase=0.5).to_dict() == {
        "kind": "harmonic", "offset": 0.0, "amplitude": 1.0, "frequency": 2.0, "phase": 0.5,
    }


def test_spring_rest_length_defaults_to_initial_distance():
    s = Scene()
    r = s.rigid_body("r", mass=1.0, inertia=0.1, position=(3.0, 4.0), angle=math.pi / 2)
    s.spring_damper(s.ground.point(0, 0), r.point(1.0, 0.0), stiffness=10.0)
    # r.point(1, 0) is at (3, 5) in the world
    assert s.to_dict()["forces"][0]["rest_length"] == pytest.approx(math.hypot(3.0, 5.0))
    s.spring_damper(s.ground.point(0, 0), r.point(0, 0), stiffness=10.0, rest_length=2.0, name="k2")
    assert s.to_dict()["forces"][1]["rest_length"] == 2.0
    assert s.to_dict()["forces"][1]["name"] == "k2"


def test_names_of_joints_drivers_forces_are_kept():
    s = scenes.slider_crank()
    d = s.to_dict()
    assert [j["name"] for j in d["joints"]] == ["crank_pivot", "crank_coupler", "slider"]
    assert d["drivers"][0]["name"] == "crank_speed"


# ----------------------------------------------------------------------------------- validation
BAD_BODIES = [
    (dict(mass=0.0), "mass"),
    (dict(mass=-1.0), "mass"),
    (dict(mass=float("nan")), "mass"),
    (dict(inertia=0.0), "inertia"),
    (dict(inertia=float("inf")), "inertia"),
    (dict(com=(0.0, float("nan"))), "com"),
    (dict(position=(1.0, 2.0, 3.0)), "position"),
    (dict(angle=float("nan")), "angle"),
]


@pytest.mark.parametrize("over,field", BAD_BODIES)
def test_bad_rigid_body_rejected(over, field):
    s = Scene()
    kw = dict(mass=1.0, inertia=0.1)
    kw.update(over)
    with pytest.raises(ukflex.InvalidSceneError, match=rf"body 'link'.*{field}"):
        s.rigid_body("link", **kw)
    assert s.body_names == []  # nothing half-added


BAD_BEAMS = [
    (dict(length=0.0), "length"),
    (dict(length=-0.3), "length"),
    (dict(density=0.0), "density"),
    (dict(youngs_modulus=-2e11), "youngs_modulus"),
    (dict(youngs_modulus=float("nan")), "youngs_modulus"),
    (dict(elements=0), "elements"),
    (dict(elements=1.5), "elements"),
    (dict(poisson_ratio=0.7), "poisson_ratio"),
    (dict(shear_factor=0.0), "shear_factor"),
    (dict(shear_factor=None), "shear_factor"),
    (dict(poisson_ratio=None), "poisson_ratio or shear_modulus"),
    (dict(section=Circular(0.0)), "diameter"),
    (dict(section=Rectangular(0.01, -1.0)), "height"),
    (dict(section=CustomSection(1e-4, float("nan"))), "second_moment"),
    (dict(section="round"), "section"),
    (dict(theory="rayleigh"), "theory"),
    (dict(frame="free"), "frame"),
    (dict(damping=-1.0), "damping"),
    (dict(elastic=[0.0, 0.0]), "elastic"),
    (dict(elastic_rates=[0.0, float("nan"), 0.0]), "elastic_rates"),
]


@pytest.mark.parametrize("over,field", BAD_BEAMS)
def test_bad_beam_rejected(over, field):
    s = Scene()
    with pytest.raises(ukflex.InvalidSceneError, match=rf"body 'coupler'.*{field}"):
        s.beam("coupler", **_beam_kwargs(**over))


def test_euler_bernoulli_needs_no_shear_data():
    s = Scene()
    s.beam("b", **_beam_kwargs(theory="euler-bernoulli", poisson_ratio=None, shear_factor=None))
    assert "shear_factor" not in s.to_dict()["bodies"][0]


def test_duplicate_and_reserved_names():
    s = Scene()
    s.rigid_body("a", mass=1.0, inertia=1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="body 'a'.*duplicate"):
        s.rigid_body("a", mass=1.0, inertia=1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="body 'ground'.*reserved"):
        s.rigid_body("ground", mass=1.0, inertia=1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="name"):
        s.rigid_body("", mass=1.0, inertia=1.0)
    s.rigid_body("b", mass=1.0, inertia=1.0)
    s.revolute(s.ground.point(0, 0), s["a"].point(0, 0), name="j")
    with pytest.raises(ukflex.InvalidSceneError, match="'j'.*duplicate"):
        s.revolute(s["a"].point(1, 0), s["b"].point(0, 0), name="j")
    with pytest.raises(ukflex.InvalidSceneError, match="'j'.*duplicate"):
        s.torque(s["a"].frame(), 1.0, name="j")


def test_unknown_body_in_joint_driver_force():
    s = Scene()
    a = s.rigid_body("a", mass=1.0, inertia=1.0)
    ghost = Marker("ghost", point=(0.0, 0.0))
    with pytest.raises(ukflex.InvalidSceneError, match="joint revolute.*unknown body 'ghost'"):
        s.revolute(a.point(0, 0), ghost)
    with pytest.raises(ukflex.InvalidSceneError, match="driver angle.*unknown body 'ghost'"):
        s.angle_driver(ghost, ConstantSpeed(1.0))
    with pytest.raises(ukflex.InvalidSceneError, match="force point_force 'f'.*unknown body 'ghost'"):
        s.point_force(ghost, (1.0, 0.0), name="f")
    assert s.to_dict()["joints"] == [] and s.to_dict()["drivers"] == [] and s.to_dict()["forces"] == []


def test_marker_kind_mismatch():
    s = Scene()
    a = s.rigid_body("a", mass=1.0, inertia=1.0)
    b = s.beam("b", **_beam_kwargs())
    with pytest.raises(ukflex.InvalidSceneError, match="beam 'b'.*xi"):
        s.revolute(a.point(0, 0), Marker("b", point=(0.0, 0.0)))
    with pytest.raises(ukflex.InvalidSceneError, match="xi"):
        s.revolute(a.point(0, 0), b.at(1.5))
    with pytest.raises(ukflex.InvalidSceneError, match="not by xi"):
        s.revolute(Marker("a", xi=0.5), b.at(0.0))
    with pytest.raises(ukflex.InvalidSceneError, match="same body"):
        s.revolute(a.point(0, 0), a.point(1, 0))
    with pytest.raises(ukflex.InvalidSceneError, match="body handle"):
        s.revolute(a, b.at(0.0))


def test_bad_driver_and_force_fields():
    s = Scene()
    a = s.rigid_body("a", mass=1.0, inertia=1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="axis"):
        s.coordinate_driver(a.point(0, 0), "z", ConstantSpeed(1.0))
    with pytest.raises(ukflex.InvalidSceneError, match="speed"):
        s.angle_driver(a.frame(), ConstantSpeed(float("nan")))
    with pytest.raises(ukflex.InvalidSceneError, match="coefficients"):
        s.angle_driver(a.frame(), Polynomial([]))
    with pytest.raises(ukflex.InvalidSceneError, match="motion"):
        s.angle_driver(a.frame(), {"kind": "jerk"})
    with pytest.raises(ukflex.InvalidSceneError, match="force"):
        s.point_force(a.point(0, 0), (1.0, float("inf")))
    with pytest.raises(ukflex.InvalidSceneError, match="stiffness"):
        s.spring_damper(a.point(0, 0), s.ground.point(1, 0), stiffness=-1.0)
    with pytest.raises(ukflex.InvalidSceneError, match="torque"):
        s.torque(a.frame(), float("nan"))
    with pytest.raises(ukflex.InvalidSceneError, match="gravity"):
        Scene(gravity=(0.0, float("nan")))


def test_from_dict_rejects_malformed_descriptions():
    good = scenes.slider_crank().to_dict()
    cases = []
    d = copy.deepcopy(good)
    d["bodies"][1]["lenght"] = 1.0
    cases.append((d, "body 'coupler'.*unknown field.*lenght"))
    d = copy.deepcopy(good)
    del d["bodies"][0]["mass"]
    cases.append((d, "body 'crank'.*missing.*mass"))
    d = copy.deepcopy(good)
    d["bodies"][0]["kind"] = "soft"
    cases.append((d, "body 'crank'.*unknown kind"))
    d = copy.deepcopy(good)
    d["joints"][1]["b"]["body"] = "conrod"
    cases.append((d, "'crank_coupler'.*unknown body 'conrod'"))
    d = copy.deepcopy(good)
    d["joints"][0]["kind"] = "ball"
    cases.append((d, "unknown joint kind 'ball'"))
    d = copy.deepcopy(good)
    d["bodies"].append(copy.deepcopy(d["bodies"][0]))
    cases.append((d, "body 'crank'.*duplicate"))
    d = copy.deepcopy(good)
    d["extra"] = 1
    cases.append((d, "scene.*unknown field.*extra"))
    d = copy.deepcopy(good)
    d["bodies"][1]["elastic"] = [0.0] * 4
    cases.append((d, "body 'coupler'.*elastic must have length 3"))
    for desc, pattern in cases:
        with pytest.raises(ukflex.InvalidSceneError, match=pattern):
            Scene.from_dict(desc)
