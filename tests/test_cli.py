"""The command line: scene files end to end, errors, help, progress, export, animation geometry."""

import csv
import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ukflex
from ukflex import cli, scenes
from ukflex.results import outputs
from ukflex.results.animate import MechanismDrawer

ENV = dict(os.environ, MPLBACKEND="Agg")
EXAMPLES = os.path.join(os.path.dirname(__file__), os.pardir, "examples")

TINY = """
# a tiny flexible scene: the paper's coupler, simply supported, under gravity
gravity = [0.0, -9.81]

[[bodies]]
name = "beam"
kind = "beam"
length = 0.3048
elements = 2
theory = "euler-bernoulli"
density = 7834.56
youngs_modulus = 2.06843e11
section = { shape = "circular", diameter = 0.00635 }
frame = "pinned-pinned"

[[joints]]
kind = "revolute"
name = "pin"
a = { body = "ground", point = [0.0, 0.0] }
b = { body = "beam", xi = 0.0 }

[[joints]]
kind = "point_on_line"
name = "roller"
point = { body = "beam", xi = 1.0 }
line = { body = "ground", point = [0.0, 0.0], angle = 0.0 }

[solver]
t_end = 0.004
method = "DOP853"
rtol = 1e-6
samples = 41

[output]
plot = ["v(beam, 0.5)/L", "residual.position"]
deform_scale = 100
frames = 12
"""


def _line(start):
    """1-based line number of the first line of TINY starting with ``start``."""
    return 1 + [i for i, l in enumerate(TINY.splitlines()) if l.startswith(start)][0]


def read_csv(path):
    """Header and columns of a CSV file (standard quoting: expressions like v(b, 0.5) contain commas)."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    cols = np.array(rows[1:], dtype=float).T
    return rows[0], dict(zip(rows[0], cols))


def ukflex_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "ukflex", *map(str, args)], capture_output=True, text=True, env=ENV,
                          cwd=cwd)


@pytest.fixture()
def tiny(tmp_path):
    p = tmp_path / "tiny.toml"
    p.write_text(TINY)
    return p


def test_run_scene_file_end_to_end(tiny, tmp_path):
    out = tmp_path / "out"
    r = ukflex_cli("run", tiny, "--out", out, "--animate")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""  # piped: no progress line
    assert "scene tiny" in r.stdout and "settings: method DOP853, rtol 1e-06" in r.stdout and "max ||Phi||" in r.stdout
    for f in ("tiny.csv", "tiny.npz", "tiny_outputs.csv", "tiny.png", "tiny.gif"):
        assert (out / f).stat().st_size > 0, f
    data = np.genfromtxt(out / "tiny.csv", delimiter=",", names=True)
    assert data["t"].size == 41 and data["t"][-1] == pytest.approx(0.004)
    assert "beamqf0" in data.dtype.names  # genfromtxt drops the dot of beam.qf0
    head, o = read_csv(out / "tiny_outputs.csv")
    assert head == ["t", "v(beam, 0.5)/L", "residual.position"]
    # the beam sags under its weight: the midpoint moves down, and it starts undeformed
    v = o["v(beam, 0.5)/L"]
    assert v[0] == 0.0 and v.min() < -1e-6
    npz = np.load(out / "tiny.npz")
    assert npz["q"].shape == (3 + 6, 41) and str(npz["method"]) == "DOP853"
    from PIL import Image

    gif = Image.open(out / "tiny.gif")
    assert gif.n_frames == 12  # [output] frames


def test_run_command_line_overrides_file(tiny, tmp_path):
    r = ukflex_cli("run", tiny, "--out", tmp_path, "--method", "RK45", "--t-end", "0.002", "--samples", "5",
                   "--plot", "beam.theta", "--no-plot")
    assert r.returncode == 0, r.stderr
    assert "settings: method RK45, rtol 1e-06" in r.stdout and "\nRK45 (uk): status 0" in r.stdout
    head, o = read_csv(tmp_path / "tiny_outputs.csv")
    assert head == ["t", "beam.theta"] and o["t"][-1] == pytest.approx(0.002)
    assert not (tmp_path / "tiny.png").exists()


def test_run_default_output_folder(tiny, tmp_path):
    r = ukflex_cli("run", tiny, "--t-end", "0.001", "--no-plot", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    # a scene file's default folder is results/STEM-toml (a built-in scene's is results/NAME)
    assert (tmp_path / "results" / "tiny-toml" / "tiny.csv").exists()


@pytest.mark.parametrize(
    "edit, expected",
    [
        (("elements = 2", "elemnts = 2"), [f"[[bodies]] #1 (line {_line('[[bodies]]')})", "'elemnts'", "body 'beam'"]),
        (('b = { body = "beam", xi = 0.0 }', 'b = { body = "bean", xi = 0.0 }'), ["[[joints]] #1", "'bean'"]),
        (('method = "DOP853"', 'method = "RK4"'), ["[solver] method", "'RK4'"]),
        (("rtol = 1e-6", "rtol = 0"), ["[solver] rtol"]),
        (("[solver]", "[slover]"), ["'slover'", "did you mean 'solver'"]),
        (('section = { shape = "circular", diameter = 0.00635 }', 'section = { shape = "round", diameter = 1 }'),
         ["[[bodies]] #1", "'round'"]),
        (("theory = \"euler-bernoulli\"", "theory = euler"), ["TOML syntax error", f"line {_line('theory =')}"]),
    ],
)
def test_run_bad_scene_file_errors(tmp_path, edit, expected):
    p = tmp_path / "bad.toml"
    old, new = edit
    assert old in TINY
    p.write_text(TINY.replace(old, new))
    r = ukflex_cli("run", p, "--out", tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stderr and r.stderr.count("\n") == 1
    assert str(p) in r.stderr
    for e in expected:
        assert e in r.stderr, (e, r.stderr)


def test_run_bad_output_expression_fails_before_simulating(tiny, tmp_path):
    r = ukflex_cli("run", tiny, "--out", tmp_path, "--plot", "v(crank, 0.5)")
    assert r.returncode == 2 and "'crank' is not a beam" in r.stderr
    assert not (tmp_path / "tiny.csv").exists()


def test_run_unknown_scene_and_param_on_file(tiny, tmp_path):
    r = ukflex_cli("run", "no_such_scene")
    assert r.returncode == 2 and "neither a built-in scene" in r.stderr
    r = ukflex_cli("run", tmp_path / "missing.toml")
    assert r.returncode == 2 and "cannot read" in r.stderr
    r = ukflex_cli("run", tiny, "--param", "elements=3")
    assert r.returncode == 2 and "--param applies to built-in scenes only" in r.stderr


def test_run_builtin_with_plot_expressions(tmp_path):
    r = ukflex_cli("run", "pendulum", "--t-end", "0.3", "--method", "DOP853", "--out", tmp_path, "--plot", "rod.theta",
                   "--plot", "d:rod.theta", "--plot", "energy")
    assert r.returncode == 0, r.stderr
    head, o = read_csv(tmp_path / "pendulum_outputs.csv")
    assert head == ["t", "rod.theta", "d:rod.theta", "energy"]
    assert np.ptp(o["energy"]) < 1e-6 < np.ptp(o["rod.theta"])  # conservative pendulum


def test_export_then_run(tmp_path):
    p = tmp_path / "sc.toml"
    r = ukflex_cli("export", "slider_crank", "--param", "elements=2", "-o", p, "--t-end", "0.002")
    assert r.returncode == 0, r.stderr
    from ukflex.model import scenefile

    assert scenefile.load(p).scene.to_dict() == scenes.slider_crank(elements=2).to_dict()
    r = ukflex_cli("run", p, "--out", tmp_path, "--no-plot")
    assert r.returncode == 0, r.stderr
    assert "scene slider_crank: n = 12 coordinates" in r.stdout
    assert "\nauto: RADAU5M, fixed step" in r.stdout  # the exported file runs the default chooser
    r = ukflex_cli("run", "pendulum", "--t-end", "0.1", "--out", tmp_path / "p", "--no-plot")
    assert r.returncode == 0, r.stderr
    assert "\nauto: DOPRI5, rtol 3e-07 (no elastic mode" in r.stdout


def test_help_of_every_command():
    r = ukflex_cli("--help")
    assert r.returncode == 0
    for cmd in ("paper", "run", "list", "export", "bench"):
        assert cmd in r.stdout
    for args, words in [
        (("paper",), ["--out", "--table", "--repeats", "Table 1", "Fig. 4"]),
        (("run",), ["SCENE", "--animate", "--plot", "--method", "--rtol", "--atol", "--t-end", "--out", "v(BEAM, XI)"]),
        (("export",), ["NAME", "--output"]),
        (("list",), ["built-in"]),
        (("bench",), ["work-precision", "elements", "table1"]),
        (("bench", "work-precision"), ["--budget", "--rtols", "--methods", "--formulations", "--native", "--quick"]),
        (("bench", "elements"), ["--elements", "--cases", "--budget"]),
        (("bench", "table1"), ["--mode", "--repeats"]),
    ]:
        r = ukflex_cli(*args, "--help")
        assert r.returncode == 0, args
        for w in words:
            assert w in r.stdout, (args, w)


def test_progress_only_on_a_terminal():
    class Tty(io.StringIO):
        def isatty(self):
            return True

    assert cli.Progress(stream=io.StringIO()).callback("x", 1.0) is None  # piped: quiet
    s = Tty()
    p = cli.Progress(stream=s, delay=0.0, interval=0.0, use_tqdm=False)
    cb = p.callback("run", 0.1)
    cb(0.05)
    assert "t = 0.05 / 0.1 s ( 50.0 %)" in s.getvalue()
    p.done()
    assert s.getvalue().endswith("\r")


def test_simulate_progress_callback_reaches_t_end():
    ts = []
    res = ukflex.simulate(scenes.pendulum(), 0.2, method="RK45", progress=ts.append)
    assert res.success and ts[0] == 0.0 and ts[-1] == pytest.approx(0.2)
    assert np.all(np.diff(ts) > 0)


def test_outputs_expressions():
    system = scenes.slider_crank(elements=2).build()
    res = ukflex.simulate(system, 0.002, method="DOP853", t_eval=np.linspace(0, 0.002, 5))
    _, v = outputs.evaluate(res, "v(coupler, 0.5)")
    _, vl = outputs.evaluate(res, "v(coupler,0.5)/L")
    np.testing.assert_allclose(vl, v / 0.3048)
    # world position of the slider end: on the X axis (point-on-line), at the crank tip for xi = 0
    _, y1 = outputs.evaluate(res, "y(coupler, 1)")
    assert np.abs(y1).max() < 1e-9
    _, x0 = outputs.evaluate(res, "x(coupler, 0)")
    np.testing.assert_allclose(x0, 0.1524 * np.cos(res.coordinate("crank.theta")), atol=1e-9)
    for bad in ("v(coupler, 2)", "w(coupler, 0.5)", "psi(coupler, 0.5)/L", "residual.energy", "nope"):
        with pytest.raises(ValueError):
            outputs.validate(system, bad)


def test_animation_draws_the_deformed_beam_from_its_shape_functions():
    system = scenes.pinned_beam(elements=2).build()
    q = system.q0.copy()
    sl = system.elastic_slice("beam")
    q[sl] = np.linspace(-1e-3, 2e-3, sl.stop - sl.start)  # some deformation
    S, _ = system.beam_shape("beam", 0.5)
    u, v = np.asarray(S) @ q[sl]
    for scale in (1.0, 10.0):
        d = MechanismDrawer(system, deform_scale=scale)
        pts = d.body_polyline(q, "beam")
        assert pts.shape[0] > 10  # sampled along the axis, not a straight two-point line
        mid = pts[pts.shape[0] // 2]  # xi = 0.5 is a sample
        np.testing.assert_allclose(mid, [0.3048 * 0.5 + scale * u, scale * v], atol=1e-12)


def studies_cli(*args):
    """``python -m studies ...`` from the repository's root (the studies are not in the wheel)."""
    return subprocess.run([sys.executable, "-m", "studies", *map(str, args)], capture_output=True, text=True, env=ENV,
                          cwd=Path(__file__).resolve().parents[1])


def test_stability_and_crosscheck_commands(tmp_path):
    """The studies that had their own command lines run from the studies' entry point."""
    r = studies_cli("stability", "--out", tmp_path, "--quick", "--case", "mass_ratio_1e6")
    assert r.returncode == 0, r.stderr
    md = (tmp_path / "stability.md").read_text()
    assert "mass_ratio_1e6" in md and "Generated by `python -m studies stability --out DIR --quick`" in md
    r = studies_cli("crosscheck", "timing", "--t-end", "0.001", "--theory", "euler-bernoulli")
    assert r.returncode == 0, r.stderr
    assert "### euler-bernoulli" in r.stdout and "| CP, partition every call |" in r.stdout
    # a long study reports each case on stderr as it starts it (its tables stay on stdout)
    started = [line for line in r.stderr.splitlines() if line.startswith("[crosscheck ")]
    assert [line.split("] ")[1] for line in started] == [
        "timing euler-bernoulli: UK (NumPy, eigh + pinv)", "timing euler-bernoulli: CP, partition once",
        "timing euler-bernoulli: CP, partition every call"], r.stderr
    bad = studies_cli("crosscheck", "nope")
    assert bad.returncode == 2 and "invalid choice" in bad.stderr


def test_every_body_kind_draws_itself_from_the_core():
    """The drawing asks the core (``System.core.outline``): a rigid crank is the star from its
    centre of mass to its two attachment points (the bar from pivot to tip), a point mass its
    position, and a spatial body is refused by name (the 3D animation draws it)."""
    s = ukflex.Scene()
    crank = s.rigid_body("crank", mass=1.0, inertia=0.1, com=(0.05, 0.0), angle=0.3)
    bob = s.point_mass("bob", mass=1.0, position=(0.1 * np.cos(0.3), 0.1 * np.sin(0.3) - 0.2))
    s.revolute(s.ground.point(0.0, 0.0), crank.point(0.0, 0.0))
    s.distance(crank.point(0.1, 0.0), bob.point(), length=0.2)
    system = s.build()
    q = system.q0
    d = MechanismDrawer(system)
    c, sn = np.cos(q[2]), np.sin(q[2])
    com, pivot, tip = [0.05 * c, 0.05 * sn], [0.0, 0.0], [0.1 * c, 0.1 * sn]
    np.testing.assert_allclose(d.body_polyline(q, "crank"), [com, pivot, com, com, tip, com], atol=1e-15)
    np.testing.assert_allclose(d.body_polyline(q, "bob"), [q[3:5]], atol=0)
    np.testing.assert_allclose(d.joint_positions(q), [[0.0, 0.0]], atol=1e-15)  # the revolute only
    three = ukflex.SpatialScene()
    three.rigid_body("top", mass=1.0, inertia=[1.0, 1.0, 1.0])
    with pytest.raises(ukflex.InvalidArgumentError, match="planar"):
        ukflex.System(three).core.outline("top", ukflex.System(three).q0)
