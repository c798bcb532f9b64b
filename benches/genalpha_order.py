"""GENALPHA's order at a fixed step: Newton's stopping tolerance is still ``rtol``.

With ``step=`` GENALPHA takes no error test, but its Newton iteration stops at the ``rtol`` level
(default 1e-6) of each step's motion.  An order study at the default rtol sees the Newton error
once the discretization error falls to it; at ``rtol=1e-10`` the planar pendulum is second order
down to the finest step.  Reference: native DOPRI5 at rtol 1e-12.

    python benches/genalpha_order.py      # ~2 s
"""

from __future__ import annotations

import warnings

import numpy as np

import ukflex
from ukflex import scenes

T_END = 2.0
STEPS = (0.02, 0.01, 0.005, 0.0025, 0.00125)


def main() -> None:
    warnings.simplefilter("ignore")
    te = np.linspace(0.0, T_END, 201)
    scene = scenes.pendulum()  # 1 m, 1 kg, released at -45 degrees
    ref = ukflex.simulate(scene.build(), T_END, method="DOPRI5", rtol=1e-12, atol=1e-14, t_eval=te)
    for rtol in (None, 1e-10):
        kw = {} if rtol is None else {"rtol": rtol}
        errs = [float(np.abs(ukflex.simulate(scene.build(), T_END, method="GENALPHA", step=h, t_eval=te, **kw).q
                             - ref.q).max()) for h in STEPS]
        orders = [np.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
        print(f"rtol {'1e-6 (default)' if rtol is None else f'{rtol:g}':15} errors "
              + " ".join(f"{e:.2e}" for e in errs) + "   orders " + " ".join(f"{o:.2f}" for o in orders))


if __name__ == "__main__":
    main()
