"""Bad inputs raise clear Python exceptions carrying the crate's message (never a panic)."""
import numpy as np
import pytest
import control

import hinfix


@pytest.fixture(scope="module")
def he1():
    return hinfix.load_plant("HE1")


def test_hinfix_error_is_a_runtime_error():
    assert issubclass(hinfix.HinfixError, RuntimeError)


def test_partition_errors(he1):
    P, nmeas, ncon = he1
    with pytest.raises(ValueError, match=r"nmeas must be in 1..=2 \(P has 3 outputs and one at least is z\), got 0"):
        hinfix.design(P, 0, ncon, 1)
    with pytest.raises(ValueError, match=r"ncon must be in 1..=3 \(P has 4 inputs and one at least is w\), got 7"):
        hinfix.design(P, nmeas, 7, 1)
    with pytest.raises(TypeError, match="nmeas must be a whole number"):
        hinfix.design(P, 1.5, ncon, 1)
    # a SISO system has no room for both a measurement and a performance output
    with pytest.raises(ValueError, match=r"P has 1 output: a plant needs at least two, a measurement y"):
        hinfix.design(control.tf([1], [1, 1]), 1, 1, 0)
    with pytest.raises(ValueError, match=r"P has 1 input: a plant needs at least two, a control u"):
        hinfix.design(control.ss(np.zeros((1, 1)), np.ones((1, 1)), np.ones((2, 1)), np.zeros((2, 1))), 1, 1, 0)
    # the same rule for a plant given as its nine matrices (the design ran, then the result was
    # lost to python-control's dimension error)
    mats = [-np.eye(2), np.zeros((2, 0)), np.ones((2, 1)), np.ones((1, 2)), np.ones((1, 2)),
            np.zeros((1, 0)), np.ones((1, 1)), np.zeros((1, 0)), np.zeros((1, 1))]
    with pytest.raises(ValueError, match="B1 has no column: no disturbance input w"):
        hinfix.design(mats, None, None, 1, maxevals=100)


def test_an_init_in_the_other_time_domain_is_refused(he1):
    P, nmeas, ncon = he1
    k = control.ss([[0.5]], np.ones((1, nmeas)), np.ones((ncon, 1)), np.zeros((ncon, nmeas)), dt=0.1)
    with pytest.raises(ValueError, match=r"init is in discrete time \(dt = 0.1 s\) but the plant is in continuous time"):
        hinfix.design(P, nmeas, ncon, 1, init=k, maxevals=100)
    Pd = control.c2d(P, 0.2)
    with pytest.raises(ValueError, match=r"init is in discrete time \(dt = 0.1 s\) but the plant is in discrete time \(dt = 0.2 s\)"):
        hinfix.design(Pd, nmeas, ncon, 1, init=k, maxevals=100)
    kc = control.ss([[-0.5]], np.ones((1, nmeas)), np.ones((ncon, 1)), np.zeros((ncon, nmeas)))
    with pytest.raises(ValueError, match="init is in continuous time but the plant is in discrete time"):
        hinfix.design(Pd, nmeas, ncon, 1, init=kc, maxevals=100)
    # a static gain, and a controller in the plant's own domain, are taken
    hinfix.design(P, nmeas, ncon, 1, init=kc, maxevals=100)
    hinfix.design(Pd, nmeas, ncon, 0, init=control.ss([], [], [], np.zeros((ncon, nmeas))), maxevals=100)


def test_threads_of_run_campaign_are_in_range(tmp_path):
    for bad in (0, -1, 257, 10**6, 2.0, True):
        with pytest.raises(ValueError, match=r"run_campaign: threads must be a whole number in 1..=256"):
            hinfix.run_campaign(tmp_path / "none.toml", tmp_path, threads=bad)


def test_option_errors_carry_the_crates_message(he1):
    P, nmeas, ncon = he1
    with pytest.raises(ValueError, match="ε must be a number from 1e-50 to 1e50"):
        hinfix.design(P, nmeas, ncon, 1, eps=-1.0)
    with pytest.raises(TypeError, match="nrand must be a whole number, got '3'"):
        hinfix.design(P, nmeas, ncon, 1, nrand="3")
    with pytest.raises(ValueError, match="exceeds the plant order n = 4"):
        hinfix.design(P, nmeas, ncon, 5)
    with pytest.raises(ValueError, match="order must be ≥ 0, got -1"):
        hinfix.design(P, nmeas, ncon, -1)
    with pytest.raises(ValueError, match="must be at least 1"):
        hinfix.design(P, nmeas, ncon, 1, maxevals=0)
    with pytest.raises(ValueError, match=r"seed must be at most 2\*\*64 - 1, got 1180591620717411303424"):
        hinfix.design(P, nmeas, ncon, 1, seed=2**70)
    with pytest.raises(ValueError, match="cpumax"):
        hinfix.design(P, nmeas, ncon, 1, cpumax=float("nan"))
    with pytest.raises(TypeError, match="unknown design option.*nrandd"):
        hinfix.design(P, nmeas, ncon, 1, nrandd=3)
    with pytest.raises(TypeError, match="strong=True/False"):
        hinfix.design(P, nmeas, ncon, 1, objective="plain")


def test_plant_errors_name_the_matrix(he1):
    P, nmeas, ncon = he1
    A = P.A.copy()
    A[1, 2] = np.inf
    bad = control.ss(A, P.B, P.C, P.D)
    with pytest.raises(ValueError, match=r"matrix `A` entry \(2, 3\) is not finite"):
        hinfix.design(bad, nmeas, ncon, 1)
    with pytest.raises(ValueError, match="nine"):
        hinfix.design((P.A, P.B), None, None, 1)
    with pytest.raises(ValueError, match="must be real"):
        hinfix.design([P.A * 1j] + [np.zeros((4, 1))] * 8, None, None, 1)
    with pytest.raises(ValueError, match="B2"):
        mats = [P.A, P.B[:, :2], np.zeros((3, 2)), P.C[:2], P.C[2:], P.D[:2, :2], P.D[:2, 2:], P.D[2:, :2],
                P.D[2:, 2:]]
        hinfix.design(mats, None, None, 1)
    with pytest.raises(ValueError, match="no plant named `he2`"):
        hinfix.load_plant("he2")


def test_initial_controller_errors(he1):
    P, nmeas, ncon = he1
    with pytest.raises(ValueError, match="exceeds the target order"):
        hinfix.design(P, nmeas, ncon, 1, init=control.rss(2, ncon, nmeas))
    with pytest.raises(ValueError, match="Bk is 1×2, expected 1×1"):
        hinfix.design(P, nmeas, ncon, 1, init=([[-1.0]], [[1.0, 2.0]], [[1.0], [1.0]], [[0.0], [0.0]]))
    with pytest.raises(ValueError, match="initial controller"):
        hinfix.design(P, nmeas, ncon, 1, init=control.ss([], [], [], np.zeros((3, 3))))


def test_unclear_inputs_get_messages_that_name_them(he1, tmp_path):
    P, nmeas, ncon = he1
    # None is no system (python-control made a nonlinear system of it, and the error spoke of
    # an attribute or of "0 outputs")
    with pytest.raises(ValueError, match="sys must be a control.StateSpace .* got NoneType"):
        hinfix.hinfnorm(None)
    with pytest.raises(ValueError, match="P must be a control.StateSpace .* got NoneType"):
        hinfix.design(None, 1, 1, 1)
    for tol in ("a", None):
        with pytest.raises(TypeError, match="hinfnorm: tol must be a number in"):
            hinfix.hinfnorm(P, tol=tol)
    with pytest.raises(TypeError, match=r"structure block AK entry \(1, 1\) must be a real number"):
        hinfix.design(P, nmeas, ncon, 1, structure={"AK": [[1 + 2j]]}, maxevals=10)
    with pytest.raises(ValueError, match=r"option `hop_scales`: expected a number"):
        hinfix.design(P, nmeas, ncon, 1, hop_scales=[[0.1]], maxevals=10)
    # a 0-d array is no list (iterating it failed without the option's name)
    with pytest.raises(TypeError, match=r"hop_scales must be a list of numbers"):
        hinfix.design(P, nmeas, ncon, 1, hop_scales=np.array(0.1), maxevals=10)
    # a ragged matrix is named (numpy's own message did not say which)
    with pytest.raises(ValueError, match=r"A is not a real matrix"):
        hinfix.design([[[1.0, 2.0], [3.0]]] + [np.zeros((2, 1))] * 8, None, None, 1)
    # a structure that no stable controller fits is a bad argument (it was a HinfixError)
    with pytest.raises(ValueError, match="design: "):
        hinfix.design(P, nmeas, ncon, 1, structure={"AK": [[1.0]]}, maxevals=10)
    # an infinite fixed entry is named as such, not as "not a number" of a "structure file"
    with pytest.raises(ValueError, match=r"structure block DK entry \(1, 1\) is fixed at inf, which is not finite"):
        hinfix.design(P, nmeas, ncon, 1, structure={"DK": [[np.inf], [0.5]]}, maxevals=10)
    with pytest.raises(ValueError, match="order 10+ is larger than any plant's order"):
        hinfix.design(P, nmeas, ncon, 10**30)
    # a damaged best.csv (the report writes it whole; someone cut it)
    res = tmp_path / "c"
    res.mkdir()
    (res / "runs.jsonl").write_text("")
    (res / "best.csv").write_text("plant,order,objective,gamma\nHE1,1\n")
    with pytest.raises(ValueError, match=r"best.csv: line 2 does not have the header's 4 cells"):
        hinfix.read_results(res)
    (res / "best.csv").write_text("plant,order,objective,gamma\nHE1,notanumber,strong,0.1\n")
    with pytest.raises(ValueError, match=r"best.csv: line 2, column order: 'notanumber' is not a number"):
        hinfix.read_results(res)
    (res / "best.csv").unlink()
    (res / "best.csv").mkdir()
    with pytest.raises(ValueError, match=r"best.csv is not a file"):
        hinfix.read_results(res)
