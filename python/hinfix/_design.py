"""``hinfix.design``: one fixed-order H∞ design (HIFOO), python-control conventions."""
from __future__ import annotations

import functools
from typing import Any, Callable, Sequence, Union
import json
import math
import os
import sys
from dataclasses import dataclass, field

import numpy as np
import control

from . import _hinfix
from ._json import loads
from ._plant import as_matrix, blocks, controller, system, sampling_time

OBJECTIVES = ("hinf", "h2", "abscissa", "radius")

#: A plant: a ``control.StateSpace``, its nine matrices, or a list of ``StateSpace`` plants.
PlantLike = Union["control.StateSpace", Sequence[Any]]
#: A progress callback: called with a dict (phase, start, iteration, evaluations, cpu_s, best, done).
ProgressCallback = Callable[[dict], object]


@dataclass(frozen=True)
class DesignResult:
    """What a design returned, every figure recomputed from the returned controller.

    ``gamma`` is ‖Tzw‖∞ of the closed loop ``P.lft(K)`` (inf if it is unstable; with several
    plants or another objective, the largest weighted objective of the plants, see ``plants``),
    ``k_hinf`` is ‖K‖∞ (inf if K is unstable; σmax(Dk) for a static gain), ``alpha_cl`` and
    ``alpha_k`` the stability measures of the closed loop and of K (spectral abscissa; ρ − 1 in
    discrete time; ``alpha_k`` is None for order 0), ``objective`` max(γ, ε‖K‖∞) (strong) or γ
    (plain). ``status`` is one of "converged", "stopped", "stabilised_only", "not_stabilised",
    "bound_violated" (a stabilising controller that violates a plant's bound: see each plant's
    ``bound_met`` in ``plants``), "budget_exhausted", "interrupted". ``certificate`` is {"dnorm", "evaldist"} of the final
    point (None if the optimisation phase did not run), ``search`` the multi-start search's
    summary (starts, best start, time to best, why it stopped). ``closed_loop`` is
    ``P.lft(K)`` (of the first plant; ``closed_loops`` has every plant's), ``plants`` each
    plant's objective, value, weight and bound (empty for one plant with the H∞ objective).
    ``outcome`` is the whole outcome as the crate serialises it (the JSON of ``campaign design
    --json``).
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
    plants: list
    closed_loop: "control.StateSpace" = field(repr=False)
    closed_loops: list = field(repr=False)
    outcome: dict = field(repr=False)


def _float(x):
    return None if x is None else float(x)


@functools.lru_cache(maxsize=1)
def _defaults():
    return loads(_hinfix.default_options())


def default_options() -> dict[str, Any]:
    """Every design option with its default, as a dict: the crate's option table
    (``DesignOptions::default``), the defaults of ``campaign design`` and of campaign files. An
    option left out of ``design()`` takes this value. Optional limits without a default
    (``maxevals``, ``max_starts``) are absent."""
    return dict(_defaults())


def _json_value(v):
    """An option value as the crate's JSON reads it (non-finite floats as strings)."""
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return v if math.isfinite(v) else str(v)  # "inf", "-inf", "nan"
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_json_value(x) for x in v]
    return v


def _is_int(v):
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def _is_real(v):
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


# Whole-number options are unsigned 64-bit integers in the crate.
_U64_MAX = 2**64 - 1


def _check_option(name, value):
    """A TypeError or ValueError, in the words of the option table, for a value of the wrong
    kind (the kind of the option's default); ranges are the crate's to check."""
    default = _defaults().get(name)
    if isinstance(default, bool):
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"{name} must be True or False, got {value!r}")
    elif isinstance(default, int) or default is None:  # whole numbers; None: an optional limit
        if default is None and value is None:
            return
        if not _is_int(value):
            raise TypeError(f"{name} must be a whole number, got {value!r}")
        if value < 0:
            raise ValueError(f"{name} must be ≥ 0, got {value}")
        if value > _U64_MAX:
            raise ValueError(f"{name} must be at most 2**64 - 1, got {value}")
    elif isinstance(default, float):
        if not _is_real(value):
            raise TypeError(f"{name} must be a number, got {value!r}")
    elif isinstance(default, list):
        # a 0-d array is one number, not a list (iterating it fails later, without the name)
        items = None if isinstance(value, (str, bytes)) else np.asarray(value, dtype=object)
        if items is None or items.ndim == 0 or not all(_is_real(x) for x in np.ravel(items)):
            raise TypeError(f"{name} must be a list of numbers, got {value!r}")
    elif isinstance(default, str):
        if not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {value!r}")


def options_json(order, strong, given):
    """The JSON object of the options given (the others are the crate's defaults)."""
    if not _is_int(order):
        raise TypeError(f"order must be a whole number ≥ 0, got {order!r}")
    if order < 0:
        raise ValueError(f"order must be ≥ 0, got {order}")
    if order > 2**32:  # beyond any plant's order (the crate then says "exceeds the plant order")
        raise ValueError(f"order {order} is larger than any plant's order")
    if "objective" in given:
        raise TypeError("use strong=True/False instead of objective= for the strong-stabilisation objective "
                        "(objective= names each plant's objective: hinf, h2, abscissa, radius)")
    names = _hinfix.option_names()
    unknown = sorted(set(given) - set(names))
    if unknown:
        raise TypeError(f"unknown design option(s) {', '.join(unknown)}; the options are {', '.join(names)}")
    opts = {"order": int(order)}
    if strong is not None:
        if not isinstance(strong, (bool, np.bool_)):
            raise TypeError(f"strong must be True or False, got {strong!r}")
        opts["objective"] = "strong" if strong else "plain"
    for k, v in given.items():
        if v is None and k not in ("maxevals", "max_starts"):
            continue  # not given: the default
        _check_option(k, v)
        opts[k] = v
    return json.dumps({k: _json_value(v) for k, v in opts.items()})


def _init_matrices(init, dt):
    """The four matrices of ``init``; a ``StateSpace`` with states must be in the plant's time
    domain (sampling time ``dt``, 0: continuous): its matrices mean another controller in the
    other one (a discrete pole 0.5 read as continuous is unstable). python-control's ``dt=None``
    (no time base) and a static gain fit either."""
    if init is None:
        return None
    if isinstance(init, (tuple, list)):
        if len(init) != 4:
            raise ValueError(f"init as matrices needs (Ak, Bk, Ck, Dk), got {len(init)}")
        return [as_matrix(m, n) for m, n in zip(init, ("Ak", "Bk", "Ck", "Dk"))]
    K = system(init, "init")
    k_dt = sampling_time(K, "init")
    if K.nstates > 0 and K.dt is not None and k_dt != dt:
        def domain(ts):
            return "continuous time" if ts == 0 else f"discrete time (dt = {ts:g} s)"
        raise ValueError(f"init is in {domain(k_dt)} but the plant is in {domain(dt)}: "
                         "give the controller in the plant's time domain")
    return [as_matrix(m, n) for m, n in zip((K.A, K.B, K.C, K.D), ("Ak", "Bk", "Ck", "Dk"))]


def _per_plant(value, n, name, check):
    """One value per plant: a single value (every plant) or a list of one per plant, as the
    command's repeated flags."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()  # a 1-D array is a list of one value per plant, as a list is
    if isinstance(value, (list, tuple)):
        if len(value) != n:
            raise ValueError(f"{name} has {len(value)} values for {n} plant(s): give one (for every plant) "
                             "or one per plant")
        values = list(value)
    else:
        values = [value] * n
    return [check(v) for v in values]


def _objective(v):
    if v in ("strong", "plain"):
        raise TypeError(f"objective={v!r}: use strong=True/False for the strong-stabilisation objective "
                        "(objective= names each plant's objective: hinf, h2, abscissa, radius)")
    if not isinstance(v, str) or v not in OBJECTIVES:
        raise ValueError(f"objective must be one of {', '.join(OBJECTIVES)}, got {v!r}")
    return v


def _weight(v):
    if not _is_real(v):
        raise TypeError(f"weight must be a number, got {v!r}")
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"weight must be finite and > 0, got {v}")
    return float(v)


def _bound(v):
    if v is None:
        return None
    if not _is_real(v):
        raise TypeError(f"bound must be a number or None, got {v!r}")
    if not math.isfinite(v):
        raise ValueError(f"bound must be finite (or None for no bound), got {v}")
    return float(v)


def _structure(structure):
    """(JSON text, path) of ``structure``: a path to a structure file, a dict of blocks
    {"AK", "BK", "CK", "DK"} or a tuple (AK, BK, CK, DK) of arrays, None or NaN = free."""
    if structure is None:
        return None, None
    if isinstance(structure, (str, os.PathLike)):
        return None, os.fspath(structure)
    if isinstance(structure, (tuple, list)):
        if len(structure) != 4:
            raise ValueError(f"a structure as blocks needs (AK, BK, CK, DK), got {len(structure)}")
        structure = dict(zip(("AK", "BK", "CK", "DK"), structure))
    if not isinstance(structure, dict):
        raise TypeError(f"structure must be a file path, a dict of blocks AK, BK, CK, DK or a tuple of them, "
                        f"got {type(structure).__name__}")
    out = {}
    for k, block in structure.items():
        if block is None:
            continue  # a block left out is free
        rows = np.asarray(block, dtype=object)
        if rows.ndim != 2:
            raise ValueError(f"structure block {k} must be 2-D, got shape {rows.shape}")
        def cell(x, i, j):
            if x is None or (_is_real(x) and math.isnan(x)):
                return None
            if not _is_real(x):
                raise TypeError(f"structure block {k} entry ({i + 1}, {j + 1}) must be a real number, "
                                f"None or NaN (free), got {x!r}")
            if not math.isfinite(x):
                raise ValueError(f"structure block {k} entry ({i + 1}, {j + 1}) is fixed at {x}, which is not "
                                 f"finite (None or NaN: free)")
            return _json_value(x)
        out[k] = [[cell(x, i, j) for j, x in enumerate(row)] for i, row in enumerate(rows)]
    return json.dumps(out), None


def _print_progress(p):
    """The default progress display: one line on ``sys.stderr`` (a Jupyter cell shows it),
    rewritten in place."""
    best = "—" if not math.isfinite(p["best"]) else f"{p['best']:.6g}"
    sys.stderr.write(f"\rhinfix.design: {p['phase']:<17} start {p['start']:>4}  {p['evaluations']:>9} evaluations  "
                     f"{p['cpu_s']:8.1f} CPU s  best objective {best}   ")
    if p["done"]:
        sys.stderr.write("\n")
    sys.stderr.flush()


def _plants(P, nmeas, ncon):
    """[(StateSpace or None, nine matrices, dt, nmeas, ncon)] of one plant or a list of
    StateSpace plants."""
    several = isinstance(P, (list, tuple)) and len(P) > 0 and all(isinstance(x, control.StateSpace) for x in P)
    if not several:
        mats, dt = blocks(P, nmeas, ncon)
        return [(P if isinstance(P, control.StateSpace) else None, mats, dt, mats[4].shape[0], mats[2].shape[1])]
    nm = _per_plant(nmeas, len(P), "nmeas", lambda v: v)
    nc = _per_plant(ncon, len(P), "ncon", lambda v: v)
    out = []
    for i, (p, m, c) in enumerate(zip(P, nm, nc)):
        mats, dt = blocks(p, m, c)
        out.append((p, mats, dt, mats[4].shape[0], mats[2].shape[1]))
    dts = {dt for _, _, dt, _, _ in out}
    if len(dts) > 1:
        raise ValueError(f"the plants must share one time domain, got sampling times {sorted(dts)}")
    return out


def design(P: PlantLike, nmeas: int | Sequence[int] | None, ncon: int | Sequence[int] | None, order: int, *,
           objective: str | Sequence[str] = "hinf", weight: float | Sequence[float] = 1.0,
           bound: float | None | Sequence[float | None] = None, structure: Any = None,
           strong: bool | None = None, eps: float | None = None, seed: int | None = None,
           cpumax: float | None = None, maxevals: int | None = None, init: Any = None,
           progress: bool | ProgressCallback | None = None,
           **search_options: Any) -> tuple[control.StateSpace, DesignResult]:
    """Designs a controller of order ``order`` for the generalised plant ``P``.

    ``P`` is a ``control.StateSpace`` (continuous time, or discrete time with its sampling time
    ``dt``) partitioned as ``control.hinfsyn(P, nmeas, ncon)`` expects (the last ``nmeas``
    outputs are measured, the last ``ncon`` inputs are controls; at least one input w and one
    output z remain), or the nine matrices (A, B1, B2, C1, C2, D11, D12, D21, D22) of a
    continuous-time plant (then nmeas and ncon may be None), or a list of ``StateSpace`` plants
    (one controller for all of them, as ``campaign design`` with several ``--plant``; then
    ``nmeas``, ``ncon``, ``objective``, ``weight`` and ``bound`` are one value for every plant
    or a list of one per plant). ``objective`` is "hinf" (‖Tzw‖∞), "h2", "abscissa" or
    "radius"; ``weight`` w > 0 and ``bound`` b (w·g ≤ b, None: none) as the command's
    ``--weight`` and ``--bound``. ``structure`` fixes controller entries: a structure file
    (JSON or .mat), a dict {"AK", "BK", "CK", "DK"} of blocks or a tuple of the four, with None
    or NaN for a free entry and a number for a fixed one (a block left out is free).

    With ``strong`` (the default) it minimises max(objective, ε‖K‖∞) over stable controllers
    (strong stabilisation), else the objective alone. ``seed`` fixes every random choice (same
    seed, same controller, when the run is ended by ``maxevals`` or its own stopping rules rather
    than by ``cpumax``, which counts this thread's CPU seconds). ``init`` is a starting
    controller (``StateSpace`` or (Ak, Bk, Ck, Dk)) of order ≤ ``order``. Further keyword
    arguments are the design options of the hinfix option table (``hinfix.option_names()``:
    nrand, stall_starts, max_starts, hop_scales, …). Every option left out or None (``eps``,
    ``seed``, ``cpumax`` included) takes the crate's default, ``hinfix.default_options()``: the
    same search as ``campaign design`` and campaign jobs.

    ``progress``: True prints a line on ``sys.stderr`` while the design runs (it shows in a
    Jupyter cell), a callable is called with a dict (phase, start, iteration, evaluations,
    cpu_s, best, done) at most every 0.25 s; an exception it raises stops the design.

    Returns ``(K, info)``: ``K`` a ``control.StateSpace`` (positive feedback u = K y, as
    ``hinfsyn`` returns it, so ``P.lft(K)`` is the closed loop; its inputs named after P's
    measurements and its outputs after P's controls; P's sampling time) and ``info`` a
    ``DesignResult`` (``info.closed_loop`` is ``P.lft(K)``). Not stabilising is a result
    (``info.status == "not_stabilised"``), not an error. Bad arguments raise ValueError or
    TypeError; Ctrl-C stops the design and raises KeyboardInterrupt.
    """
    plants = _plants(P, nmeas, ncon)
    n = len(plants)
    objectives = _per_plant(objective, n, "objective", _objective)
    weights = _per_plant(weight, n, "weight", _weight)
    bounds = _per_plant(bound, n, "bound", _bound)
    given = dict(search_options, eps=eps, seed=seed, cpumax=cpumax)
    if maxevals is not None:
        given["maxevals"] = maxevals
    opts = options_json(order, strong, given)
    terms = []
    for i, (sys_, mats, dt, _, _) in enumerate(plants):
        name = getattr(sys_, "name", None) or ("plant" if n == 1 else f"plant {i + 1}")  # for messages
        terms.append((name, list(mats), dt, objectives[i], weights[i], bounds[i]))
    s_json, s_path = _structure(structure)
    if progress is True:
        progress = _print_progress
    elif progress is False or progress is None:
        progress = None
    elif not callable(progress):
        raise TypeError(f"progress must be True, False or a callable, got {progress!r}")
    (ak, bk, ck, dk), text, used = _hinfix.design(terms, opts, _init_matrices(init, plants[0][2]), s_json, s_path, progress)
    out = loads(text)
    status = out["status"]["kind"]
    gamma, k_hinf = _float(out["gamma"]), _float(out["k_hinf"])
    alpha_k = _float(out.get("alpha_k"))
    stabilised = status not in ("not_stabilised", "interrupted") and math.isfinite(gamma)
    sys0, _, dt, nm0, nc0 = plants[0]
    K = controller(ak, bk, ck, dk, sys0, nm0, nc0, dt)
    loops = [_closed_loop(p, mats, dt, K, (ak, bk, ck, dk)) for p, mats, dt, _, _ in plants]
    info = DesignResult(
        gamma=gamma,
        k_hinf=k_hinf,
        alpha_cl=_float(out["alpha_cl"]),
        alpha_k=alpha_k,
        objective=_float(out["objective"]),
        status=status,
        stabilised=bool(stabilised),
        strongly_stabilised=bool(stabilised and math.isfinite(k_hinf) and (alpha_k is None or alpha_k < 0)),
        controller_norm_active=bool(out.get("controller_norm_active", False)),
        certificate=None if out.get("certificate") is None else
        {k: _float(v) for k, v in out["certificate"].items()},
        search={k: (_float(v) if k == "cpu_to_best_s" else v) for k, v in out["search"].items()},
        iterations=int(out["iterations"]),
        evaluations=int(out["evaluations"]),
        design_cpu_s=_float(out["design_cpu_s"]),
        options=loads(used),
        plants=list(out.get("plants", [])),
        closed_loop=loops[0],
        closed_loops=loops,
        outcome=out,
    )
    return K, info


def _closed_loop(P, mats, dt, K, k_matrices):
    """``P.lft(K)`` (of the plant's nine matrices when it came as matrices); where python-control
    refuses it — its well-posedness test depends on the scale of Dk, and a plant without w or z
    channels is no python-control system — the crate's closed loop, the one the design measured
    (``_hinfix.closed_loop``), with P's w inputs and z outputs as its names when P has them."""
    try:
        if P is None:
            from ._plant import statespace
            P, _, _ = statespace(mats, dt=dt)
        return P.lft(K)
    except ValueError:  # control.ControlDimension is a ValueError too
        pass
    a, b, c, d = _hinfix.closed_loop(list(mats), list(k_matrices), dt)
    names = {}
    if P is not None and hasattr(P, "input_labels"):
        names = {"inputs": list(P.input_labels[:b.shape[1]]), "outputs": list(P.output_labels[:c.shape[0]])}
    return control.ss(a, b, c, d, dt, **names)
