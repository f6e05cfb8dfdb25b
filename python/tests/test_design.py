"""Round trip against python-control on the shipped plants: the reported γ is ‖P.lft(K)‖∞ as
python-control computes it (to 1e-8 relative), the closed loop and the controller are stable,
and the same seed gives the same controller."""
import numpy as np
import pytest
import control

import hinfix
from check import abscissa, linfnorm, relerr

BUDGET = dict(maxevals=400, cpumax=30.0)


@pytest.mark.parametrize("order", [0, 1, 2])
def test_gamma_is_the_closed_loops_norm_by_python_control(shipped, order):
    name, P, nmeas, ncon = shipped
    K, info = hinfix.design(P, nmeas, ncon, order, **BUDGET)
    assert info.stabilised, (name, order, info.status)
    assert isinstance(K, control.StateSpace)
    assert (K.nstates, K.ninputs, K.noutputs) == (order, nmeas, ncon)
    CL = P.lft(K)
    assert abscissa(CL) < 0
    assert info.alpha_cl == pytest.approx(abscissa(CL), rel=1e-6, abs=1e-9)
    assert relerr(info.gamma, linfnorm(CL)) <= 1e-8, (name, order, info.gamma, linfnorm(CL))
    # strongly stabilising: the controller is stable, and ‖K‖∞ is python-control's too
    assert info.strongly_stabilised
    if order > 0:
        assert abscissa(K) < 0 and info.alpha_k < 0
    assert relerr(info.k_hinf, linfnorm(K)) <= 1e-8
    assert info.objective == pytest.approx(max(info.gamma, 1e-3 * info.k_hinf), rel=1e-12)
    assert info.status in ("converged", "stopped", "budget_exhausted", "stabilised_only")


def test_same_seed_same_controller_other_seed_other_start():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    K1, i1 = hinfix.design(P, nmeas, ncon, 2, seed=3, **BUDGET)
    K2, i2 = hinfix.design(P, nmeas, ncon, 2, seed=3, **BUDGET)
    for m in "ABCD":
        np.testing.assert_array_equal(getattr(K1, m), getattr(K2, m))
    assert i1.gamma == i2.gamma
    K3, _ = hinfix.design(P, nmeas, ncon, 2, seed=4, **BUDGET)
    assert not np.array_equal(K1.A, K3.A)


def test_the_nine_matrices_are_the_same_plant():
    P, nmeas, ncon = hinfix.load_plant("REA2")
    m1, p1 = P.ninputs - ncon, P.noutputs - nmeas
    mats = (P.A, P.B[:, :m1], P.B[:, m1:], P.C[:p1], P.C[p1:],
            P.D[:p1, :m1], P.D[:p1, m1:], P.D[p1:, :m1], P.D[p1:, m1:])
    K1, i1 = hinfix.design(P, nmeas, ncon, 1, **BUDGET)
    K2, i2 = hinfix.design(mats, None, None, 1, **BUDGET)
    np.testing.assert_array_equal(K1.D, K2.D)
    assert i1.gamma == i2.gamma


def test_plain_hinf_and_warm_start():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    K0, i0 = hinfix.design(P, nmeas, ncon, 0, strong=False, **BUDGET)
    assert i0.options["objective"] == "plain" and i0.objective == i0.gamma
    K1, i1 = hinfix.design(P, nmeas, ncon, 1, init=K0, nrand=1, **BUDGET)
    assert i1.stabilised and relerr(i1.gamma, linfnorm(P.lft(K1))) <= 1e-8


def test_search_options_reach_the_design():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    _, info = hinfix.design(P, nmeas, ncon, 1, max_starts=2, stall_starts=0, cpumax=30.0)
    assert info.options["max_starts"] == 2
    assert info.search["starts"] <= 2
    assert set(info.certificate or {}) <= {"dnorm", "evaldist"}


def test_full_order_gamma_bounds_every_design():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    g = hinfix.full_order_gamma(P, nmeas, ncon)
    _, info = hinfix.design(P, nmeas, ncon, 2, **BUDGET)
    assert 0 < g["gamma_lower"] <= g["gamma"] <= info.gamma
