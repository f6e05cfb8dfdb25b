"""The generalised plant in python-control's partition, as hinfix's nine matrices.

``control.hinfsyn(P, nmeas, ncon)`` partitions ``P`` as ::

    x' = A x  + B1 w  + B2 u          B = [B1 B2],   C = [C1; C2]
    z  = C1 x + D11 w + D12 u         D = [D11 D12; D21 D22]
    y  = C2 x + D21 w + D22 u

with the last ``ncon`` inputs the controls u and the last ``nmeas`` outputs the measurements y.
hinfix's plant is the same system as the nine blocks (A, B1, B2, C1, C2, D11, D12, D21, D22).
"""
import numpy as np
import control

NAMES = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")


def as_matrix(x, name):
    """``x`` as a 2-D float64 array (no copy when it already is one)."""
    if np.iscomplexobj(x):
        raise ValueError(f"{name} must be real, got a complex array")
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} is not a real matrix: {e}") from None
    if a.ndim != 2:
        raise ValueError(f"{name} must be 2-D, got an array of shape {a.shape}")
    return a


def continuous(sys, what):
    """``sys`` as a continuous-time ``control.StateSpace`` (a ValueError otherwise)."""
    if not isinstance(sys, control.StateSpace):
        try:
            sys = control.ss(sys)
        except Exception as e:  # python-control raises several types for what it cannot convert
            raise ValueError(f"{what} must be a control.StateSpace (or convertible to one): {e}") from None
    if sys.dt not in (0, None):
        raise ValueError(f"{what} must be continuous-time, got a discrete-time system (dt = {sys.dt})")
    return sys


def _count(value, name, upper):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if not 1 <= value <= upper:
        raise ValueError(f"{name} must be in 1..={upper}, got {value}")
    return int(value)


def blocks(P, nmeas=None, ncon=None):
    """The nine matrices of ``P``: a ``control.StateSpace`` with ``nmeas`` measurements (its last
    outputs) and ``ncon`` controls (its last inputs), or a sequence of the nine matrices
    themselves (then ``nmeas``, ``ncon`` may be omitted, and must agree if given)."""
    if isinstance(P, (tuple, list)):
        if len(P) != 9:
            raise ValueError(f"a plant given as matrices needs the nine {', '.join(NAMES)}, got {len(P)}")
        mats = tuple(as_matrix(m, n) for m, n in zip(P, NAMES))
        for given, actual, name in ((nmeas, mats[4].shape[0], "nmeas"), (ncon, mats[2].shape[1], "ncon")):
            if given is not None and given != actual:
                raise ValueError(f"{name} = {given} does not match the matrices ({actual})")
        return mats
    P = continuous(P, "P")
    if nmeas is None or ncon is None:
        raise TypeError("nmeas and ncon are required with a StateSpace plant (as for control.hinfsyn)")
    nmeas = _count(nmeas, "nmeas", P.noutputs)
    ncon = _count(ncon, "ncon", P.ninputs)
    A, B, C, D = (as_matrix(m, n) for m, n in zip((P.A, P.B, P.C, P.D), "ABCD"))
    m1, p1 = P.ninputs - ncon, P.noutputs - nmeas
    return (A, B[:, :m1], B[:, m1:], C[:p1, :], C[p1:, :],
            D[:p1, :m1], D[:p1, m1:], D[p1:, :m1], D[p1:, m1:])


def statespace(mats, name=None):
    """The ``control.StateSpace`` of nine plant matrices, with (nmeas, ncon)."""
    A, B1, B2, C1, C2, D11, D12, D21, D22 = mats
    B = np.hstack([B1, B2])
    C = np.vstack([C1, C2])
    D = np.block([[D11, D12], [D21, D22]])
    kw = {"name": name} if name else {}
    return control.ss(A, B, C, D, **kw), C2.shape[0], B2.shape[1]


def controller(ak, bk, ck, dk):
    """The controller u = K y as a ``control.StateSpace`` (a static gain for order 0)."""
    return control.ss(ak, bk, ck, dk)
