"""run_campaign and read_results: a small campaign file run from Python, its folder read back
into plain data, and the journaled controllers checked against python-control."""
import numpy as np
import pytest
import control

import hinfix
from check import linfnorm, relerr

CAMPAIGN = """
name = "py-small"
[defaults]
eps = [1e-3]
seeds = 1
cpumax = 30.0
maxevals = 300
threads = 2
trace = "off"

[[problem]]
plant = "HE1"
orders = [0, 1]
"""


def test_run_then_read_a_campaign(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(CAMPAIGN)
    summary = hinfix.run_campaign(path, tmp_path / "results")
    assert summary["total"] == 2 and summary["finished"] == 2 and summary["failed"] == 0
    again = hinfix.run_campaign(path, tmp_path / "results")  # resumes: nothing left to do
    assert again["already_done"] == 2 and again["finished"] == 0

    res = hinfix.read_results(summary["dir"])
    assert len(res) == 2
    cols = res.columns()
    assert cols["order"].dtype == float and sorted(cols["order"]) == [0.0, 1.0]
    assert list(cols["plant"]) == ["HE1", "HE1"]
    assert np.all(np.isfinite(cols["gamma"]))
    assert {r["order"] for r in res.best} == {0, 1}

    P, nmeas, ncon = hinfix.load_plant("HE1")
    for rec in res.records:
        c = rec["controller"]
        nk = rec["order"]
        K = control.ss(np.reshape(c["AK"], (nk, nk)), np.reshape(c["BK"], (nk, nmeas)),
                       np.reshape(c["CK"], (ncon, nk)), np.array(c["DK"]))
        assert relerr(rec["gamma"], linfnorm(P.lft(K))) <= 1e-8


def test_an_empty_folder_reads_as_no_records(tmp_path):
    res = hinfix.read_results(tmp_path)
    assert len(res) == 0 and res.best == [] and res.columns()["gamma"].shape == (0,)


def test_a_bad_campaign_file_is_a_value_error(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n[[problem]]\nplant = "HE1"\norders = [1]\nnrandd = 3\n')
    with pytest.raises(ValueError, match="nrandd"):
        hinfix.run_campaign(path, tmp_path)
