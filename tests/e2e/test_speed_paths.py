"""The fused fast path and the five wired blocks compute the same run."""

import numpy as np
import pytest
from conftest import run_cached


@pytest.mark.parametrize("name", ["curve_b025_tf15", "assembly"])
def test_fused_equals_blocks(name):
    fused = run_cached(name)
    blocks = run_cached(name, "controller: {implementation: blocks}")
    assert fused.metrics["sim"]["steps"] == blocks.metrics["sim"]["steps"]
    # the same kernels; σ is a Drake Integrator's state in the fused system, the surface's in the
    # blocks, and ẋ = J v a loop in one, BLAS in the other: the steps agree to rounding
    np.testing.assert_allclose(fused.series["t"], blocks.series["t"], rtol=0, atol=1e-10)
    for key in ("q", "v", "tau", "e", "edot", "s_x", "sigma", "xi", "alpha", "x_r", "objects"):
        np.testing.assert_allclose(fused.series[key], blocks.series[key], rtol=1e-7, atol=1e-10,
                                   err_msg=key)
    for a, b in zip(fused.metrics["segments"], blocks.metrics["segments"]):
        assert a["e_tf_norm"] == pytest.approx(b["e_tf_norm"], rel=1e-7)
