"""The findings of issue 28 (the campaign against expressions, dense output, per-call methods, FE
input and sweeps), each run as a user would in its own process, printed as a Markdown table:
exit status (-11: segmentation fault, -6: abort), the last line of output, wall time.

``python -m fuzz.findings`` from the repository root (about a minute; ``python -m fuzz.findings 1 4``
runs the findings whose label starts with "1" or "4"). docs/robustness.md keeps its output for the
code before the fix (same script) and after.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

PY = sys.executable
PRE = "import ukflex, numpy as np, warnings\nwarnings.simplefilter('ignore')\n"
DRIVER = "s = ukflex.Scene(); p = s.point_mass('p', mass=1.0); s.coordinate_driver(p.point(), 'x', {expr})\n"


def drv(e: str) -> str:
    """A point mass driven along x by the expression ``e`` (Python text)."""
    return DRIVER.format(expr=e) + "print('accepted')"


PEND = "sy = ukflex.System(ukflex.scenes.pendulum())\n"
ANCF = ("s = ukflex.Scene(gravity=(0.0, -9.81)); b = s.cable('beam', length=1.0, section=ukflex.Rectangular(0.02, 0.01), "
        "density=7850.0, youngs_modulus=2.1e11, elements=2); s.weld(s.ground.frame(), b.at(0.0)); sy = s.build()\n")
CRANK = "sy = ukflex.System(ukflex.scenes.slider_crank(elements=2, strain='nonlinear'))\n"
CASES = [
 ("1 '(' * 30000 + 't' + ')' * 30000", drv("'(' * 30000 + 't' + ')' * 30000")),
 ("1 '-' * 30000 + 't'", drv("'-' * 30000 + 't'")),
 ("1 '(' * 30000 unterminated", drv("'(' * 30000")),
 ("1 't+' * 100000 + 't'", drv("'t+' * 100000 + 't'")),
 ("1 ukflex run f.toml with a deep motion", "CLI"),
 ("2 't^' * 10000 + 't'", drv("'t^' * 10000 + 't'")),
 ("2 product of 1000 factors '(t+1)*' (6 kB)", drv("'*'.join(['(t+1)'] * 1000)")),
 ("2 tower 't^' * 1000 + 't' (2 kB)", drv("'t^' * 1000 + 't'")),
 ("2 'sin(' * 1000 + 't' + ')' * 1000", drv("'sin(' * 1000 + 't' + ')' * 1000")),
 ("2 one evaluation of 'sin(' * 150 (751 chars)", "import json, timeit\nm = json.dumps({'kind': 'expression', 'expression': 'sin(' * 150 + 't' + ')' * 150})\nt = np.array([0.3])\nukflex._core.motion_values(m, t)\nn = 20\nprint('%.3g ms per evaluation' % (1e3 * timeit.timeit(lambda: ukflex._core.motion_values(m, t), number=n) / n))"),
 ("3 dense_eval with part_len [2] (one too long)", "print(ukflex._core.dense_eval('DOPRI5', np.zeros((1, 3)), np.zeros((1, 2)), [2], np.array([0.0])))"),
 ("3 dense_eval with part_len [2**63, 2**63]", "print(ukflex._core.dense_eval('DOPRI5', np.zeros((1, 3)), np.zeros((1, 0)), [2**63, 2**63], np.array([0.0])))"),
 ("3 DenseSolution GENALPHA with short y", "from ukflex.simulate import DenseSolution\nsol = DenseSolution('GENALPHA', np.array([[0.0, 1.0, 1.0]]), np.zeros((1, 3)), [1, 1, 1])\nprint(sol(0.5))"),
 ("4 System.project(-1e308, q0, qd0) (point mass driven x = 2 t)", "s = ukflex.Scene(); p = s.point_mass('p', mass=1.0); s.coordinate_driver(p.point(), 'x', '2*t'); sy = s.build()\nq, qd, rep = sy.project(-1e308, sy.q0, sy.qd0); print(q, rep['position_residual'])"),
 ("4 residual_norms with NaN times", PEND + "print(sy.core.residual_norms(np.array([np.nan]), sy.q0[:, None], sy.qd0[:, None]))"),
 ("4 phi_t(1e308) (point mass driven x = t^2)", "s = ukflex.Scene(); p = s.point_mass('p', mass=1.0); s.coordinate_driver(p.point(), 'x', 't^2'); sy = s.build(); print(sy.phi_t(1e308))"),
 ("4 tangent_stiffness, q = 1e300 (FFRF, nonlinear)", CRANK + "q = sy.q0.copy(); q[3:] = 1e300; k = sy.tangent_stiffness('coupler', q); print(np.isfinite(k).all())"),
 ("4 axial_forces, q = 1e300 (FFRF, nonlinear)", CRANK + "q = sy.q0.copy(); q[3:] = 1e300; print(sy.axial_forces('coupler', q))"),
 ("4 ANCF beam_point at q = 0", ANCF + "print(sy.beam_point('beam', 0.5, np.zeros(sy.n_coords)))"),
 ("4 ANCF tangent_stiffness at q = 0", ANCF + "print(np.isfinite(sy.tangent_stiffness('beam', np.zeros(sy.n_coords))).all())"),
 ("4 sensors of a pendulum with angular_velocity=-1e150 (mass 1e13, length 1e-3)", "res = ukflex.simulate(ukflex.scenes.pendulum(angular_velocity=-1e150, mass=1e13, length=1e-3), 1e-160, method='DOPRI5', t_eval=[0.0]); print(res.sensors.reaction('pivot'))"),
 ("4 dense_eval returns NaN (NaN in the record)", "print(ukflex._core.dense_eval('DOPRI5', np.array([[0.0, 1.0, 1.0]]), np.full((1, 5), np.nan), [1]*5, np.array([0.5])))"),
 ("5 'sign(log(t - 1))'", "s = ukflex.Scene(); w = s.rigid_body('w', mass=1.0, inertia=0.1); s.revolute(s.ground.point(0.0, 0.0), w.point(0.0, 0.0)); s.angle_driver(w.frame(), 'sign(log(t - 1))')\nr = ukflex.simulate(s, 0.1); print('status', r.status, 'theta', r.coordinate('w.theta')[-1])"),
 ("5 '1e-170/(1e-170*(t+1))' f', f'' at t = 0", "import json\nprint(ukflex._core.motion_values(json.dumps({'kind': 'expression', 'expression': '1e-170/(1e-170*(t+1))'}), np.array([0.0]))[:, 0])"),
 ("6 System.body_info('nope')", PEND + "sy.body_info('nope')"),
 ("6 res.max_residual('nope')", "res = ukflex.simulate(ukflex.scenes.pendulum(), 0.01); res.max_residual('nope')"),
 ("6 res.sensors.reaction('nope')", "res = ukflex.simulate(ukflex.scenes.pendulum(), 0.01); res.sensors.reaction('nope')"),
 ("6 Scene.from_dict on 1000-deep lists", "d = ukflex.scenes.pendulum().to_dict(); x = []\nfor _ in range(1000): x = [x]\nd['bodies'][0]['mass'] = x\nukflex.Scene.from_dict(d)"),
 ("6 simulate(max_steps=10**23)", "r = ukflex.simulate(ukflex.scenes.pendulum(), 0.01, method='DOPRI5', max_steps=10**23); print('status', r.status, r.message)"),
 ("6 scenes.chain(length=1e300)", "ukflex.System(ukflex.scenes.chain(length=1e300))"),
 ("6 fe.from_mesh(poisson_ratio=0.5)", "from ukflex import fe\npts = np.array([[0,0],[1,0],[1,1],[0,1]], float); cells = np.array([[0,1,2],[0,2,3]])\nd = fe.from_mesh(pts, cells=cells, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.5, interfaces={'a': 0, 'b': 2}, modes=2); print('frequencies', d.info['frequencies'])"),
 ("6 fe.from_mesh with a cell index out of range", "from ukflex import fe\npts = np.array([[0,0],[1,0],[1,1],[0,1]], float); cells = np.array([[0,1,2],[0,2,7]])\nfe.from_mesh(pts, cells=cells, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3, interfaces={'a': 0, 'b': 2}, modes=2)"),
 ("6 fe.from_mesh with negative cell indices", "from ukflex import fe\npts = np.array([[0,0],[1,0],[1,1],[0,1]], float); cells = np.array([[0,1,2],[0,2,-1]])\nd = fe.from_mesh(pts, cells=cells, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3, interfaces={'a': 0, 'b': 2}, modes=2); print('accepted')"),
 ("6 fe.from_mesh with float cell indices", "from ukflex import fe\npts = np.array([[0,0],[1,0],[1,1],[0,1]], float); cells = np.array([[0,1,2.5],[0,2,3]])\nd = fe.from_mesh(pts, cells=cells, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3, interfaces={'a': 0, 'b': 2}, modes=2); print('accepted')"),
 ("6 pickle state without 'settings'", "import pickle\nsy = ukflex.System(ukflex.scenes.pendulum()); st = sy.__getstate__(); del st['settings']\nnew = ukflex.System.__new__(ukflex.System); new.__setstate__(st)"),
 ("6 pickle state with settings {'nope': ()}", "sy = ukflex.System(ukflex.scenes.pendulum()); st = sy.__getstate__(); st['settings'] = {'nope': ()}\nnew = ukflex.System.__new__(ukflex.System); new.__setstate__(st)"),
 ("6 pickle state with a wrong-shape q0", "sy = ukflex.System(ukflex.scenes.pendulum()); st = sy.__getstate__(); st['q0'] = np.zeros(7)\nnew = ukflex.System.__new__(ukflex.System); new.__setstate__(st); print('accepted q0 of shape', new.q0.shape)"),
 ("7 fe.reduce(None)", "from ukflex import fe\nfe.reduce(None, 2)"),
 ("7 damping_ratio='x'", "from ukflex import fe\npts = np.array([[0,0],[1,0],[1,1],[0,1]], float); cells = np.array([[0,1,2],[0,2,3]])\nfe.from_mesh(pts, cells=cells, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3, interfaces={'a': 0, 'b': 2}, modes=2, damping_ratio='x')"),
 ("7 an event with terminal='x'", "ev = lambda t, y: y[0]\nev.terminal = 'x'\nukflex.simulate(ukflex.scenes.pendulum(), 0.1, events=[ev])"),
 ("7 Spline(times=5)", "s = ukflex.Scene(); p = s.point_mass('p', mass=1.0); s.coordinate_driver(p.point(), 'x', ukflex.Spline(times=5, values=[0.0, 1.0]))"),
 ("7 ukflex run pendulum --param gravity=nan", "CLI"),
 ("8 --plot 'reaction(nope).fx'", "CLI"),
 ("8 --out ./x/../y", "CLI"),
 ("8 --plot writes caches under $HOME", "CLI"),
 ("9 sweep over a 10^9-case grid", "import ukflex.sweep as sw\nukflex.sweep(lambda **c: ukflex.scenes.pendulum(), {'a': list(range(1000)), 'b': list(range(1000)), 'c': list(range(1000))}, lambda r: {}, t_end=0.01)"),
]

def cli(label: str, tmp: str):
    """(argv, env, what to look at afterwards) of a CLI finding."""
    env = dict(os.environ, MPLBACKEND="Agg")
    if label.startswith("1 "):
        p = os.path.join(tmp, "f.toml")
        with open(p, "w") as f:
            f.write('[[bodies]]\nname = "p"\nkind = "point_mass"\nmass = 1.0\n\n[[drivers]]\nkind = "coordinate"\npoint = { body = "p" }\naxis = "x"\nmotion = "' + "(" * 30000 + "t" + ")" * 30000 + '"\n')
        return [PY, "-m", "ukflex", "run", p, "--out", os.path.join(tmp, "o"), "--no-plot"], env, None
    if "gravity=nan" in label:
        return [PY, "-m", "ukflex", "run", "pendulum", "--param", "gravity=nan", "--out", os.path.join(tmp, "o")], env, None
    if "reaction(nope)" in label:
        return [PY, "-m", "ukflex", "run", "pendulum", "--t-end", "0.05", "--plot", "reaction(nope).fx", "--out", os.path.join(tmp, "o")], env, None
    if "./x/../y" in label:
        return [PY, "-m", "ukflex", "run", "pendulum", "--t-end", "0.01", "--no-plot", "--out", "./x/../y"], env, ("stray", tmp)
    if "HOME" in label:
        home = os.path.join(tmp, "home"); os.makedirs(home)
        env = dict(env, HOME=home); env.pop("MPLCONFIGDIR", None); env.pop("XDG_CACHE_HOME", None); env.pop("XDG_CONFIG_HOME", None)
        return [PY, "-m", "ukflex", "run", "pendulum", "--t-end", "0.01", "--out", os.path.join(tmp, "o")], env, ("home", home)



def run(only=()) -> list:
    rows = []
    for label, code in CASES:
        if only and not any(label.startswith(o) for o in only):
            continue
        with tempfile.TemporaryDirectory() as tmp:
            post = None
            if code == "CLI":
                argv, env, post = cli(label, tmp)
            else:
                argv, env = [PY, "-c", PRE + code], dict(os.environ, MPLBACKEND="Agg")
            tic = time.time()
            try:
                p = subprocess.run(argv, capture_output=True, text=True, timeout=120, cwd=tmp, env=env)
                rc, out = p.returncode, (p.stdout + p.stderr).strip().splitlines()
                last = out[-1] if out else ""
            except subprocess.TimeoutExpired:
                rc, last = "killed", "> 120 s"
            wall = time.time() - tic
            if post and post[0] == "stray":
                last += f" | stray x/: {os.path.isdir(os.path.join(tmp, 'x'))}"
            if post and post[0] == "home":
                found = [os.path.relpath(os.path.join(d, f), post[1]) for d, _, fs in os.walk(post[1]) for f in fs]
                last += f" | files under $HOME: {len(found)} {found[:2]}"
            last = last.replace(tmp, "TMP").replace("|", "\\|")
            rows.append(f"| {label} | {rc} | {last[:300]} | {wall:.1f} |")
            print(rows[-1], flush=True)
    return rows


def main(argv=None) -> int:
    rows = run(tuple(sys.argv[1:] if argv is None else argv))
    print("\n| finding | exit status | last line of output | wall [s] |\n|---|---|---|---:|")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
