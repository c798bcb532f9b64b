"""The heavy top (30 rad/s, 10 s): drift of energy, L_z and L.e3 (relative) for the settings of
docs/spatial.md ("The heavy top at the default rtol"), then at rtol 1e-5 .. 1e-9 in units of
rtol: auto (DOPRI5 at ``DOPRI5_RTOL_PER_RTOL`` rtol) against DOPRI5 at the user's rtol (what
auto ran until issue 26's round on DOPRI5's rtol), with and without the projection.
Run: .venv/bin/python benches/spatial_top_drift.py   (~6 s)"""
import pathlib
import sys

import numpy as np

import ukflex
from ukflex.reference import spatial as sp

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from test_spatial import to_description  # noqa: E402

T = np.linspace(0, 10, 2001)
RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9)


def invariants(system, res):
    out = ukflex.spatial_outputs(system, res, reactions=False)
    E, L = out["energy"], out["angular_momentum"]
    e3 = out["bodies"]["top"]["rotation"][:, :, 2]
    rel = lambda x: np.abs(x - x[0]) / abs(x[0])  # noqa: E731
    return rel(E), rel(L[:, 2]), rel(np.einsum("ij,ij->i", L, e3))


def run(**kw):
    system = ukflex.System(to_description(sp.scenes.heavy_top(spin=30.0)))
    res = ukflex.simulate(system, 10.0, t_eval=T, **kw)
    return res, invariants(system, res)


def main():
    for kw in [dict(), dict(method="DOPRI5", rtol=1e-6), dict(method="DOPRI5", rtol=1e-6, atol=1e-12),
               dict(method="DOPRI5", rtol=1e-6, stabilization="none"), dict(rtol=1e-6, method="RK45"),
               dict(rtol=1e-6, method="DOP853"), dict(rtol=1e-6, method="RADAU5")]:
        res, (e, lz, l3) = run(**kw)
        print(kw or "defaults (auto)", res.method, f"rtol {res.rtol:g}", res.nfev, f"to t = {res.t[-1]:g} s:",
              "max E %.1e Lz %.1e L.e3 %.1e" % (e.max(), lz.max(), l3.max()),
              "| E at 1, 2, 5 s:", " ".join("%.1e" % e[:k].max() for k in (201, 401, 1001)))
    print("\nin units of rtol (rhs calls): auto | DOPRI5 at rtol | DOPRI5 at rtol, no projection (to the drift stop)")
    for rtol in RTOLS:
        cells = []
        for kw in (dict(), dict(method="DOPRI5"), dict(method="DOPRI5", stabilization="none")):
            res, inv = run(rtol=rtol, **kw)
            cells.append(", ".join(f"{x.max() / rtol:.2f}" for x in inv) + f" ({res.nfev}{'' if res.t[-1] == 10.0 else f', {res.t[-1]:.1f} s'})")
        print(f"rtol {rtol:.0e}: " + " | ".join(cells), flush=True)


if __name__ == "__main__":
    main()
