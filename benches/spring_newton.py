"""The implicit methods' Newton matrix with and without the springs' stiffness: a 1 kg mass on a
1e8 N/m spring-damper (1e4 rad/s, damping ratio 0.5), falling under gravity, 1 s.  RADAU5 with
the structured Jacobian (K of the bodies and force elements) against its central-difference
Jacobian (every term), and RADAU5M, at rtol 1e-3 and 1e-6: steps, rejections, Newton iterations.

    .venv/bin/python benches/spring_newton.py        # a few seconds
"""

import ukflex
from ukflex import Scene


def scene():
    s = Scene(gravity=(0.0, -9.81))
    b = s.rigid_body("m", mass=1.0, inertia=1e-2, position=(0.3, 0.0))
    s.spring_damper(s.ground.point(0.0, 0.0), b.point(0.0, 0.0), stiffness=1e8, damping=1e4, rest_length=0.3)
    return s


if __name__ == "__main__":
    print("method   jacobian    rtol   status  steps  rejected  newton")
    for method, jac in (("RADAU5", "structured"), ("RADAU5", "central"), ("RADAU5M", None)):
        for rtol in (1e-3, 1e-6):
            kw = {} if jac is None else {"jacobian": jac}
            r = ukflex.simulate(scene().build(), 1.0, method=method, rtol=rtol, **kw)
            e = r.extra
            print(f"{method:8s} {jac or 'structured':10s} {rtol:6.0e} {r.status:6d} {e['naccept']:6d} {e['nreject']:9d} "
                  f"{e['newton_iterations']:7d}")
