"""The H∞ norm of a system and the full-order bound γ_opt of a plant."""
from __future__ import annotations

from typing import Any

import numpy as np

from . import _hinfix
from ._json import loads
from ._plant import blocks, system, sampling_time, as_matrix


def hinfnorm(sys: Any, tol: float = 1e-10) -> tuple[float, float]:
    """(‖sys‖∞, peak frequency in rad/s) of a continuous-time or discrete-time system, by hinfix's
    norm to relative tolerance ``tol`` (the design's own norm; on the unit circle in discrete
    time, the peak then at most the Nyquist frequency π/dt). ``sys`` is a ``control.StateSpace``
    or anything ``control.ss`` converts. An unstable system gives (inf, nan): its H∞ norm is
    infinite (unlike ``control.linfnorm``, which gives the L∞ norm). The frequency may be inf
    (continuous time, peak as ω → ∞)."""
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)):
        raise TypeError(f"hinfnorm: tol must be a number in (0, 1), got {tol!r}")
    sys = system(sys, "sys")
    a, b, c, d = (as_matrix(m, n) for m, n in zip((sys.A, sys.B, sys.C, sys.D), "ABCD"))
    return _hinfix.hinfnorm(a, b, c, d, float(tol), sampling_time(sys, "sys"))


def full_order_gamma(P: Any, nmeas: int | None, ncon: int | None) -> dict[str, Any]:
    """γ_opt of full-order H∞ synthesis for the plant ``P`` (partitioned as for
    ``control.hinfsyn``; continuous or discrete time): the bound below every fixed-order
    design's γ. Returns a dict: ``gamma`` (γ_opt, the feasible end of the final bracket),
    ``gamma_lower`` (its infeasible end), the regularisation used for a singular plant, the
    binding condition and diagnostics."""
    mats, dt = blocks(P, nmeas, ncon)
    name = getattr(P, "name", None) or "plant"
    return loads(_hinfix.full_order_gamma(list(mats), name, dt))
