"""hinfix.hinfnorm against python-control's linfnorm (slycot ab13dd)."""
import math

import numpy as np
import pytest
import control

import hinfix
from check import linfnorm, relerr


@pytest.mark.parametrize("seed", range(8))
def test_random_stable_systems_agree_with_python_control(seed):
    rng = np.random.default_rng(seed)
    n, m, p = rng.integers(1, 9), rng.integers(1, 4), rng.integers(1, 4)
    np.random.seed(seed)  # control.rss draws from numpy's global generator
    sys = control.rss(int(n), int(p), int(m), strictly_proper=bool(seed % 2))
    value, peak = hinfix.hinfnorm(sys)
    assert relerr(value, linfnorm(sys)) <= 1e-8
    # the peak frequency attains the value
    g = sys(1j * peak) if math.isfinite(peak) else sys.D
    assert np.linalg.svd(np.atleast_2d(g), compute_uv=False)[0] == pytest.approx(value, rel=1e-8)


def test_static_gain_transfer_function_and_unstable():
    assert hinfix.hinfnorm(control.ss([], [], [], [[3.0, 4.0]]))[0] == pytest.approx(5.0, rel=1e-14)
    value, peak = hinfix.hinfnorm(control.tf([1.0], [1.0, 0.2, 1.0]))  # resonance near ω = 1
    assert relerr(value, linfnorm(control.tf([1.0], [1.0, 0.2, 1.0]))) <= 1e-8
    assert peak == pytest.approx(math.sqrt(1 - 0.02), rel=1e-4)
    value, peak = hinfix.hinfnorm(control.ss([[1.0]], [[1.0]], [[1.0]], [[0.0]]))
    assert value == math.inf and math.isnan(peak)


def test_bad_systems_raise():
    with pytest.raises(ValueError, match="unspecified sampling time"):
        hinfix.hinfnorm(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], True))
    with pytest.raises(ValueError, match="NaN or infinite"):
        hinfix.hinfnorm(control.ss([[-1.0]], [[np.nan]], [[1.0]], [[0.0]]))
    with pytest.raises(ValueError, match="tol"):
        hinfix.hinfnorm(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), tol=0.0)


def test_a_discrete_time_system_on_the_unit_circle():
    # G(z) = 1/(z - 0.5): the peak is at z = -1 (θ = π), |G| = 1/1.5; at z = 1 it is 2
    value, peak = hinfix.hinfnorm(control.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1))
    assert value == pytest.approx(2.0, rel=1e-12) and peak == pytest.approx(0.0, abs=1e-9)
    value, peak = hinfix.hinfnorm(control.ss([[-0.5]], [[1.0]], [[1.0]], [[0.0]], 0.1))
    assert value == pytest.approx(2.0, rel=1e-12) and peak == pytest.approx(math.pi / 0.1, rel=1e-9)
    value, peak = hinfix.hinfnorm(control.ss([[1.5]], [[1.0]], [[1.0]], [[0.0]], 0.1))
    assert value == math.inf and math.isnan(peak)
