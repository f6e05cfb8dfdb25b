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
    assert cols["order"].dtype == np.int64 and sorted(cols["order"]) == [0, 1]
    assert cols["seed"].dtype == np.int64
    best = {r["order"]: r for r in res.best}
    assert all(type(r["controller_stable"]) is bool for r in res.best), res.best
    assert [type(r["controller_stable"]) for r in summary["best"]] == [bool, bool]
    assert [best[r["order"]]["controller_stable"] for r in summary["best"]] == \
        [r["controller_stable"] for r in summary["best"]]
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


def test_progress_lines_go_to_sys_stderr(tmp_path, monkeypatch):
    import io
    import sys
    path = tmp_path / "small.toml"
    path.write_text(CAMPAIGN.replace("orders = [0, 1]", "orders = [0]"))
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)  # a Jupyter cell's stream, not file descriptor 2
    hinfix.run_campaign(path, tmp_path / "results", progress=True)
    assert "1 jobs: 0 already in the journal, 1 to run" in err.getvalue()
    assert "start  HE1" in err.getvalue()


def test_a_results_root_points_at_its_campaign_folders(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(CAMPAIGN.replace("orders = [0, 1]", "orders = [0]"))
    hinfix.run_campaign(path, tmp_path / "results")
    with pytest.raises(ValueError, match=r"is a results root, not a campaign's folder: it holds py-small"):
        hinfix.read_results(tmp_path / "results")


def test_a_torn_last_line_is_left_out_with_a_warning(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(CAMPAIGN.replace("orders = [0, 1]", "orders = [0]"))
    folder = hinfix.run_campaign(path, tmp_path / "results")["dir"]
    with open(f"{folder}/runs.jsonl", "a") as f:
        f.write('{"plant": "HE1", "ord')  # a run killed while writing
    with pytest.warns(UserWarning, match=r"runs.jsonl: line 2 is torn"):
        res = hinfix.read_results(folder)
    assert len(res) == 1


def test_to_pandas_gives_the_columns_or_says_what_is_missing(tmp_path, monkeypatch):
    import sys
    res = hinfix.read_results(tmp_path)
    monkeypatch.setitem(sys.modules, "pandas", None)  # as if pandas were not installed
    with pytest.raises(ImportError, match=r"needs pandas .*Results.columns\(\)"):
        res.to_pandas()
    monkeypatch.undo()
    pandas = pytest.importorskip("pandas")
    df = res.to_pandas("plant", "gamma")
    assert isinstance(df, pandas.DataFrame) and list(df.columns) == ["plant", "gamma"]
