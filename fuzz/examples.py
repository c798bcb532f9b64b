"""Every hostile input of the robustness review, run as a user would (each in its own process, with a time
limit), printed as a Markdown table: what happens now, the message quoted, the exit status.

``python -m fuzz.examples`` from the repository root (about two minutes); docs/robustness.md
keeps its output.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

PY = sys.executable

#: (label, kind, payload): kind "py" runs the snippet (it prints its outcome), "cli" runs ukflex
EXAMPLES = [
    ("five beams of 4,096 elements (used to abort: 30 GB of dense buffers)", "py", """
s = ukflex.Scene()
for k in range(5):
    s.beam(f"b{k}", length=1.0, section=ukflex.Circular(0.01), density=7800.0, youngs_modulus=2e11, elements=4096,
           theory="euler-bernoulli", position=(0.0, 0.1 * k))
sy = s.build(); print("built", sy.n_coords, "coordinates;", end=" ")
sy.jac(0.0, sy.y0)"""),
    ("20,000 free rigid bodies", "py", """
s = ukflex.Scene()
for k in range(20000):
    s.rigid_body(f"r{k}", mass=1.0, inertia=0.1, position=(k, 0.0))
sy = s.build(); print("built", sy.n_coords, "coordinates;", end=" ")
r = ukflex.simulate(sy, 1e-3, method="RADAU5"); print(r.status, r.message)"""),
    ("simulate(pendulum, 1e9, method='RK45') (used to never return)", "py", """
r = ukflex.simulate(ukflex.scenes.pendulum(), 1e9, method="RK45")
print("status", r.status, "t reached", r.t[-1], "|", r.message)"""),
    ("max_step=1e-300", "py", """ukflex.simulate(ukflex.scenes.pendulum(), 1.0, method="RK45", max_step=1e-300)"""),
    ("simulate with a stabilization and default budgets, 1e4 s", "py", """
r = ukflex.simulate(ukflex.scenes.pendulum(), 1e4, "DOPRI5", stabilization="none")
print("status", r.status, "outputs", r.t.size, "|", r.message)"""),
    ("slider_crank(diameter=1e100)", "py", "ukflex.System(ukflex.scenes.slider_crank(diameter=1e100))"),
    ("custom section area 1e-300, I 1e300", "py", """
s = ukflex.Scene(); s.beam("b", length=1.0, section={"shape": "custom", "area": 1e-300, "second_moment": 1e300},
                           density=7800.0, youngs_modulus=2e11, theory="euler-bernoulli"); s.build()"""),
    ("slider_crank(shear_factor=1e308)", "py", "ukflex.System(ukflex.scenes.slider_crank(shear_factor=1e308))"),
    ("pendulum(mass=1e308)", "py", "ukflex.System(ukflex.scenes.pendulum(mass=1e308))"),
    ("pendulum(gravity=1e308)", "py", """
r = ukflex.simulate(ukflex.scenes.pendulum(gravity=1e308), 0.1); print("status", r.status, "|", r.message)"""),
    ("slider_crank(omega=1e308) (driver coefficient)", "py", "ukflex.System(ukflex.scenes.slider_crank(omega=1e308))"),
    ("pendulum(angular_velocity=1e200)", "py", "ukflex.System(ukflex.scenes.pendulum(angular_velocity=1e200))"),
    ("revolute pivot at x = 1e17", "py", """
s = ukflex.Scene(gravity=(0.0, -9.81)); b = s.rigid_body("link", mass=1.0, inertia=0.1)
s.revolute(s.ground.point(1e17, 0.0), b.point(-0.5, 0.0)); s.build()"""),
    ("qdd with q = 1e200 entries", "py", """
sy = ukflex.System(ukflex.scenes.slider_crank()); q = sy.q0.copy(); q[3] = 1e200; sy.qdd(0.0, q, sy.qd0)"""),
    ("masked array", "py", """
import numpy as np; sy = ukflex.System(ukflex.scenes.pendulum()); sy.phi(0.0, np.ma.masked_array(sy.q0, mask=True))"""),
    ("complex array", "py", """sy = ukflex.System(ukflex.scenes.pendulum()); sy.phi(0.0, sy.q0 + 1j)"""),
    ("NaN mid-run, scipy path (a driver sqrt(0.5 - t) undefined after t = 0.5)", "py", """
s = ukflex.Scene(); b = s.rigid_body("w", mass=1.0, inertia=0.1); s.revolute(s.ground.point(0.0, 0.0), b.point(0.0, 0.0))
s.angle_driver(b.frame(), "sqrt(0.5 - t)")
r = ukflex.simulate(s, 1.0, method="RK45"); print("status", r.status, "kept t up to", r.t[-1], "|", r.message)"""),
    ("E = 1e300 (was 'mass matrix is not positive definite')", "py",
     "ukflex.System(ukflex.scenes.slider_crank(youngs_modulus=1e300))"),
    ("elements = 10**30", "py", "ukflex.System(ukflex.scenes.slider_crank(elements=10**30))"),
    ("rigid_body(mass='x')", "py", "s = ukflex.Scene(); s.rigid_body('a', mass='x', inertia=1.0)"),
    ("qdd(q=None)", "py", "sy = ukflex.System(ukflex.scenes.pendulum()); sy.qdd(0.0, None, sy.qd0)"),
    ("simulate(max_steps=1.5)", "py", "ukflex.simulate(ukflex.scenes.pendulum(), 0.1, method='DOPRI5', max_steps=1.5)"),
    ("simulate(t_end='1')", "py", "ukflex.simulate(ukflex.scenes.pendulum(), '1')"),
    ("simulate(rtol='1e-6')", "py", "ukflex.simulate(ukflex.scenes.pendulum(), 0.1, rtol='1e-6')"),
    ("simulate(t_end=True)", "py", "ukflex.simulate(ukflex.scenes.pendulum(), True)"),
    ("simulate(method='dopri5')", "py", """
r = ukflex.simulate(ukflex.scenes.pendulum(), 0.1, method='dopri5'); print("ran", r.method)"""),
    ("simulate(max_stpe=1e-3) (misspelt)", "py", "ukflex.simulate(ukflex.scenes.pendulum(), 0.1, max_stpe=1e-3)"),
    ("CLI: run --out unwritable", "cli", ["run", "pendulum", "--t-end", "0.01", "--out", "/proc/ukflex/x"]),
    ("CLI: export -o a directory", "cli", ["export", "pendulum", "-o", "{tmp}"]),
    ("CLI: --samples 1e11", "cli", ["run", "pendulum", "--samples", "1e11", "--out", "{tmp}/o"]),
    ("CLI: deeply nested TOML", "cli", ["run", "{deep}"]),
    ("CLI: /dev/zero", "cli", ["run", "/dev/zero"]),
    ("CLI: a FIFO", "cli", ["run", "{fifo}"]),
    ("CLI: a 400-digit integer", "cli", ["run", "{bigint}", "--out", "{tmp}/o2"]),
    ("CLI: scene named '..'", "cli", ["run", "{dotdot}", "--t-end", "0.01", "--no-plot"]),
    ("CLI: 'my scene.toml'", "cli", ["run", "{spaces}", "--t-end", "0.01", "--no-plot", "--out", "{tmp}/o3"]),
    ("CLI: kind = []", "cli", ["run", "{kindlist}"]),
    ("CLI: 3,000 bodies + 1 bad entry (was > 120 s)", "cli", ["run", "{many}"]),
]

_SCENE = """gravity = [0.0, -9.81]

[scene]
name = "{name}"

[[bodies]]
name = "rod"
kind = "{kind}"
mass = {mass}
inertia = 0.1
position = [0.5, 0.0]

[[joints]]
kind = "revolute"
a = {{ body = "ground", point = [0.0, 0.0] }}
b = {{ body = "rod", point = [-0.5, 0.0] }}
"""


def _files(tmp: str) -> dict:
    def write(name, text):
        path = os.path.join(tmp, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    fifo = os.path.join(tmp, "fifo.toml")
    os.mkfifo(fifo)
    good = dict(name="pend", kind="rigid", mass="1.0")
    many = _SCENE.format(**good) + "".join(
        f'\n[[bodies]]\nname = "b{i}"\nkind = "rigid"\nmass = 1.0\ninertia = 0.1\n' for i in range(3000)
    ) + '\n[[bodies]]\nname = "bad"\nkind = "rigid"\nmass = -1.0\ninertia = 0.1\n'
    return {
        "tmp": tmp, "fifo": fifo,
        "deep": write("deep.toml", "x = " + "[" * 5000 + "]" * 5000 + "\n"),
        "bigint": write("big.toml", _SCENE.format(name="big", kind="rigid", mass="1" + "0" * 400)),
        "dotdot": write("dd.toml", _SCENE.format(name="..", kind="rigid", mass="1.0")),
        "spaces": write("my scene.toml", _SCENE.format(**good)),
        "kindlist": write("kl.toml", _SCENE.format(name="kl", kind="rigid", mass="1.0").replace('kind = "rigid"',
                                                                                                "kind = []")),
        "many": write("many.toml", many),
    }


def run_one(label, kind, payload, files, timeout=120.0):
    t0 = time.time()
    if kind == "py":
        code = ("import warnings; warnings.simplefilter('ignore'); import ukflex\n"
                "try:\n" + "".join("    " + line + "\n" for line in payload.strip().splitlines())
                + "    print(' -> returned')\n"
                "except Exception as e:\n    print(f'{type(e).__name__}: {e}')\n")
        cmd = [PY, "-c", code]
    else:
        cmd = [PY, "-m", "ukflex"] + [a.format(**files) for a in payload]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=files["tmp"],
                           env=dict(os.environ, MPLBACKEND="Agg"))
        out = " ".join(p.stdout.split()) if kind == "py" else p.stderr.strip()
        status = p.returncode
        if "Traceback" in p.stderr:
            out = "TRACEBACK: " + p.stderr.strip().splitlines()[-1]
    except subprocess.TimeoutExpired:
        out, status = f"HANG (> {timeout:g} s)", "killed"
    return label, out, status, time.time() - t0


def main() -> int:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        files = _files(tmp)
        for label, kind, payload in EXAMPLES:
            label, out, status, wall = run_one(label, kind, payload, files)
            out = out.replace("|", "\\|").replace(tmp, "TMP")
            if len(out) > 400:
                out = out[:397] + "..."
            rows.append(f"| {label} | {out} | {status} | {wall:.1f} |")
            print(rows[-1], flush=True)
    print("\n| example | now (message quoted) | exit status | wall [s] |\n|---|---|---|---:|")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
