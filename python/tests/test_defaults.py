"""One search everywhere: ``hinfix.design`` searches with the same defaults as
``campaign design`` and campaign jobs. The defaults come from the crate (``DesignOptions::default``,
``hinfix.default_options()``); a Rust test (src/cli/design.rs) holds the command's flags and a
campaign job to the same, and this file holds Python to them."""
import os
import re
import subprocess
from pathlib import Path

import pytest

import hinfix

REPO = Path(__file__).resolve().parents[2]


def test_an_option_left_out_is_the_crates_default():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    _, info = hinfix.design(P, nmeas, ncon, 1, maxevals=300)
    want = dict(hinfix.default_options(), order=1, maxevals=300)
    assert info.options == {k: v for k, v in want.items() if k in info.options}
    assert {k for k in want if k not in info.options} <= {"max_starts", "refine_rtol", "stall_cpu"}  # off: left out
    # the multi-start search: not HIFOO's bare starts (stall_starts 0, no hops, no open-loop or
    # central starts), which a record without these fields reads as
    assert info.options["stall_starts"] > 0
    assert info.options["hop_scales"] and info.options["central_gammas"]
    assert info.options["open_loop_start"] is True


def test_a_given_option_wins_and_none_means_default():
    P, nmeas, ncon = hinfix.load_plant("HE1")
    _, info = hinfix.design(P, nmeas, ncon, 1, maxevals=300, stall_starts=3, hop_scales=[], eps=None, seed=None)
    d = hinfix.default_options()
    assert info.options["stall_starts"] == 3 and info.options["hop_scales"] == []
    assert info.options["eps"] == d["eps"] and info.options["seed"] == d["seed"]
    assert info.options["cpumax"] == d["cpumax"]


def test_every_option_has_a_default():
    d = hinfix.default_options()
    assert list(d) == hinfix.option_names() or set(d) == set(hinfix.option_names())
    assert d["maxevals"] is None and d["max_starts"] is None  # no limit
    assert d["refine_rtol"] == 0.0 and isinstance(d["refine_rtol"], float)  # off, left out of records


def _campaign_binary():
    for p in (REPO / "target" / "release" / "campaign", REPO / "target" / "debug" / "campaign"):
        if p.is_file() and os.access(p, os.X_OK):
            return p
    return None


def _value(text):
    """A default as `campaign design --help` prints it: a comma-separated list ("none": empty),
    else a cell as best.csv writes one (a bool, an int, a float or the text)."""
    from hinfix._campaign import _cell
    if text == "none":
        return []
    if "," in text:
        return [float(x) for x in text.split(",")]
    return _cell(text)


@pytest.mark.skipif(_campaign_binary() is None, reason="no built `campaign` binary (cargo build --release)")
def test_the_commands_help_shows_the_same_defaults():
    help_text = subprocess.run([str(_campaign_binary()), "design", "--help"], capture_output=True, text=True,
                               check=True).stdout
    shown = {m.group(1).replace("-", "_"): _value(m.group(2))
             for m in re.finditer(r"--([a-z0-9-]+)[^\n]*(?:\n(?!\s*-)[^\n]*)*?\[default: ([^\]]+)\]", help_text)}
    d = hinfix.default_options()
    compared = 0
    for name, value in shown.items():
        if name in d:
            want = d[name]
            if isinstance(want, list):
                assert [float(x) for x in want] == (value if isinstance(value, list) else [float(value)]), name
            else:
                assert want == value, (name, want, value)
            compared += 1
    assert compared >= 10, (compared, sorted(shown))


# The problem arguments of design(); every other keyword is a design option.
_NOT_OPTIONS = {"P", "nmeas", "ncon", "objective", "weight", "bound", "structure", "strong", "init", "progress",
                "search_options"}


def test_every_keyword_of_design_is_an_option_of_the_table():
    """Options declared once: the keywords design() names are options of the crate's table (the
    others reach it through **search_options), and every option of the table is accepted as a
    keyword at its default, which it keeps."""
    import inspect
    import json

    from hinfix._design import options_json
    names = hinfix.option_names()
    named = set(inspect.signature(hinfix.design).parameters) - _NOT_OPTIONS
    assert named <= set(names), sorted(named - set(names))
    d = hinfix.default_options()
    for name in names:
        if name in ("order", "objective"):  # the positional order and strong=
            continue
        given = json.loads(options_json(1, None, {name: d[name]}))
        assert name in given or d[name] is None, name
