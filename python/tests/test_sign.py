"""Sign convention: the controller is python-control's (positive feedback u = K y, as
``control.hinfsyn`` returns it and ``P.lft(K)`` closes the loop)."""
import pytest
import control

import hinfix
from check import abscissa, linfnorm, relerr


def unstable_plant():
    """x' = x + w1 + u, z = (x, u), y = x + 0.1 w2: only u = k y with k < -1 stabilises. A
    regular problem (D12, D21 of full rank), so control.hinfsyn (slycot sb10ad) solves it."""
    return control.ss([[1.0]], [[1.0, 0.0, 1.0]], [[1.0], [0.0], [1.0]], [[0, 0, 0], [0, 0, 1.0], [0, 0.1, 0]])


def test_static_gain_has_hinfsyns_sign_and_lft_closes_the_loop():
    P = unstable_plant()
    K, info = hinfix.design(P, 1, 1, 0, maxevals=300)
    k = K.D[0, 0]
    assert k < -1, k  # negative: stabilising in u = K y
    # hinfsyn's optimal controller is (up to a pole at -6e9) the same static gain: same sign
    Kh, _, gam_h, _ = control.hinfsyn(P, 1, 1)
    assert abs(control.dcgain(Kh) - k) <= 1e-4 * abs(k), (control.dcgain(Kh), k)
    assert hinfix.full_order_gamma(P, 1, 1)["gamma"] == pytest.approx(gam_h, rel=1e-4)
    CL = P.lft(K)
    assert abscissa(CL) < 0
    assert relerr(info.gamma, linfnorm(CL)) <= 1e-8
    # the other sign is not the loop hinfix designed: it is unstable
    assert abscissa(P.lft(-K)) > 0
    # fixed order cannot beat full order; here it attains it
    assert gam_h * (1 - 1e-6) <= info.gamma <= gam_h * (1 + 1e-4)


def test_dynamic_controller_closes_the_reported_loop():
    P, nmeas, ncon = hinfix.load_plant("AC8")
    K, info = hinfix.design(P, nmeas, ncon, 1, maxevals=300)
    assert relerr(info.gamma, linfnorm(P.lft(K))) <= 1e-8
    # with the sign flipped, the loop is a different one
    flipped = P.lft(-K)
    assert abscissa(flipped) >= 0 or relerr(linfnorm(flipped), info.gamma) > 1e-3
