#!/usr/bin/env python3
"""Writes campaigns/compleib.toml: every COMPleib plant of the library (plants/compleib/ and the
seven COMPleib plants of the top folder) x controller orders 0-3 x plain and strong
stabilisation. Run from the project root; the campaign file says what each choice is and why.

    python3 scripts/compleib_campaign.py > campaigns/compleib.toml
"""
import csv
import json
import os

# COMPleib plants of the top folder (the paper's protocol) and their n; Enns is not COMPleib's.
TOP = {"AC8": 9, "HE1": 4, "REA2": 4, "AC10": 55, "BDT2": 82, "HF1": 130, "CM4": 240, "Enns": 8}
LARGE_N = 60  # above: the large-plant budget (orders 0 and 1, one seed)


def plants():
    with open("plants/compleib/INDEX.csv") as f:
        rows = {r["name"]: int(r["n"]) for r in csv.DictReader(f)}
    for name, n in TOP.items():
        with open(f"plants/{name}.json") as f:
            assert json.load(f)["dims"]["n"] == n, name
        rows[name] = n
    # small plants, then the large ones with the 2-D heat-flow family (HF2D*) last; by name within each
    large = lambda kv: kv[1] > LARGE_N
    return sorted(rows.items(), key=lambda kv: (large(kv), large(kv) and kv[0].startswith(HEAT_FLOW), kv[0].lower()))


HEAT_FLOW = "HF2D"  # the 2-D heat-flow plants: one model at several discretisations


HEADER = """\
# Every COMPleib plant of the library × controller orders 0–3 × plain and strong stabilisation
# (ε = 1e-3): the field's benchmark library (F. Leibfritz, COMPleib v1.1, 2005) in one campaign,
# with the library's one other plant, Enns (the four-disk system of the paper's protocol).
# Its committed run is results/compleib/. Written by scripts/compleib_campaign.py (rerun it rather
# than editing by hand); plants/compleib/README.md says where the plants come from.
#
# Budget (the whole campaign at most 12 CPU hours on 2 cores; "bound" = every job at its cap):
# * Plants with n ≤ 60 (112 plants): orders 0, 1, 2, 3 (NN2 has n = 2: orders 0–2, an order
#   above n is no reduced-order controller), 2 seeds, 10 CPU s per job, ended sooner by the stall
#   rule (10 local searches, or 4 CPU s, without a relative improvement of 1e-4). Bound: 5.0 CPU h.
# * Plants with n > 60 (39 plants, n = 82 … 1006): orders 0 and 1 only, one seed, 120 CPU s per
#   job (the per-design budget at which hinfix was compared with HIFOO 3.5 on these plants),
#   one first random start (`nrand = 1`, not HIFOO's 3) and no stall rule in CPU time (the
#   stall rule of 10 local searches stays). A standard-normal first start costs about a quarter
#   of the budget on CDP (n = 120, 11 ms per evaluation) and gives nothing there (its loop gain
#   is ~10^6 times too large: G22 peaks at 2.0e6), while the basin hops of the continued search
#   find the good controllers: CDP, order 1, strong, ε = 1e-3, 120 CPU s reached γ = 7.436
#   with nrand = 1 against 39.06 with nrand = 3 and a 30-s CPU stall rule (which ended the
#   run before its first hop finished; HIFOO 3.5 reaches 7.848 at this budget). CM3 and EB6 at
#   order 1 (strong, 120 s) end at the same γ either way (0.816497, 1.905236).
#   One H∞ norm of such a closed loop costs 5 ms (CDP, n = 120) to
#   7 s (HF2D_CD3_M576, n = 576) here, so a design of order 2 or 3 would get no further than one
#   of order 1 in any budget this campaign can give it; a run of higher orders on a chosen
#   large plant is a campaign of its own. A job may overrun its cap by one evaluation.
#   Bound: 5.2 CPU h.
#   The large plants come after the small ones and the 2-D heat-flow plants (HF2D*, 22 of
#   the 39: one model at several discretisations) last, so that a sitting cut short has every
#   other family first (the order of the problems does not change job ids).
# * Order chaining (campaigns/FORMAT.md "Order chaining"): every order starts also from the best
#   verified controller of the order below at the same ε, so the best-γ tables are
#   non-increasing in n_K wherever the order below has a controller.
# * Strong stabilisation is a problem of its own per plant (objective = "strong", ε = 1e-3); on a
#   plant that no stable controller stabilises (parity interlacing) its jobs fail at once and the
#   tables say so. The plain problems ask nothing of the controller's stability.
name = "compleib"
description = "COMPleib v1.1: every library plant, orders 0-3 (0-1 for n > 60), plain and strong (eps = 1e-3)"

[defaults]
# The search its committed results (results/compleib/) were made with: no BFGS restarts. The default
# (bfgs_restart = 300, campaigns/FORMAT.md) would make new job ids, and `campaign run` would start
# this campaign over instead of resuming its journal.
bfgs_restart = 0
eps = 1e-3
seeds = 2
cpumax = 10.0
nrand = 3
spend_budget = false
stall_starts = 10
stall_rtol = 1e-4
stall_cpu = 4.0
order_chaining = true
threads = 2
"""


def main():
    out = [HEADER]
    for name, n in plants():
        large = n > LARGE_N
        for objective in ("plain", "strong"):
            out.append("[[problem]]")
            out.append(f'plant = "{name}"')
            out.append(f'objective = "{objective}"')
            if large:
                # one seed, 120 CPU s (see the header)
                out.append("orders = [0, 1]")
                out.append("seeds = 1")
                out.append("cpumax = 120.0")
                out.append("nrand = 1")
                out.append("stall_cpu = 0.0")
            else:
                top = min(3, n)
                out.append(f"orders = {{ from = 0, to = {top} }}")
                if top < 3:
                    out.append(f"# n = {n}: no order above {top} (an order above n is no reduced-order controller)")
            out.append("")
    print("\n".join(out).rstrip() + "\n")


if __name__ == "__main__":
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    main()
