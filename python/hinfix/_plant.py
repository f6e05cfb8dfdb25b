"""The generalised plant in python-control's partition, as hinfix's nine matrices.

``control.hinfsyn(P, nmeas, ncon)`` partitions ``P`` as ::

    x' = A x  + B1 w  + B2 u          B = [B1 B2],   C = [C1; C2]
    z  = C1 x + D11 w + D12 u         D = [D11 D12; D21 D22]
    y  = C2 x + D21 w + D22 u

with the last ``ncon`` inputs the controls u and the last ``nmeas`` outputs the measurements y
(x' is x(t+1) for a discrete-time ``P``, whose ``dt`` is its sampling time in seconds).
hinfix's plant is the same system as the nine blocks (A, B1, B2, C1, C2, D11, D12, D21, D22).
"""
import numpy as np
import control

NAMES = ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")


def as_matrix(x, name):
    """``x`` as a 2-D float64 array (no copy when it already is one)."""
    try:
        complex_ = np.iscomplexobj(x)  # may itself fail on ragged rows
        a = None if complex_ else np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} is not a real matrix: {e}") from None
    if complex_:
        raise ValueError(f"{name} must be real, got a complex array")
    if a.ndim != 2:
        raise ValueError(f"{name} must be 2-D, got an array of shape {a.shape}")
    return a


def system(sys, what):
    """``sys`` as a ``control.StateSpace`` (a ValueError otherwise), continuous or discrete time."""
    if not isinstance(sys, control.StateSpace):
        try:
            converted = None if sys is None else control.ss(sys)
        except Exception as e:  # python-control raises several types for what it cannot convert
            raise ValueError(f"{what} must be a control.StateSpace (or convertible to one): {e}") from None
        # control.ss makes a nonlinear system of what it does not know (None, a function, …)
        if not isinstance(converted, control.StateSpace):
            raise ValueError(f"{what} must be a control.StateSpace (or convertible to one, such as a "
                             f"TransferFunction), got {type(sys).__name__}")
        sys = converted
    sampling_time(sys, what)
    return sys


def sampling_time(sys, what):
    """The sampling time of ``sys`` in seconds, 0 for continuous time. python-control's
    ``dt=True`` (discrete time, sampling time unspecified) is refused: the design's frequencies
    and the Nyquist frequency need it."""
    dt = sys.dt
    if dt is None or dt is False or dt == 0:
        return 0.0
    if dt is True:
        raise ValueError(f"{what} is discrete-time with an unspecified sampling time (dt=True): "
                         "give its sampling time in seconds (control.ss(..., dt=0.1))")
    dt = float(dt)
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"{what} has the sampling time dt = {dt}: it must be a finite number of seconds > 0")
    return dt


def _count(value, name, upper, what):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be a whole number, got {value!r}")
    if not 1 <= value <= upper:
        raise ValueError(f"{name} must be in 1..={upper} ({what}), got {value}")
    return int(value)


def blocks(P, nmeas=None, ncon=None):
    """The nine matrices of ``P`` and its sampling time (0: continuous time): a
    ``control.StateSpace`` with ``nmeas`` measurements (its last outputs) and ``ncon`` controls
    (its last inputs), or a sequence of the nine matrices themselves (continuous time; then
    ``nmeas``, ``ncon`` may be omitted, and must agree if given)."""
    if isinstance(P, (tuple, list)):
        if len(P) != 9:
            raise ValueError(f"a plant given as matrices needs the nine {', '.join(NAMES)}, got {len(P)}")
        mats = tuple(as_matrix(m, n) for m, n in zip(P, NAMES))
        for given, actual, name in ((nmeas, mats[4].shape[0], "nmeas"), (ncon, mats[2].shape[1], "ncon")):
            if given is not None and given != actual:
                raise ValueError(f"{name} = {given} does not match the matrices ({actual})")
        # as for a StateSpace plant: T_zw needs a disturbance w and a performance output z (the
        # closed loop would be no python-control system)
        for count, what in ((mats[1].shape[1], "B1 has no column: no disturbance input w"),
                            (mats[3].shape[0], "C1 has no row: no performance output z")):
            if count == 0:
                raise ValueError(f"a plant given as matrices: {what} (a plant needs at least one)")
        return mats, 0.0
    P = system(P, "P")
    if nmeas is None or ncon is None:
        raise TypeError("nmeas and ncon are required with a StateSpace plant (as for control.hinfsyn)")
    # at least one disturbance input w and one performance output z must remain
    for count, kind, split in ((P.noutputs, "output", "a measurement y and a performance output z"),
                               (P.ninputs, "input", "a control u and a disturbance w")):
        if count < 2:
            raise ValueError(f"P has {count} {kind}{'' if count == 1 else 's'}: a plant needs at least two, {split}")
    nmeas = _count(nmeas, "nmeas", P.noutputs - 1, f"P has {P.noutputs} outputs and one at least is z")
    ncon = _count(ncon, "ncon", P.ninputs - 1, f"P has {P.ninputs} inputs and one at least is w")
    A, B, C, D = (as_matrix(m, n) for m, n in zip((P.A, P.B, P.C, P.D), "ABCD"))
    m1, p1 = P.ninputs - ncon, P.noutputs - nmeas
    return (A, B[:, :m1], B[:, m1:], C[:p1, :], C[p1:, :],
            D[:p1, :m1], D[:p1, m1:], D[p1:, :m1], D[p1:, m1:]), sampling_time(P, "P")


def statespace(mats, name=None, dt=0.0):
    """The ``control.StateSpace`` of nine plant matrices (sampling time ``dt``, 0: continuous
    time), with (nmeas, ncon). Its signals are named w[i], u[i] (inputs) and z[i], y[i]
    (outputs), as the partition reads them."""
    A, B1, B2, C1, C2, D11, D12, D21, D22 = mats
    B = np.hstack([B1, B2])
    C = np.vstack([C1, C2])
    D = np.block([[D11, D12], [D21, D22]])
    names = {"inputs": [f"w[{i}]" for i in range(B1.shape[1])] + [f"u[{i}]" for i in range(B2.shape[1])],
             "outputs": [f"z[{i}]" for i in range(C1.shape[0])] + [f"y[{i}]" for i in range(C2.shape[0])]}
    kw = {"name": name.replace(".", "_")} if name else {}  # python-control refuses '.' in a name
    return control.ss(A, B, C, D, dt=dt, **names, **kw), C2.shape[0], B2.shape[1]


def controller(ak, bk, ck, dk, P=None, nmeas=None, ncon=None, dt=0.0):
    """The controller u = K y as a ``control.StateSpace`` (a static gain for order 0) with
    sampling time ``dt``. Its inputs are named after the plant's measurements (the last
    ``nmeas`` outputs of ``P``) and its outputs after the plant's controls (the last ``ncon``
    inputs), when ``P`` is a ``StateSpace``."""
    names = {}
    if isinstance(P, control.StateSpace):
        names = {"inputs": list(P.output_labels[P.noutputs - nmeas:]),
                 "outputs": list(P.input_labels[P.ninputs - ncon:])}
    else:
        names = {"inputs": [f"y[{i}]" for i in range(bk.shape[1])],
                 "outputs": [f"u[{i}]" for i in range(ck.shape[0])]}
    return control.ss(ak, bk, ck, dk, dt=dt, **names)
