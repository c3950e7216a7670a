"""The figures' quantile bands against numpy's own quantiles."""

import numpy as np

from pendulum_fmu.plot import BAND_LEVELS, _quantiles


def test_band_quantiles_are_numpys_per_value():
    rng = np.random.default_rng(7)
    x, y = rng.integers(0, 9, 2000).astype(float), rng.normal(size=2000)
    levels, values = _quantiles(x, y, [0.05, 0.5, 0.75])
    assert levels.tolist() == sorted(set(x.tolist()))
    for i, level in enumerate(levels):
        assert np.allclose([v[i] for v in values], np.quantile(y[x == level], [0.05, 0.5, 0.75]),
                           rtol=0, atol=1e-12)
    many = rng.uniform(0.0, 1.0, 5000)  # more distinct values than levels: pooled into bins
    levels, (median,) = _quantiles(many, many, [0.5])
    assert len(levels) == BAND_LEVELS and np.max(np.abs(median - levels)) < 0.5 / BAND_LEVELS
