"""Stress stiffening of the flexible3 body (docs/spatial-flexible.md, "Stress stiffening"): the
cost (fe3.from_mesh with and without stress_stiffening; ukflex.simulate of Kane's spin-up on a
freshly built System, medians of interleaved repetitions), Southwell's coefficients against
Omega and the hub radius, the spin-up against the planar FFRF beam by mesh, the size of the
angular-acceleration cases left out, and the energy drift of a free, spinning, stiffened body.
Run: .venv/bin/python benches/flexible3_stiffening.py   (about 1 min)"""
import sys
import time
import pathlib

import numpy as np

import ukflex

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from test_flexible3_stiffening import K1, K2, _bar, _hub, _kane, _lowest_two  # noqa: E402
from ukflex.model.scene import CustomSection  # noqa: E402
from ukflex.model.fe3_stiffening import LOAD_CASES  # noqa: E402


def median_times(fns, reps=5):
    times = [[] for _ in fns]
    for _ in range(reps):
        for i, f in enumerate(fns):
            t0 = time.perf_counter()
            f()
            times[i].append(time.perf_counter() - t0)
    return [float(np.median(t)) for t in times]


print("== build cost, mesh (20, 2, 2) P2, 4 clamped modes")
b0, b1 = median_times([lambda: _bar(), lambda: _bar(stress_stiffening=True)], reps=3)
print(f"from_mesh {b0:.3f} s, with stress_stiffening {b1:.3f} s")

print("== Southwell: K = (w^2 - w0^2) / Omega^2, flapwise and in-plane; beam theory K1 + K2 r/L")
d = _bar(stress_stiffening=True)
for radius in (0.0, 0.5):
    w0 = _lowest_two(_hub(d, ukflex.ConstantSpeed(0.0), 0.0, radius))
    for om in (5.0, 20.0, 50.0):
        w = _lowest_two(_hub(d, ukflex.ConstantSpeed(om), om, radius))
        wn = _lowest_two(_hub(d, ukflex.ConstantSpeed(om), om, radius, stiffening=False))
        k, kn = (w ** 2 - w0 ** 2) / om ** 2, (wn ** 2 - w0 ** 2) / om ** 2
        ref = K1 + K2 * radius
        print(f"r/L {radius}, Omega {om}: with flap {k[0]:.4f} ({k[0] / ref - 1:+.2%} of {ref:.4f}), in-plane {k[1]:.4f} "
              f"(ref {ref - 1:.4f}); without flap {kn[0]:+.2e}, in-plane {kn[1]:+.5f}")

print("== Kane's spin-up (10 m, 0.1 m square, E 70 GPa, rho 3000; 6 rad/s in 15 s; 20 s)")
length, a, e, rho = 10.0, 0.1, 7e10, 3000.0
expr = _kane(15.0, 6.0)
ts = np.linspace(0.0, 20.0, 201)


def planar_system(elements):
    s = ukflex.Scene()
    hub = s.rigid_body("hub", mass=1.0, inertia=1.0)
    s.revolute(s.ground.point(0.0, 0.0), hub.point(0.0, 0.0), name="axle")
    s.angle_driver(hub.frame(), expr, name="spin")
    beam = s.beam("beam", length=length, elements=elements, density=rho, youngs_modulus=e,
                  section=CustomSection(a * a, a ** 4 / 12), frame="clamped", strain="nonlinear", theory="euler-bernoulli")
    s.weld(hub.frame(), beam.at(0.0), name="clamp")
    return ukflex.System(s)


vs = {}
for el in (8, 16):
    sy = planar_system(el)
    vs[el] = np.asarray(sy.beam_point("beam", 1.0, ukflex.simulate(sy, 20.0, t_eval=ts).q))[3]
v = vs[16]
peak = np.abs(v).max()
print(f"planar nonlinear FFRF: peak {peak:.5f} m (8 elements: {np.abs(vs[8] - v).max() / peak:.1e} of it from 16)")
for cells, modes in (((20, 1, 1), 4), ((40, 2, 2), 4), ((40, 2, 2), 8), ((80, 2, 2), 4)):
    dd = _bar(cells, length, a, a, rho, e, modes=modes, stress_stiffening=True)
    res = ukflex.simulate(_hub(dd, expr), 20.0, t_eval=ts)
    tip = (np.asarray(dd.interfaces["B"].phi).T @ res.q[-modes:])[1]
    w1 = dd.info["frequencies"][0] * 2 * np.pi
    w_eb = 1.8751 ** 2 * np.sqrt(e * a ** 4 / 12 / (rho * a * a * length ** 4))
    print(f"3D {cells}, {modes} modes: first bending {w1:.4f} rad/s ({w1 / w_eb - 1:+.2%} of E-B), peak "
          f"{np.abs(tip).max():.5f}, history max diff {np.abs(tip - v).max() / peak:.2%} of the peak")
dd = _bar((40, 2, 2), length, a, a, rho, e, modes=4, stress_stiffening=True)
res0 = ukflex.simulate(_hub(dd, expr, stiffening=False), 20.0, t_eval=ts)
tip0 = (np.asarray(dd.interfaces["B"].phi).T @ res0.q[-4:])[1]
print(f"without stiffening: stops at t = {res0.t[-1]:.2f} s ({res0.message}); |tip| at 10, 12, 13 s:",
      [f"{abs(tip0[np.searchsorted(res0.t, x)]):.3g}" for x in (10.0, 12.0, 13.0)])
kg = dd.geometric_stiffness
for c in range(12):
    print(f"  case {LOAD_CASES[c]}: diag K_c / M_ff (mode 1, 2): {kg[c, 0, 0] / dd.m_ff[0, 0]:+.4f} {kg[c, 1, 1] / dd.m_ff[1, 1]:+.4f}")
f0, f1 = median_times([lambda: ukflex.simulate(_hub(dd, _kane(15.0, 3.0), stiffening=False), 20.0, t_eval=ts),
                       lambda: ukflex.simulate(_hub(dd, _kane(15.0, 3.0)), 20.0, t_eval=ts)])
print(f"simulate (spin-up to 3 rad/s, where both stay bounded; fresh System): without {f0:.4f} s, with {f1:.4f} s, ratio {f1 / f0:.2f}")

print("== energy of a free spinning body (no joint), DOPRI5 rtol 1e-10, 1 s")
for on, lab in ((False, "without"), (True, "with")):
    s = ukflex.SpatialScene()
    s.flexible_body("bar", d, angular_velocity=(0, 0, 50.0), elastic=[1e-4, 1e-4, 0, 0], stress_stiffening=on)
    sy = ukflex.System(s)
    r = ukflex.simulate(sy, 1.0, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=np.linspace(0, 1, 201))
    en = ukflex.spatial_outputs(sy, r, reactions=False)
    ke = en["kinetic_energy"]
    strain = np.array([0.5 * x @ d.k_ff @ x for x in r.q[-4:].T])
    tot = ke + strain
    print(f"{lab}: kinetic {ke[0]:.4g} J, max strain {strain.max():.3g} J, drift of kinetic + strain {np.abs(tot - tot[0]).max():.2e} J")
