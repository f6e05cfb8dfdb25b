"""The independent checks of a design, by python-control (slycot's ab13dd for the norm)."""
import numpy as np
import control


def linfnorm(sys):
    """‖sys‖∞ of a stable system by python-control (slycot)."""
    return float(control.linfnorm(sys, tol=1e-12)[0])


def abscissa(sys):
    """Largest real part of the poles (-inf for a static gain)."""
    poles = np.linalg.eigvals(sys.A) if sys.nstates else np.array([])
    return float(np.max(poles.real)) if poles.size else -np.inf


def relerr(a, b):
    return abs(a - b) / abs(b)
