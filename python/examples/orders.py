"""Fixed-order H∞ design from python-control: a plant built with python-control, strongly
stabilising controllers of orders 0–3 designed by hinfix, each checked by python-control, and γ
plotted against the order (with the full-order bound γ_opt).

    python python/examples/orders.py [--out scratch/gamma_vs_order.png] [--maxevals 3000]

(scratch/ is ignored by git.)

The plant: two masses joined by a lightly damped spring, the first one tied to the ground by a
soft spring; the force u acts on the first mass, a disturbance force w1 on the second, whose
position is measured with noise w2. The performance outputs are the second mass's position and the
weighted control effort. u = K y (positive feedback), as control.hinfsyn: P.lft(K) is the loop.
"""
import argparse
import os

import numpy as np
import control

import hinfix


def two_mass_plant(k=1.0, k0=0.2, c=0.02, noise=0.1, effort=0.1):
    """The generalised plant and (nmeas, ncon): states (x1, x2, v1, v2), inputs (w1, w2, u),
    outputs (z1 = x2, z2 = effort·u, y = x2 + noise·w2)."""
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-k - k0, k, -c, c], [k, -k, c, -c]], dtype=float)
    B = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 1], [1, 0, 0]], dtype=float)
    C = np.array([[0, 1, 0, 0], [0, 0, 0, 0], [0, 1, 0, 0]], dtype=float)
    D = np.array([[0, 0, 0], [0, 0, effort], [0, noise, 0]], dtype=float)
    P = control.ss(A, B, C, D, inputs=["w1", "w2", "u"], outputs=["z1", "z2", "y"], name="two-mass")
    return P, 1, 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("scratch", "gamma_vs_order.png"),
                    help="figure file (needs matplotlib)")
    ap.add_argument("--maxevals", type=int, default=3000, help="evaluation budget per design")
    args = ap.parse_args()

    P, nmeas, ncon = two_mass_plant()
    bound = hinfix.full_order_gamma(P, nmeas, ncon)["gamma"]
    print(f"full-order bound gamma_opt = {bound:.6g}")
    orders, gammas = [], []
    for order in range(4):
        K, info = hinfix.design(P, nmeas, ncon, order, eps=1e-3, strong=True, seed=0,
                                maxevals=args.maxevals)
        if not info.stabilised:
            print(f"order {order}: {info.status}")
            continue
        # python-control's own verdict on the controller hinfix returned
        CL = P.lft(K)
        cl_stable = bool(np.all(CL.poles().real < 0))
        k_stable = bool(np.all(K.poles().real < 0)) if order > 0 else True
        norm = control.linfnorm(CL)[0] if control.slycot_check() else hinfix.hinfnorm(CL)[0]
        print(f"order {order}: gamma = {info.gamma:.6g} (python-control: {norm:.6g}, "
              f"relative difference {abs(norm - info.gamma) / norm:.1e}), "
              f"closed loop stable: {cl_stable}, controller stable: {k_stable}, "
              f"||K||inf = {info.k_hinf:.4g}, {info.status}")
        orders.append(order)
        gammas.append(info.gamma)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no figure")
        return
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot(orders, gammas, "o-", label="hinfix, strongly stabilising")
    ax.axhline(bound, color="gray", ls="--", label=r"full-order $\gamma_{opt}$")
    ax.set_xlabel("controller order $n_K$")
    ax.set_ylabel(r"$\|T_{zw}\|_\infty$")
    ax.set_yscale("log")
    ax.set_xticks(range(4))
    ax.legend()
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=120)
    print(f"figure written to {args.out}")


if __name__ == "__main__":
    main()
