"""A05 (the stiff flyball governor, 2 s, 201 outputs): RADAU5M's Newton work per setting.

For each setting, one ``simulate()`` on a fresh System: its process CPU time (not wall: the
machine is shared), right-hand sides, difference passes of the velocity terms (``njev``), LU
factorizations, steps (accepted, rejected), Newton iterations and the slider's largest error
against DOPRI5 at rtol 1e-12 (docs/spatial.md, "MBS benchmark A05").

    python benches/a05_newton.py      # ~15 s
"""

from __future__ import annotations

import time
import warnings

import numpy as np

import ukflex
from ukflex import spatial_scenes

SETTINGS = (
    dict(rtol=1e-3), dict(rtol=1e-4), dict(rtol=1e-5), dict(rtol=1e-6),
    dict(method="RADAU5M", rtol=1e-2), dict(method="RADAU5M", rtol=1e-3),
    dict(method="RADAU5M", step=0.01, rtol=1e-3), dict(method="RADAU5M", step=0.02, rtol=1e-3),
    dict(method="RADAU5M", step=0.04, rtol=1e-3),
)


def slider(system, res) -> np.ndarray:
    return ukflex.spatial_outputs(system, res)["bodies"]["slider"]["position"]


def main() -> None:
    warnings.simplefilter("ignore")
    scene = spatial_scenes.flyball_governor()
    t = np.linspace(0.0, 2.0, 201)
    system = ukflex.System(scene)
    ref = slider(system, ukflex.simulate(system, 2.0, t_eval=t, method="DOPRI5", rtol=1e-12, atol=1e-14))
    print(f"{'setting':42s} {'cpu ms':>7s} {'nfev':>6s} {'njev':>5s} {'nlu':>5s} {'steps':>6s} {'rej':>4s} "
          f"{'newton':>6s} {'error m':>9s}  method")
    for kw in SETTINGS:
        system = ukflex.System(scene)
        c0 = time.process_time()
        res = ukflex.simulate(system, 2.0, t_eval=t, **kw)
        cpu = time.process_time() - c0
        err = float(np.linalg.norm(slider(system, res) - ref, axis=1).max())
        e = res.extra
        print(f"{str(kw):42s} {1e3 * cpu:7.1f} {res.nfev:6d} {res.njev:5d} {res.nlu:5d} {e['naccept']:6d} "
              f"{e['nreject']:4d} {e['newton_iterations']:6d} {err:9.2e}  {res.method}")


if __name__ == "__main__":
    main()
