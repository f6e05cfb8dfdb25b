"""Builds the walk-through's plant of one's own with python-control and saves it as
scratch/two_mass.mat (the nine blocks hinfix reads; scratch/ is ignored by git) — the committed
examples/own-plant/two_mass.mat is this file, which the script checks: two masses joined by a spring and a damper, the
first also held by a spring of *negative* stiffness (an unstable real mode), the force u on the
first mass, a disturbance force on the second, the second's position measured (non-collocated).

    x = (x1, v1, x2, v2)          w = (force on mass 2, sensor noise)
    z = (x2, rho * u)             y = x2 + eta * noise

Development-time only (hinfix and its tests never run Python):

    python3 -m venv venv && venv/bin/pip install control slycot numpy scipy
    venv/bin/python examples/own-plant/make_plant.py [OUT.mat]

(`venv/` and `scratch/` are in .gitignore: the walk-through leaves no untracked file.)

It also prints slycot's full-order optimal level (control.hinfsyn), to compare with
`campaign plant examples/own-plant/two_mass.mat`.
"""
import os
import sys

import control
import numpy as np
import scipy.io

m1, m2 = 1.0, 1.0  # masses
k, c = 1.0, 0.02  # spring and damper between the masses
k0 = 0.5  # negative stiffness holding mass 1: the force +k0*x1 pushes it away
rho, eta = 0.1, 0.1  # control weight, sensor noise level

A = np.array([
    [0.0, 1.0, 0.0, 0.0],
    [(k0 - k) / m1, -c / m1, k / m1, c / m1],
    [0.0, 0.0, 0.0, 1.0],
    [k / m2, c / m2, -k / m2, -c / m2],
])
B1 = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [1.0 / m2, 0.0]])
B2 = np.array([[0.0], [1.0 / m1], [0.0], [0.0]])
C1 = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
C2 = np.array([[0.0, 0.0, 1.0, 0.0]])
D11 = np.zeros((2, 2))
D12 = np.array([[0.0], [rho]])
D21 = np.array([[0.0, eta]])
D22 = np.zeros((1, 1))

# the generalised plant as python-control sees it: inputs (w, u), outputs (z, y)
P = control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]), np.block([[D11, D12], [D21, D22]]))
print("open-loop poles:", np.sort_complex(np.linalg.eigvals(A)))
K, CL, gamma, rcond = control.hinfsyn(P, 1, 1)
print(f"slycot hinfsyn: full-order gamma = {gamma:.7f}")

here = os.path.dirname(os.path.abspath(__file__))
blocks = dict(A=A, B1=B1, B2=B2, C1=C1, C2=C2, D11=D11, D12=D12, D21=D21, D22=D22)
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "scratch", "two_mass.mat")
os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
scipy.io.savemat(out, blocks)
print("wrote", os.path.normpath(out))
committed = scipy.io.loadmat(os.path.join(here, "two_mass.mat"))
same = all(np.array_equal(np.atleast_2d(committed[k]), v) for k, v in blocks.items())
print("the same blocks as the committed examples/own-plant/two_mass.mat:", "yes" if same else "NO")
