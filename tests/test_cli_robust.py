"""CLI robustness: every user error is one line on stderr with exit status 2, checked before any
work; output folders never collide or escape; `ukflex list` shows every parameter."""

import os
import time
from pathlib import Path

import pytest

from ukflex.cli import main
from ukflex.model.scenes import SCENES, scene_parameters

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = (ROOT / "examples" / "pendulum.toml").read_text()


def run(capsys, *argv):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse: argument errors exit 2 with one line
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, *argv, match=""):
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2, (code, err)
    assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err
    assert match in lines[0], lines[0]
    return lines[0]


@pytest.fixture()
def cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_builtin_and_file_of_the_same_name_do_not_collide(cwd, capsys):
    (cwd / "pendulum.toml").write_text(PENDULUM)
    assert run(capsys, "run", "pendulum", "--t-end", "0.01", "--no-plot")[0] == 0
    assert run(capsys, "run", "pendulum.toml", "--t-end", "0.01", "--no-plot")[0] == 0
    assert run(capsys, "run", "pendulum", "--t-end", "0.01", "--no-plot", "--param", "length=2.0")[0] == 0
    folders = sorted(p.name for p in (cwd / "results").iterdir())
    assert folders == ["pendulum", "pendulum-toml", "pendulum_length-2.0"]
    # another file with the same stem elsewhere gets its own folder; a rerun reuses its own
    (cwd / "other").mkdir()
    (cwd / "other" / "pendulum.toml").write_text(PENDULUM)
    assert run(capsys, "run", "other/pendulum.toml", "--t-end", "0.01", "--no-plot")[0] == 0
    assert run(capsys, "run", "pendulum.toml", "--t-end", "0.01", "--no-plot")[0] == 0
    assert sorted(p.name for p in (cwd / "results").iterdir()) == sorted(folders + ["pendulum-toml-2"])


def test_scene_names_stay_inside_the_output_folder(cwd, capsys):
    (cwd / "dots.toml").write_text(PENDULUM + '\n[scene]\nname = ".."\n')
    one_line_error(capsys, "run", "dots.toml", "--no-plot", match="not starting with a dot")
    (cwd / "my scene.toml").write_text(PENDULUM)  # spaces in the file name
    code, out, err = run(capsys, "run", "my scene.toml", "--t-end", "0.01", "--no-plot")
    assert code == 0, err
    assert (cwd / "results" / "my_scene-toml" / "my_scene.csv").exists()
    assert sorted(os.listdir(cwd)) == ["dots.toml", "my scene.toml", "results"]


def test_unwritable_output_fails_before_running(cwd, capsys):
    (cwd / "file").write_text("x")
    t = time.perf_counter()
    one_line_error(capsys, "run", "slider_crank", "--t-end", "5", "--out", cwd / "file" / "sub", match="--out")
    one_line_error(capsys, "run", "slider_crank", "--t-end", "5", "--out", cwd / "file", match="not a directory")
    one_line_error(capsys, "run", "slider_crank", "--out", "/dev/null", match="not a directory")
    one_line_error(capsys, "bench", "table1", "--out", cwd / "file", match="not a directory")
    assert time.perf_counter() - t < 5.0  # nothing was simulated (5 s of slider-crank takes minutes)
    if os.geteuid() != 0:  # root writes anywhere
        ro = cwd / "ro"
        ro.mkdir(mode=0o500)
        one_line_error(capsys, "run", "pendulum", "--out", ro, match="not writable")


@pytest.mark.parametrize("argv, match", [
    (["run", "pendulum", "--samples", "1e11"], "not an integer"),
    (["run", "pendulum", "--samples", "100000000000"], "too large"),
    (["run", "pendulum", "--frames", "99999999999"], "too large"),
    (["run", "pendulum", "--method", "nope"], "unknown method 'nope'"),
    (["run", "no_such_scene"], "neither a built-in scene"),
    (["run", "missing.toml"], "cannot read"),
    (["run", "/dev/zero"], "not a regular file (a device)"),
    (["run", "/"], "not a regular file (a directory)"),
    (["run", "pendulum", "--param", "lenght=2"], "lenght"),
    (["export", "nope"], "invalid choice"),
    (["nope"], "invalid choice"),
])
def test_user_errors_are_one_line(cwd, capsys, argv, match):
    one_line_error(capsys, *argv, match=match)


def test_export_to_a_directory_or_special_file(cwd, capsys):
    one_line_error(capsys, "export", "pendulum", "-o", cwd, match="is a directory")
    one_line_error(capsys, "export", "pendulum", "-o", "/dev/zero", match="not a regular file")
    one_line_error(capsys, "export", "pendulum", "-o", cwd / "no" / "such.toml", match="does not exist")
    assert run(capsys, "export", "pendulum", "-o", cwd / "p.toml")[0] == 0 and (cwd / "p.toml").exists()


def test_fifo_is_refused_without_blocking(cwd, capsys):
    os.mkfifo(cwd / "fifo.toml")
    one_line_error(capsys, "run", "fifo.toml", match="a FIFO")


@pytest.mark.parametrize("text, match", [
    ("a = " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply"),
    ("bodies = " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply"),
    (PENDULUM.replace("mass = 1.0", "mass = 1" + "0" * 400), "[[bodies]] #1 (line 9): mass: integer 1000000000...(401 digits) is out of range"),
    (PENDULUM.replace("point = [-0.5, 0.0]", "point = [-0.5, 10000000000000000000]"), "b.point[1]: integer"),
    (PENDULUM.replace('kind = "rigid"', "kind = []"), '[[bodies]] #1 (line 9): kind: must be a string'),
    (PENDULUM.replace('kind = "revolute"', "kind = {a = 1}"), "[[joints]] #1"),
    (PENDULUM.replace("[solver]", "[solver]\nsamples = 100000000000"), "too large"),
    ("\xff", "TOML"),
])
def test_hostile_scene_files(cwd, capsys, text, match):
    p = cwd / "bad.toml"
    p.write_text(text)
    line = one_line_error(capsys, "run", p, "--no-plot", "--t-end", "0.01", match=match)
    assert "bad.toml" in line


def test_toml_error_path_is_linear_in_file_size():
    from ukflex.model import scenefile

    body = '[[bodies]]\nname = "b{i}"\nkind = "rigid"\nmass = 1.0\ninertia = 1.0\n\n'
    bad = '[[joints]]\nkind = "revolute"\na = { body = "nope", point = [0, 0] }\nb = { body = "b0", point = [0, 0] }\n'

    def cost(n):
        text = "".join(body.format(i=i) for i in range(n)) + bad
        best = float("inf")
        for _ in range(3):
            t = time.perf_counter()
            with pytest.raises(scenefile.SceneFileError, match=r"\[\[joints\]\] #1"):
                scenefile.loads(text, "x.toml")
            best = min(best, time.perf_counter() - t)
        return best

    small, large = cost(300), cost(2400)
    assert large < 2.0 and large / small < 8 * 2.5  # 8x the entries: linear (quadratic would be 64x)


def test_list_shows_every_parameter_untruncated(capsys):
    code, out, err = run(capsys, "list")
    assert code == 0
    assert "DESIGN" not in out and "/work" not in out
    for name, fn in SCENES.items():
        assert f"\n{name}: " in "\n" + out
        for p, default in scene_parameters(fn):
            assert f"--param {p}={default!r}" in out


def test_one_name_per_concept():
    names = {p for fn in SCENES.values() for p, _ in scene_parameters(fn)}
    for old in ("beam", "g", "flexible_coupler", "crank", "coupler", "rocker", "ground"):
        assert old not in names
    for gravity_name in ("gravity",):
        assert all(gravity_name in [p for p, _ in scene_parameters(fn)] for fn in SCENES.values())


