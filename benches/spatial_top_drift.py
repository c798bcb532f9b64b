"""The heavy top (30 rad/s, 10 s) at the default rtol: drift of energy, L_z and L.e3 (relative)
for the settings of docs/spatial.md ("The heavy top at the default rtol").
Run: .venv/bin/python benches/spatial_top_drift.py"""
import numpy as np
import ukflex
from ukflex.reference import spatial as sp
import sys, pathlib
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from test_spatial import to_description  # noqa: E402


def invariants(system, res):
    out = ukflex.spatial_outputs(system, res, reactions=False)
    E, L = out["energy"], out["angular_momentum"]
    e3 = out["bodies"]["top"]["rotation"][:, :, 2]
    rel = lambda x: np.abs(x - x[0]) / abs(x[0])
    return rel(E), rel(L[:, 2]), rel(np.einsum("ij,ij->i", L, e3))


t = np.linspace(0, 10, 2001)
for kw in [dict(rtol=1e-6), dict(rtol=1e-6, atol=1e-12), dict(rtol=1e-6, stabilization="none"),
           dict(rtol=1e-6, method="RK45"), dict(rtol=1e-6, method="DOP853"), dict(rtol=1e-7), dict(rtol=1e-8),
           dict(rtol=1e-6, method="RADAU5")]:
    system = ukflex.System(to_description(sp.scenes.heavy_top(spin=30.0)))
    res = ukflex.simulate(system, 10.0, t_eval=t, **kw)
    e, lz, l3 = invariants(system, res)
    print(kw, res.nfev, "max over 10 s: E %.1e Lz %.1e L.e3 %.1e" % (e.max(), lz.max(), l3.max()),
          "| E at 1, 2, 5 s:", " ".join("%.1e" % e[:k].max() for k in (201, 401, 1001)))
