"""Shared fixtures: the shipped plants of the repository this package was built from."""
import os
from pathlib import Path

import pytest

import hinfix

REPO = Path(__file__).resolve().parents[2]
os.environ.setdefault("HINFIX_PLANTS", str(REPO / "plants"))

# Small shipped plants (n = 4, 4, 9) and evaluation budgets that keep each design well under a
# second or two: the budget is deterministic, so results repeat bit for bit.
SMALL_PLANTS = ("HE1", "REA2", "AC8")


@pytest.fixture(scope="session", params=SMALL_PLANTS)
def shipped(request):
    """(name, P, nmeas, ncon) of each small shipped plant."""
    P, nmeas, ncon = hinfix.load_plant(request.param)
    return request.param, P, nmeas, ncon
