"""``hinfix.design``: one fixed-order H∞ design (HIFOO), python-control conventions."""
import json
import math
from dataclasses import dataclass, field

import numpy as np

from . import _hinfix
from ._json import loads
from ._plant import blocks, controller, as_matrix, continuous


@dataclass(frozen=True)
class DesignResult:
    """What a design returned, every figure recomputed from the returned controller.

    ``gamma`` is ‖Tzw‖∞ of the closed loop ``P.lft(K)`` (inf if it is unstable), ``k_hinf`` is
    ‖K‖∞ (inf if K is unstable; σmax(Dk) for a static gain), ``alpha_cl`` and ``alpha_k`` the
    spectral abscissas of the closed loop and of K (``alpha_k`` is None for order 0),
    ``objective`` max(γ, ε‖K‖∞) (strong) or γ (plain). ``status`` is one of "converged",
    "stopped", "stabilised_only", "not_stabilised", "budget_exhausted", "interrupted".
    ``certificate`` is {"dnorm", "evaldist"} of the final point (None if the optimisation phase
    did not run), ``search`` the multi-start search's summary (starts, best start, time to best,
    why it stopped). ``outcome`` is the whole outcome as the crate serialises it (the JSON of
    ``campaign design --json``).
    """

    gamma: float
    k_hinf: float
    alpha_cl: float
    alpha_k: "float | None"
    objective: float
    status: str
    stabilised: bool
    strongly_stabilised: bool
    controller_norm_active: bool
    certificate: "dict | None"
    search: dict
    iterations: int
    evaluations: int
    design_cpu_s: float
    options: dict
    outcome: dict = field(repr=False)


def _float(x):
    return None if x is None else float(x)


def _json_value(name, v):
    """An option value as the crate's JSON reads it (non-finite floats as strings)."""
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return v if math.isfinite(v) else str(v)  # "inf", "-inf", "nan"
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_json_value(name, x) for x in v]
    return v


def options_json(order, eps, strong, seed, cpumax, maxevals, search_options):
    for reserved in ("order", "eps", "seed", "cpumax", "maxevals", "objective"):
        if reserved in search_options:
            raise TypeError(f"give {reserved!r} as design()'s own argument" if reserved != "objective"
                            else "use strong=True/False instead of objective=")
    unknown = sorted(set(search_options) - set(_hinfix.option_names()))
    if unknown:
        raise TypeError(f"unknown design option(s) {', '.join(unknown)}; "
                        f"the options are {', '.join(_hinfix.option_names())}")
    opts = {"order": order, "eps": eps, "seed": seed, "cpumax": cpumax,
            "objective": "strong" if strong else "plain", **search_options}
    if maxevals is not None:
        opts["maxevals"] = maxevals
    return json.dumps({k: _json_value(k, v) for k, v in opts.items()})


def _init_matrices(init):
    if init is None:
        return None
    if isinstance(init, (tuple, list)):
        if len(init) != 4:
            raise ValueError(f"init as matrices needs (Ak, Bk, Ck, Dk), got {len(init)}")
        return [as_matrix(m, n) for m, n in zip(init, ("Ak", "Bk", "Ck", "Dk"))]
    K = continuous(init, "init")
    return [as_matrix(m, n) for m, n in zip((K.A, K.B, K.C, K.D), ("Ak", "Bk", "Ck", "Dk"))]


def design(P, nmeas, ncon, order, *, eps=1e-3, strong=True, seed=0, cpumax=60.0,
           maxevals=None, init=None, **search_options):
    """Designs a controller of order ``order`` for the generalised plant ``P``.

    ``P`` is a continuous-time ``control.StateSpace`` partitioned as ``control.hinfsyn(P,
    nmeas, ncon)`` expects (the last ``nmeas`` outputs are measured, the last ``ncon`` inputs are
    controls), or the nine matrices (A, B1, B2, C1, C2, D11, D12, D21, D22; then nmeas and ncon
    may be None). With ``strong``
    (the default) it minimises max(‖Tzw‖∞, ε‖K‖∞) over stable controllers (strong
    stabilisation), else ‖Tzw‖∞ alone. ``seed`` fixes every random choice (same seed, same
    controller, when the run is ended by ``maxevals`` or its own stopping rules rather than by
    ``cpumax``, which counts this thread's CPU seconds). ``init`` is a starting controller
    (``StateSpace`` or (Ak, Bk, Ck, Dk)) of order ≤ ``order``. Further keyword arguments are the
    design options of the hinfix option table (``hinfix.option_names()``: nrand, stall_starts,
    max_starts, hop_scales, …).

    Returns ``(K, info)``: ``K`` a ``control.StateSpace`` (positive feedback u = K y, as
    ``hinfsyn`` returns it, so ``P.lft(K)`` is the closed loop) and ``info`` a ``DesignResult``.
    Not stabilising is a result (``info.status == "not_stabilised"``), not an error. Bad
    arguments raise ValueError or TypeError; Ctrl-C stops the design and raises
    KeyboardInterrupt.
    """
    mats = blocks(P, nmeas, ncon)
    opts = options_json(order, eps, strong, seed, cpumax, maxevals, search_options)
    name = getattr(P, "name", None) or "plant"  # python-control's name, for messages
    (ak, bk, ck, dk), text, used = _hinfix.design(list(mats), opts, _init_matrices(init), name)
    out = loads(text)
    status = out["status"]["kind"]
    gamma, k_hinf = _float(out["gamma"]), _float(out["k_hinf"])
    alpha_k = _float(out.get("alpha_k"))
    stabilised = status not in ("not_stabilised", "interrupted") and math.isfinite(gamma)
    info = DesignResult(
        gamma=gamma,
        k_hinf=k_hinf,
        alpha_cl=_float(out["alpha_cl"]),
        alpha_k=alpha_k,
        objective=_float(out["objective"]),
        status=status,
        stabilised=stabilised,
        strongly_stabilised=stabilised and math.isfinite(k_hinf) and (alpha_k is None or alpha_k < 0),
        controller_norm_active=bool(out.get("controller_norm_active", False)),
        certificate=None if out.get("certificate") is None else
        {k: _float(v) for k, v in out["certificate"].items()},
        search={k: (_float(v) if k == "cpu_to_best_s" else v) for k, v in out["search"].items()},
        iterations=out["iterations"],
        evaluations=out["evaluations"],
        design_cpu_s=_float(out["design_cpu_s"]),
        options=loads(used),
        outcome=out,
    )
    return controller(ak, bk, ck, dk), info
