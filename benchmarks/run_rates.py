"""Energy gained per second of a run, from its checkpoint's history (one entry per improving step:
basis size, E, phase, elapsed seconds): per block of consecutive steps of one phase, and per
window of `--window` seconds, with the distance to a reference energy. With `--target`, a
power law E − E_ref = a t^(−p) fitted (least squares in logs) to the history from each of the
`--fit-from` seconds on, and the elapsed time at which it reaches E_target − E_ref: an
extrapolation, not a measurement. With `--reach`, the first elapsed second at which each of the
given distances to the reference was reached (time to accuracy; at the basis size of the latest
entry, so a pruning's larger basis does not count).

    python benchmarks/run_rates.py benchmarks/checkpoints/h2-cycles/basis.json --reference -1.164025030884 --since 5400
    python benchmarks/run_rates.py benchmarks/checkpoints/h2-cycles/basis.json --reference -1.164025030884 \
        --since 16000 --target -1.164025020 --fit-from 8000,12000,16000
    python benchmarks/run_rates.py benchmarks/checkpoints/h2-auto/basis.json --reference -1.164025030884 \
        --reach 1e-6,5e-7,2e-7,1e-7,5e-8
"""
from __future__ import annotations

import argparse
import json

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis", help="a run's basis.json")
    ap.add_argument("--reference", type=float, required=True, help="reference energy (Eh)")
    ap.add_argument("--window", type=float, default=600.0, help="seconds per window")
    ap.add_argument("--since", type=float, default=0.0, help="first elapsed second shown")
    ap.add_argument("--target", type=float, default=None, help="target energy (Eh) for the power-law extrapolation")
    ap.add_argument("--fit-from", default="0", help="comma-separated first elapsed seconds of the fits")
    ap.add_argument("--reach", help="comma-separated distances to the reference (Eh): when each was first reached")
    args = ap.parse_args()
    history = json.loads(open(args.basis).read())["history"]
    t = np.array([h[3] for h in history])
    E = np.array([h[1] for h in history])
    phase = [h[2] for h in history]
    if args.reach:
        size = np.array([h[0] for h in history]) == history[-1][0]
        print("| E − E_ref | first reached after (s) |\n|---|---|")
        for d in (float(v) for v in args.reach.split(",")):
            hit = np.flatnonzero(size & (E - args.reference <= d))
            print(f"| {d:.1e} | {t[hit[0]]:.1f} |" if len(hit) else f"| {d:.1e} | not yet |")
        return

    print("| phase | from (s) | to (s) | gain (Eh) | gain per s | E − E_ref at the end |")
    print("|---|---|---|---|---|---|")
    start = 0
    for k in range(1, len(history) + 1):
        if k == len(history) or phase[k] != phase[start]:
            if t[k - 1] >= args.since:
                e0 = E[start - 1] if start else E[start]
                span = max(t[k - 1] - (t[start - 1] if start else t[start]), 1e-9)
                print(f"| {phase[start]} | {t[start]:.0f} | {t[k - 1]:.0f} | {e0 - E[k - 1]:.2e} | "
                      f"{(e0 - E[k - 1]) / span:.2e} | {E[k - 1] - args.reference:.3e} |")
            start = k

    print(f"\n| window (s) | phases | gain per s | E − E_ref at the end |\n|---|---|---|---|")
    for a in np.arange(args.since, t[-1], args.window):
        inside = np.flatnonzero((t >= a) & (t < a + args.window))
        if len(inside) == 0:
            continue
        e0 = E[inside[0] - 1] if inside[0] else E[0]
        names = ", ".join(sorted({phase[i] for i in inside}))
        print(f"| {a:.0f}–{a + args.window:.0f} | {names} | {(e0 - E[inside[-1]]) / args.window:.2e} | "
              f"{E[inside[-1]] - args.reference:.3e} |")

    if args.target is not None:
        print(f"\n| fit from (s) | points | p | E − E_ref reaches {args.target - args.reference:.3e} after (h) |\n|---|---|---|---|")
        for lo in (float(v) for v in args.fit_from.split(",")):
            m = (t >= lo) & (E > args.reference)
            slope, icpt = np.polyfit(np.log(t[m]), np.log(E[m] - args.reference), 1)
            reach = np.exp((np.log(args.target - args.reference) - icpt) / slope)
            print(f"| {lo:.0f} | {m.sum()} | {-slope:.2f} | {reach / 3600:.0f} |")


if __name__ == "__main__":
    main()
