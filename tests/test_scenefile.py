"""TOML scene files: round trip of every built-in scene, settings, and errors naming the offending key."""

import os

import numpy as np
import pytest

import ukflex
from ukflex.model import scenefile
from ukflex import scenes
from ukflex.model.scenefile import SceneFileError

EXAMPLES = os.path.join(os.path.dirname(__file__), os.pardir, "examples")

TINY = """
gravity = [0.0, -9.81]

[scene]
name = "tiny"

[[bodies]]
name = "rod"
kind = "rigid"
mass = 1.0
inertia = 0.08333333333333333
position = [0.5, 0.0]

[[joints]]
kind = "revolute"
a = { body = "ground", point = [0.0, 0.0] }
b = { body = "rod", point = [-0.5, 0.0] }

[initial]
hold = "none"

[solver]
t_end = 0.2
method = "DOP853"
rtol = 1e-8
samples = 21

[output]
plot = ["rod.theta", "energy"]
animate = false
"""


@pytest.mark.parametrize("name", sorted(scenes.SCENES))
def test_builtin_scenes_round_trip_exactly(name):
    scene = scenes.SCENES[name]()
    text = scenefile.dumps(scene, name=name, solver={"t_end": 0.5, "method": "RK45"})
    sf = scenefile.loads(text, path=f"{name}.toml")
    assert sf.scene.to_dict() == scene.to_dict()
    assert sf.name == name and sf.solver == {"t_end": 0.5, "method": "RK45"}


def test_tiny_file_settings_and_build():
    sf = scenefile.loads(TINY, path="tiny.toml")
    assert sf.name == "tiny"
    assert sf.initial == {"hold": None}
    assert sf.solver == {"t_end": 0.2, "method": "DOP853", "rtol": 1e-8, "samples": 21}
    assert sf.output == {"plot": ["rod.theta", "energy"], "animate": False}
    system = sf.build()
    assert system.n_coords == 3 and system.n_constraints == 2
    assert system.coordinate_names == ["rod.x", "rod.y", "rod.theta"]


@pytest.mark.parametrize("path", ["slider_crank.toml", "pendulum.toml", "four_bar_flexible.toml"])
def test_examples_load(path):
    sf = scenefile.load(os.path.join(EXAMPLES, path))
    sf.build()
    assert sf.solver["t_end"] > 0


def test_example_slider_crank_is_the_builtin_paper_scene():
    sf = scenefile.load(os.path.join(EXAMPLES, "slider_crank.toml"))
    assert sf.scene.to_dict() == scenes.slider_crank().to_dict()


def test_name_defaults_to_file_stem(tmp_path):
    p = tmp_path / "my_rod.toml"
    p.write_text(TINY.replace('[scene]\nname = "tiny"\n', ""))
    assert scenefile.load(p).name == "my_rod"


def _error(text, path="bad.toml"):
    with pytest.raises(SceneFileError) as info:
        scenefile.loads(text, path=path)
    return str(info.value)


def test_error_is_an_invalid_scene_error():
    assert issubclass(SceneFileError, ukflex.InvalidSceneError)
    assert issubclass(SceneFileError, ukflex.UkflexError)


def test_error_unknown_body_field_names_entry_line_and_key():
    text = TINY.replace("mass = 1.0", "mas = 1.0")
    msg = _error(text)
    line = [i + 1 for i, l in enumerate(text.splitlines()) if l.strip() == "[[bodies]]"][0]
    assert msg.startswith("bad.toml: [[bodies]] #1 (line %d)" % line)
    assert "'mas'" in msg and "body 'rod'" in msg


def test_error_joint_with_unknown_body_points_at_the_joint():
    msg = _error(TINY.replace('b = { body = "rod"', 'b = { body = "rood"'))
    assert "[[joints]] #1" in msg and "'rood'" in msg


def test_error_bad_values_in_settings():
    assert "[solver] method" in _error(TINY.replace('method = "DOP853"', 'method = "RK4"'))
    assert "[solver] rtol" in _error(TINY.replace("rtol = 1e-8", "rtol = -1e-8"))
    assert "[solver] samples" in _error(TINY.replace("samples = 21", "samples = 2.5"))
    assert "[output] plot" in _error(TINY.replace('plot = ["rod.theta", "energy"]', "plot = [1, 2]"))
    assert "[initial] hold" in _error(TINY.replace('hold = "none"', "hold = 3"))


def test_error_unknown_keys_suggest_and_explain():
    msg = _error(TINY.replace("[solver]", "[solvr]"))
    assert "top level" in msg and "'solvr'" in msg and "did you mean 'solver'" in msg
    msg = _error(TINY.replace("samples = 21", "samples = 21\ngravity = [0, -1]"))
    assert "[solver]" in msg and "'gravity'" in msg and "before the first [table]" in msg


def test_error_toml_syntax_and_missing_file(tmp_path):
    assert "TOML syntax error" in _error("gravity = [0.0, \n")
    with pytest.raises(SceneFileError, match="cannot read"):
        scenefile.load(tmp_path / "missing.toml")


def test_error_no_bodies():
    assert "at least one body" in _error('gravity = [0.0, -9.81]\n')


def test_dumps_values():
    text = scenefile.dumps({"bodies": [{"name": "a b", "kind": "rigid", "mass": np.float64(2), "inertia": 1,
                                        "com": [0.0, 1e-300]}]}, initial={"hold": None})
    assert 'name = "a b"' in text and "mass = 2.0" in text and "1e-300" in text and 'hold = "none"' in text


def test_native_integrator_names_are_accepted():
    from ukflex.run.simulate import NATIVE_METHODS

    for m in NATIVE_METHODS:
        assert scenefile.loads(TINY.replace('method = "DOP853"', f'method = "{m}"')).solver["method"] == m
