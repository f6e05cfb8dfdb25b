"""hinfix: fixed-order H∞ controller design with strong stabilisation (the HIFOO method of
Burke, Henrion, Lewis and Overton; strong stabilisation after Gumussoy, Millstone and Overton,
CDC 2008), with python-control's conventions.

    import control, hinfix
    P, nmeas, ncon = hinfix.load_plant("HE1")      # or any control.StateSpace plant
    K, info = hinfix.design(P, nmeas, ncon, 2)     # order-2 controller, strongly stabilising
    CL = P.lft(K)                                  # the closed loop; ‖CL‖∞ = info.gamma

The numerics are the hinfix Rust crate's (the extension module ``hinfix._hinfix``); this
package converts python-control systems to and from it.
"""
from __future__ import annotations

import control

from ._hinfix import HinfixError, __version__
from ._campaign import Results, read_results, run_campaign
from ._design import DesignResult, default_options, design
from ._norms import full_order_gamma, hinfnorm
from ._plant import statespace as _statespace
from . import _hinfix

__all__ = ["HinfixError", "DesignResult", "Results", "__version__", "default_options", "design",
           "full_order_gamma", "hinfnorm", "load_plant", "option_names", "read_results", "run_campaign",
           "shipped_plants"]


def load_plant(name_or_path: str) -> tuple[control.StateSpace, int, int]:
    """A shipped plant by name (``"HE1"``; ``hinfix.shipped_plants()`` lists them) or a plant file
    (JSON or MATLAB .mat with A B1 … D22) by path. Returns ``(P, nmeas, ncon)``: ``P`` a
    ``control.StateSpace`` partitioned as for ``control.hinfsyn(P, nmeas, ncon)``, with the
    file's sampling time ``Ts`` as its ``dt`` (0: continuous time). Names are
    looked up in ``$HINFIX_PLANTS``, else ``./plants``, else the ``plants/`` folder of the source
    tree the package was built from."""
    import os
    name, mats, dt = _hinfix.load_plant(os.fspath(name_or_path))
    return _statespace(mats, name, dt)


def shipped_plants() -> list[str]:
    """Names of the plants in the plant library (see ``load_plant``)."""
    return _hinfix.shipped_plants()


def option_names() -> list[str]:
    """The design options ``design(**search_options)`` accepts (the crate's option table)."""
    return _hinfix.option_names()
