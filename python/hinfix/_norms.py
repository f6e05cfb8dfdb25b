"""The H∞ norm of a system and the full-order bound γ_opt of a plant."""
from . import _hinfix
from ._json import loads
from ._plant import blocks, continuous, as_matrix


def hinfnorm(sys, tol=1e-10):
    """(‖sys‖∞, peak frequency in rad/s) of a continuous-time system, by hinfix's norm to relative
    tolerance ``tol`` (the design's own norm). ``sys`` is a ``control.StateSpace`` or anything
    ``control.ss`` converts. An unstable system gives (inf, nan): its H∞ norm is infinite (unlike
    ``control.linfnorm``, which gives the L∞ norm). The frequency may be inf (peak as ω → ∞)."""
    sys = continuous(sys, "sys")
    a, b, c, d = (as_matrix(m, n) for m, n in zip((sys.A, sys.B, sys.C, sys.D), "ABCD"))
    return _hinfix.hinfnorm(a, b, c, d, float(tol))


def full_order_gamma(P, nmeas, ncon):
    """γ_opt of full-order H∞ synthesis for the plant ``P`` (partitioned as for
    ``control.hinfsyn``): the bound below every fixed-order design's γ. Returns a dict: ``gamma``
    (γ_opt, the feasible end of the final bracket), ``gamma_lower`` (its infeasible end), the
    regularisation used for a singular plant, the binding condition and diagnostics."""
    return loads(_hinfix.full_order_gamma(list(blocks(P, nmeas, ncon))))
