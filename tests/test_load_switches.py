"""A fixed-step RADAU5M run ends its steps at the kinks and jumps of the loads that are
expressions of ``t`` (``rust/integrate/switches.rs``): a step that straddles a kink integrates a
load that is not smooth inside it. Simo and Vu-Quoc's right-angle cantilever, its triangular
pulse written with ``abs`` (2 elements per member, 4 s; 30 s and 5 elements in
``benches/beam3_floor.py --steps``)."""

import numpy as np
import pytest

import ukflex
from studies import right_angle_cantilever as rac

T = 4.0


def _frame(load) -> ukflex.System:
    s = ukflex.SpatialScene()
    sec = ukflex.CustomSection3(ea=rac.EA, ga_y=rac.GA, ga_z=rac.GA, gj=rac.GJ, ei_y=rac.EI, ei_z=rac.EI,
                                mass_per_length=rac.RHO_A, rotary_inertia=rac.RHO_J)
    a = s.beam("a", (0, 0, 0), (rac.L, 0, 0), sec, elements=2)
    b = s.beam("b", (rac.L, 0, 0), (rac.L, rac.L, 0), sec, elements=2)
    s.fixed(s.ground.marker((0, 0, 0)), a.node(0))
    s.fixed(a.node(-1, z=(0, 0, 1), x=(1, 0, 0)), b.node(0, z=(0, 0, 1), x=(0, -1, 0)))
    s.point_load(a.node(-1), [0, 0, load])
    return ukflex.System(s)


def _tip(load, **kw) -> np.ndarray:
    """The last node body's position at 0.01 s intervals."""
    r = ukflex.simulate(_frame(load), T, t_eval=np.linspace(0.0, T, 401), **kw)
    return np.asarray(r.q)[-7:-4]


def test_a_fixed_step_ends_at_the_kinks_of_an_expression_load():
    """At 0.0826 s the steps straddle the pulse's kinks at 1 and 2 s: the expression's run ends
    a step at each and is as close to a tight run as the 0.1 s steps that land on them (1.1e-6
    and 2.0e-6 m); the same pulse as a Python callable (no kinks known) is 3.5e-4 m off (on the
    30 s frame with 5 elements per member, 1.0e-3 m before the stops, 8e-6 m with them)."""
    ref = _tip(rac.PULSE, method="DOPRI5", rtol=1e-10, atol=1e-12)
    err = {(kind, h): np.abs(_tip(load, method="RADAU5M", step=h, rtol=1e-6) - ref).max()
           for kind, load in (("expression", rac.PULSE), ("callable", lambda t, state: rac.pulse(t)))
           for h in (0.1, 0.0826)}
    assert err["expression", 0.0826] < 3 * err["expression", 0.1] < 2e-5, err
    assert err["callable", 0.0826] > 30 * err["expression", 0.0826], err
    # a callable's aligned steps are the expression's: only the straddled kinks differ
    assert err["callable", 0.1] == pytest.approx(err["expression", 0.1], rel=1e-3), err


def test_auto_follows_rtol_on_the_frame():
    """Below the default rtol auto runs a geometrically exact beam's Newton tighter than 100 rtol
    (``newton_rtol`` in ``rust/integrate/choice/mod.rs``): on the frame (5 elements per member,
    30 s) its tip is 1.4e-4 / 1.5e-5 / 4.3e-6 m off a tight run at rtol 1e-6 / 1e-7 / 1e-9; with
    Newton at 100 rtol (the former rule) 1.4e-4 / 2.6e-5 / 1.7e-5."""
    te = np.linspace(0.0, 30.0, 301)

    def tip(**kw):
        return np.asarray(ukflex.simulate(ukflex.System(rac.scene(5)), 30.0, t_eval=te, **kw).q)[-7:-4]

    ref = tip(method="RADAU5M", step=0.005, rtol=1e-10)  # 1.1e-7 m off DOPRI5 at rtol 1e-10
    err = {rtol: np.abs(tip(rtol=rtol) - ref).max() for rtol in (1e-6, 1e-7, 1e-9)}
    assert err[1e-6] > 3 * err[1e-7] > 7.5 * err[1e-9], err
