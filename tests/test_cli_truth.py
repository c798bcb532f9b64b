"""The command line tells the truth (issue 33): what it prints matches what it ran, a base install
(no matplotlib) runs, native runs report progress from Rust, the documented examples behave as
documented."""

import io
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import ukflex
from ukflex import cli, scenes
from ukflex.run.simulate import NATIVE_PROGRESS_STEPS

ROOT = Path(__file__).resolve().parent.parent


def run_cli(capsys, *args):
    code = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


# ------------------------------------------------------------------------ settings, names
def test_printed_settings_are_the_users_and_auto_is_named(capsys, tmp_path):
    code, out, err = run_cli(capsys, "run", "slider_crank", "--rtol", "1e-8", "--t-end", "0.01", "--no-plot",
                             "--out", tmp_path)
    assert code == 0, err
    assert "settings: method auto, rtol 1e-08, atol 0.001 rtol" in out  # what was given, not auto's
    auto = re.search(r"^auto: RADAU5M, fixed step ([0-9.e+-]+) s, Newton tol ([0-9.e+-]+) \(stiff", out, re.M)
    assert auto, out
    assert float(auto.group(2)) != 1e-8  # auto's own Newton tolerance, named as such
    assert "rtol=1e-06" not in out


def test_method_names_any_case(capsys, tmp_path):
    code, out, err = run_cli(capsys, "run", "pendulum", "--method", "dop853", "--t-end", "0.05", "--no-plot",
                             "--out", tmp_path)
    assert code == 0, err
    assert "settings: method DOP853" in out and "\nDOP853 (uk): status 0" in out
    code, out, err = run_cli(capsys, "run", "pendulum", "--method", "radau5m", "--t-end", "0.05", "--no-plot",
                             "--out", tmp_path / "b")
    assert code == 0 and "RADAU5M (uk): status 0" in out, err
    with pytest.raises(SystemExit) as e:
        cli.main(["run", "pendulum", "--method", "dopri6"])
    assert e.value.code == 2 and "unknown method 'dopri6'" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["run", "export"])
def test_misspelt_param_lists_the_valid_names(capsys, tmp_path, command):
    code, out, err = run_cli(capsys, command, "slider_crank", "--param", "elemnts=8",
                             *(["--out", tmp_path] if command == "run" else []))
    assert code == 2
    assert "unknown parameter of scene 'slider_crank' 'elemnts'" in err
    for name in ("elements", "theory", "strain", "gravity"):
        assert f"'{name}'" in err, err


def test_version_from_the_package_metadata(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"ukflex {ukflex.__version__}"
    assert ukflex.__version__ != "0+unknown"


# ------------------------------------------------------------------------ the energy verdict
def test_energy_verdict_of_the_readme_example_is_not_a_false_gain(capsys, tmp_path):
    # README: ukflex run slider_crank --param elements=8 --plot 'v(coupler, 0.5)/L' --rtol 1e-8 (1 s, 201 samples)
    code, out, err = run_cli(capsys, "run", "slider_crank", "--param", "elements=8", "--plot", "v(coupler, 0.5)/L",
                             "--rtol", "1e-8", "--no-plot", "--out", tmp_path)
    assert code == 0, err
    line = [ln for ln in out.splitlines() if ln.startswith("energy T + V")][0]
    assert "gained energy" not in line and "lost energy" not in line
    assert "balance not judged: the 201 output samples do not resolve the driver and damping power" in line


def test_energy_verdict_still_judges_what_the_sampling_cannot_explain():
    # conservative, undriven: the balance is exact at each sample (no power to integrate)
    pend = scenes.pendulum().build()
    res = ukflex.simulate(pend, 2.0, method="DOP853", rtol=1e-10, t_eval=np.linspace(0, 2, 51))
    bal = res.sensors.energy_balance()
    assert bal["quadrature_error"] == 0.0 and "balance closes" in res.sensors.energy_line()
    # generalized-alpha with full numerical dissipation and a large step: a real loss, judged as such
    res = ukflex.simulate(pend, 2.0, method="GENALPHA", step=0.05, rho_inf=0.0, t_eval=np.linspace(0, 2, 51))
    assert "balance open: the integrator lost energy" in res.sensors.energy_line()
    # the driven slider-crank sampled at the method's steps resolves the power well enough to close
    # to within the quadrature estimate: then no "not judged" on a resolved run of a few samples per period
    sc = scenes.slider_crank().build()
    res = ukflex.simulate(sc, 0.02, method="DOPRI5", rtol=1e-10)
    bal = res.sensors.energy_balance()
    assert bal["quadrature_error"] < 1e-3 * bal["scale"]
    assert "not judged" not in res.sensors.energy_line()


# ------------------------------------------------------------------------ a base install
@pytest.fixture()
def no_matplotlib(monkeypatch):
    for name in list(sys.modules):
        if name == "matplotlib" or name.startswith("matplotlib."):
            monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib -> ImportError


def test_run_without_matplotlib_skips_the_plot_with_a_note(capsys, tmp_path, no_matplotlib):
    code, out, err = run_cli(capsys, "run", "pendulum", "--t-end", "0.05", "--out", tmp_path)
    assert code == 0, err
    notes = [ln for ln in out.splitlines() if ln.startswith("note: no plot:")]
    assert len(notes) == 1 and "pip install matplotlib" in notes[0]
    assert (tmp_path / "pendulum.csv").exists() and not (tmp_path / "pendulum.png").exists()
    # --animate without matplotlib: refused before the run (tests/test_package.py)


def test_geometric_study_checks_for_matplotlib_first(capsys, tmp_path, no_matplotlib):
    from studies.__main__ import main

    assert main(["geometric", "--out", str(tmp_path), "--quick"]) == 2
    assert "need matplotlib" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []  # nothing ran


def test_every_extra_named_in_a_hint_exists():
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    named = {"plot"}  # require()'s default
    for path in (ROOT / "python" / "ukflex").rglob("*.py"):
        text = path.read_text()
        named |= set(re.findall(r"""extra\s*=\s*["'](\w+)["']""", text))
        named |= set(re.findall(r"ukflex\[(\w+)\]", text))
    assert named and named <= set(extras), named - set(extras)
    with pytest.raises(ukflex.MissingDependencyError, match=r"pip install nonexistent_mod_x \(one of ukflex's "
                                                            r"extra \[plot\]\)"):
        from ukflex.errors import require

        require("nonexistent_mod_x", "a test")


# ------------------------------------------------------------------------ progress from Rust
def test_native_progress_fires_during_the_run_with_increasing_t():
    sc = scenes.slider_crank().build()
    ts = []
    res = ukflex.simulate(sc, 0.1, method="DOPRI5", rtol=1e-8, progress=ts.append)
    steps = res.extra["naccept"]
    assert res.success and steps >= 2000, steps
    during = ts[:-1]  # the last call is the end of the run
    assert len(during) >= steps // NATIVE_PROGRESS_STEPS - 1 and len(during) >= 10, (len(during), steps)
    assert np.all(np.diff(ts) > 0) and 0 < during[0] < during[-1] < 0.1 and ts[-1] == pytest.approx(0.1)


def test_native_progress_every_step_from_the_core():
    pend = ukflex.scenes.pendulum().build()
    ts = []
    out = pend.core.integrate(0.0, np.concatenate([pend.q0, pend.qd0]), 0.5, "DOPRI5", 1e-8, progress=ts.append,
                              progress_steps=1)
    assert len(ts) == out["naccept"] and ts == list(out["t"][1:])  # one report per accepted step, at its time
    with pytest.raises(ukflex.InvalidArgumentError, match="progress_steps"):
        pend.core.integrate(0.0, np.concatenate([pend.q0, pend.qd0]), 0.5, "DOPRI5", progress=ts.append,
                            progress_steps=0)


def test_native_progress_exception_ends_the_run():
    pend = scenes.pendulum().build()

    class Stop(Exception):
        pass

    def stop(t):
        raise Stop(t)

    with pytest.raises(Stop):
        ukflex.simulate(pend, 10.0, method="RADAU5M", progress=stop)
    with pytest.raises(ukflex.InvalidArgumentError, match="progress"):
        ukflex.simulate(pend, 1.0, method="DOPRI5", progress=3)


@pytest.mark.parametrize("use_tqdm", [False, True])
def test_cli_progress_shows_a_native_run(use_tqdm):
    pytest.importorskip("tqdm") if use_tqdm else None
    stream = io.StringIO()
    p = cli.Progress(enabled=True, stream=stream, delay=0.0, interval=0.0, use_tqdm=use_tqdm)
    res = ukflex.simulate(scenes.slider_crank().build(), 0.05, method="DOPRI5", rtol=1e-8,
                          progress=p.callback("slider_crank", 0.05))
    p.done()
    shown = [float(x) for x in re.findall(r"t = ([0-9.e+-]+) / 0.05 s", stream.getvalue())]
    assert res.success and len(shown) >= 5 and np.all(np.diff(shown) > 0), stream.getvalue()[-300:]


# ------------------------------------------------------------------------ documented examples
def test_docs_max_wall_time_example_stops_on_wall_time():
    # docs/solve-ivp.md, "Stops and partial results"
    system = ukflex.scenes.pendulum().build()
    res = ukflex.simulate(system, 1e4, method="RK45", max_wall_time=0.5)
    assert res.status == -1 and res.stop["cause"] == "max_wall_time", res.message
    assert 1.0 < res.t[-1] < 1e4 and "work budget max_wall_time exhausted" in res.message
    # the step budget's own stop, as the docs say: t_end = 1e9 cannot be reached within max_steps
    res = ukflex.simulate(system, 1e9, method="RK45", max_wall_time=0.5)
    assert res.stop["cause"] == "max_steps" and "cannot suffice" in res.message


def test_readme_cli_examples_run_as_documented(capsys, tmp_path, monkeypatch):
    # README, "Command line and scene files": the quick ones as written (outputs into tmp_path;
    # the slider-crank one is test_energy_verdict_of_the_readme_example_is_not_a_false_gain;
    # paper and bench: tests/test_api.py, tests/test_cli.py with shorter settings)
    block = (ROOT / "README.md").read_text().split("## Command line and scene files")[1].split("```")[1]
    lines = [ln.split("#")[0].strip() for ln in block.splitlines()]
    pend = [ln for ln in lines if ln.startswith("ukflex run pendulum")][0]
    assert pend == "ukflex run pendulum --t-end 2 --method DOP853 --plot rod.theta --plot energy"
    monkeypatch.setenv("MPLBACKEND", "Agg")
    code, out, err = run_cli(capsys, *pend.split()[1:], "--out", tmp_path / "p")
    assert code == 0 and (tmp_path / "p" / "pendulum.png").exists(), err
    assert "balance closes" in out  # a conservative pendulum at DOP853
    export = [ln for ln in lines if ln.startswith("ukflex export")][0]
    assert export == "ukflex export four_bar > my_scene.toml"
    code, out, err = run_cli(capsys, "export", "four_bar", "-o", tmp_path / "my_scene.toml")
    assert code == 0, err
    code, out, err = run_cli(capsys, "run", tmp_path / "my_scene.toml", "--no-plot", "--out", tmp_path / "f")
    assert code == 0 and "scene four_bar" in out, err
