"""The Python package on a par with the command: discrete-time plants, several plants
with objectives, weights and bounds, structures, K's signal names, the closed loop, progress,
types; every figure checked against python-control."""
import importlib.metadata
import io
import json
import sys

import numpy as np
import pytest
import control

import hinfix
from check import linfnorm, relerr

BUDGET = dict(maxevals=600, cpumax=30.0)


@pytest.fixture(scope="module")
def he1():
    return hinfix.load_plant("HE1")


def test_version_is_the_packages():
    assert hinfix.__version__ == importlib.metadata.version("hinfix")


def test_a_discrete_time_plant_agrees_with_python_control(he1):
    P, nmeas, ncon = he1
    Pd = control.c2d(P, 0.1)
    K, info = hinfix.design(Pd, nmeas, ncon, 1, **BUDGET)
    assert info.stabilised and K.dt == 0.1 and info.closed_loop.dt == 0.1
    CL = Pd.lft(K)
    assert np.max(np.abs(np.linalg.eigvals(CL.A))) < 1 and np.max(np.abs(np.linalg.eigvals(K.A))) < 1
    assert relerr(info.gamma, linfnorm(CL)) <= 1e-8, (info.gamma, linfnorm(CL))
    assert relerr(info.k_hinf, linfnorm(K)) <= 1e-8
    value, w = hinfix.hinfnorm(CL)
    assert relerr(value, linfnorm(CL)) <= 1e-8 and 0 <= w <= np.pi / 0.1 + 1e-9


def test_a_discrete_plant_file_loads_with_its_sampling_time():
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "examples" / "discrete" / "HE1_Ts0.1.json"
    P, nmeas, ncon = hinfix.load_plant(path)
    assert P.dt == 0.1 and (nmeas, ncon) == (1, 2) and P.name == "HE1_Ts0_1"


def test_python_controls_unspecified_sampling_time_is_refused(he1):
    P, nmeas, ncon = he1
    Pd = control.ss(P.A, P.B, P.C, P.D, dt=True)
    with pytest.raises(ValueError, match="unspecified sampling time"):
        hinfix.design(Pd, nmeas, ncon, 1)


def test_two_plants_weights_and_bounds_agree_with_python_control(he1):
    P, nmeas, ncon = he1
    P2 = control.ss(P.A * 1.05, P.B, P.C, P.D)
    K, info = hinfix.design([P, P2], nmeas, ncon, 1, weight=[1.0, 2.0], **BUDGET)
    K_weighted = K
    assert info.stabilised and len(info.plants) == 2 and len(info.closed_loops) == 2
    g = [linfnorm(P.lft(K)), linfnorm(P2.lft(K))]
    for v, gi, w in zip(info.plants, g, (1.0, 2.0)):
        assert relerr(v["value"], gi) <= 1e-8 and v["weight"] == w
    assert relerr(info.gamma, max(g[0], 2.0 * g[1])) <= 1e-8
    # a bound on the second plant: it leaves the max and must hold at the end
    K, info = hinfix.design([P, P2], nmeas, ncon, 1, bound=[None, 10.0], **BUDGET)
    assert info.plants[1]["bound"] == 10.0 and linfnorm(P2.lft(K)) <= 10.0 * (1 + 1e-6)
    assert relerr(info.gamma, linfnorm(P.lft(K))) <= 1e-8
    with pytest.raises(ValueError, match="weight has 3 values for 2 plant"):
        hinfix.design([P, P2], nmeas, ncon, 1, weight=[1.0, 2.0, 3.0])
    # a 1-D array is one value per plant, as a list is
    K2, info2 = hinfix.design([P, P2], nmeas, ncon, 1, weight=np.array([1.0, 2.0]), **BUDGET)
    assert np.array_equal(K2.D, K_weighted.D) and [v["weight"] for v in info2.plants] == [1.0, 2.0]


def test_the_h2_objective_agrees_with_python_control(he1):
    P, nmeas, ncon = he1
    K, info = hinfix.design(P, nmeas, ncon, 1, objective="h2", **BUDGET)
    CL = info.closed_loop
    assert np.allclose(CL.D, 0, atol=1e-10)  # the H2 feedthrough constraint
    h2 = float(np.sqrt(np.trace(CL.C @ control.lyap(CL.A, CL.B @ CL.B.T) @ CL.C.T)))
    assert relerr(info.plants[0]["value"], h2) <= 1e-8


def test_a_structure_fixes_entries_bit_for_bit(he1):
    P, nmeas, ncon = he1
    dk = np.full((ncon, nmeas), np.nan)
    dk[1, 0] = 0.25
    K, info = hinfix.design(P, nmeas, ncon, 1, structure={"DK": dk, "AK": [[-1.0]]}, **BUDGET)
    assert K.D[1, 0] == 0.25 and K.A[0, 0] == -1.0 and info.stabilised
    # every entry fixed: evaluated once and answered at once, as by `campaign design` (HE1's
    # optimal static gain at ε = 1e-3)
    dk = [[8.99941740947262], [153.81173268664625]]
    K, info = hinfix.design(P, nmeas, ncon, 0, structure={"DK": dk})
    assert info.search["stop"] == "no_free_variable" and info.evaluations == 1
    assert K.D[0, 0] == dk[0][0] and K.D[1, 0] == dk[1][0]
    assert info.stabilised and abs(info.gamma - 0.154124) < 1e-6


def test_k_is_named_after_the_plants_partition_and_closes_the_loop(he1):
    P, nmeas, ncon = he1
    K, info = hinfix.design(P, nmeas, ncon, 1, **BUDGET)
    assert list(K.input_labels) == list(P.output_labels[-nmeas:]) == ["y[0]"]
    assert list(K.output_labels) == list(P.input_labels[-ncon:]) == ["u[0]", "u[1]"]
    CL = P.lft(K)
    for m in "ABCD":
        np.testing.assert_array_equal(getattr(info.closed_loop, m), getattr(CL, m))
    named = control.ss(P.A, P.B, P.C, P.D, inputs=["w1", "w2", "thrust", "pitch"], outputs=["z1", "z2", "alt"])
    K, _ = hinfix.design(named, nmeas, ncon, 0, **BUDGET)
    assert list(K.input_labels) == ["alt"] and list(K.output_labels) == ["thrust", "pitch"]


def test_result_types_are_pythons(he1):
    P, nmeas, ncon = he1
    _, info = hinfix.design(P, nmeas, ncon, 1, **BUDGET)
    assert type(info.stabilised) is bool and type(info.strongly_stabilised) is bool
    assert type(info.iterations) is int and type(info.evaluations) is int
    assert type(info.controller_norm_active) is bool and isinstance(info.gamma, float)


def test_progress_reaches_a_callback_and_sys_stderr(he1, monkeypatch):
    P, nmeas, ncon = he1
    seen = []
    _, info = hinfix.design(P, nmeas, ncon, 2, maxevals=3000, progress=seen.append)
    assert seen and seen[-1]["done"] is True and seen[-1]["evaluations"] <= info.evaluations
    assert {"phase", "start", "iteration", "evaluations", "cpu_s", "best"} <= set(seen[-1])
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)  # a Jupyter cell's stream is sys.stderr, not fd 2
    hinfix.design(P, nmeas, ncon, 1, maxevals=300, progress=True)
    assert "hinfix.design:" in err.getvalue() and err.getvalue().endswith("\n")

    def stop(_):
        raise RuntimeError("enough")
    with pytest.raises(RuntimeError, match="enough"):
        hinfix.design(P, nmeas, ncon, 2, maxevals=3000, progress=stop)


def test_arguments_are_checked_in_the_projects_words(he1):
    P, nmeas, ncon = he1
    with pytest.raises(ValueError, match=r"ncon must be in 1..=3 .*one at least is w"):
        hinfix.design(P, nmeas, P.ninputs, 1)
    with pytest.raises(ValueError, match=r"nmeas must be in 1..=2 .*one at least is z"):
        hinfix.design(P, P.noutputs, ncon, 1)
    with pytest.raises(TypeError, match="strong must be True or False, got 'no'"):
        hinfix.design(P, nmeas, ncon, 1, strong="no")
    with pytest.raises(TypeError, match="order must be a whole number ≥ 0, got 1.5"):
        hinfix.design(P, nmeas, ncon, 1.5)
    with pytest.raises(TypeError, match="nrand must be a whole number, got '3'"):
        hinfix.design(P, nmeas, ncon, 1, nrand="3")
    with pytest.raises(TypeError, match="open_loop_start must be True or False"):
        hinfix.design(P, nmeas, ncon, 1, open_loop_start="no")
    with pytest.raises(ValueError, match="objective must be one of hinf, h2, abscissa, radius"):
        hinfix.design(P, nmeas, ncon, 1, objective="hinfinity")
    with pytest.raises(TypeError, match="progress must be True, False or a callable"):
        hinfix.design(P, nmeas, ncon, 1, progress="yes")
    for bad in (dict(order=1.5), dict(nrand=2.5), dict(stall_starts=-1)):
        with pytest.raises((TypeError, ValueError)) as e:
            hinfix.design(P, nmeas, ncon, **{"order": 1, **bad})
        assert not any(w in str(e.value) for w in ("usize", "u64", "f64", "untagged", "invalid type")), e.value


def test_the_crates_serde_messages_are_put_in_plain_words():
    # past the Python checks (a list where a number is wanted, given directly to the bindings)
    P, nmeas, ncon = hinfix.load_plant("HE1")
    from hinfix._plant import blocks
    mats, dt = blocks(P, nmeas, ncon)
    with pytest.raises(ValueError) as e:
        hinfix._hinfix.design([("HE1", list(mats), dt, "hinf", 1.0, None)], json.dumps({"order": 1.5}))
    assert "option `order`" in str(e.value) and "usize" not in str(e.value), e.value
