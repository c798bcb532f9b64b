"""Issue 6: safeguards of ukflex.stability (scaling accuracy, failures keep partial results) and the
stability report (studies.stability)."""

import numpy as np
import pytest

from conftest import core_available

pytestmark = pytest.mark.skipif(not core_available(), reason="ukflex._core not built")

import ukflex  # noqa: E402
from studies import extreme as X  # noqa: E402
from ukflex import stability as S  # noqa: E402
from studies import stability as report_study  # noqa: E402


def test_longdouble_reference_solves_to_extended_precision():
    rng = np.random.default_rng(0)
    K = rng.standard_normal((12, 12))
    x = rng.standard_normal(12)
    b = (K.astype(np.longdouble) @ x.astype(np.longdouble))
    y = S._solve_longdouble(K, b)
    assert np.abs(np.asarray(y - x, dtype=float)).max() < 1e-16


def test_scaling_accuracy_on_a_fine_mesh():
    """cond(M) ~ 1e8: the core's block-Cholesky UK keeps full accuracy; the paper's symmetric
    root M^-1/2 loses digits, and the diagonal scaling D = diag(M)^-1/2 recovers them."""
    system = X.stiff(1.0, elements=64).build()
    r = ukflex.simulate(system, 0.002, "DOPRI5", rtol=1e-8, t_eval=[0.0, 0.002], stabilization="none", raise_on_failure=True)
    a = S.scaling_accuracy(system, r.t[-1], r.q[:, -1], r.qd[:, -1])
    assert a["cond_M"] > 5e7 and a["cond_M_scaled"] < 1e4
    assert a["rust_uk"] < 1e-13
    assert a["uk_symmetric"] > 1e-13
    assert a["uk_symmetric_scaled"] < a["uk_symmetric"] / 10


def test_native_failure_raises_with_partial_result():
    system = ukflex.scenes.slider_crank().build()
    with pytest.raises(S.IntegrationFailure) as ei:
        ukflex.simulate(system, 0.01, "DOPRI5", rtol=1e-6, max_steps=50, stabilization="none", raise_on_failure=True)
    part = ei.value.result
    assert part.status == -1 and 0 < part.t[-1] < 0.01 and part.t.size > 10
    assert ei.value.t_fail == part.t[-1]
    res = ukflex.simulate(system, 0.01, "DOPRI5", rtol=1e-6, max_steps=50, raise_on_failure=False, stabilization="none")
    assert res.status == -1 and np.array_equal(res.t, part.t)


def test_drift_warning_and_baumgarte_option_validation():
    system = ukflex.scenes.slider_crank().build()
    r = ukflex.simulate(system, 0.01, "DOPRI5", rtol=1e-3, stabilization="none", raise_on_failure=True)
    with pytest.warns(S.DriftWarning):
        S.check(r, drift_threshold=1e-14, rank=False)
    with pytest.raises(ValueError):
        ukflex.simulate(system, 0.01, "DOPRI5", stabilization="sideways", raise_on_failure=True)
    with pytest.raises(ValueError):
        ukflex.simulate(system, 0.01, "DOPRI5", stabilization=("baumgarte", -1.0, 1.0), raise_on_failure=True)


def test_report_writes_markdown_for_one_case(tmp_path):
    data = report_study.report(str(tmp_path), quick=True, cases=["mass_ratio_1e6"], verbose=False)
    md = (tmp_path / "stability.md").read_text()
    assert "mass_ratio_1e6" in md and (tmp_path / "stability.json").exists()
    runs = data["cases"][0]["runs"]
    assert all(r["ok"] for r in runs)
    assert any(r["formulation"].startswith("CP") for r in runs)
