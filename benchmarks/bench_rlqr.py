"""Batched RLQR gains versus python-control's dlqr, in the same process.

2000 designs of the paper's 4-state truck with two identical steering columns
(G2 = [G G]), z drawn uniformly from the applied MOP's search space
(0, 500]^7 = (EF (4), EG (2), (log10 mu)^2), against 2000 calls of
``control.dlqr`` on the same plant. Target: the batched RLQR costs at most
one fifth of a dlqr call per design (ratio <= 0.2).

    python benchmarks/bench_rlqr.py [--designs 2000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import time

import control
import numpy as np

import robustctl as rc
from robustctl.models.truck import truck_plant


def best_of(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    plant = truck_plant(0.0, doubled=True)
    rng = np.random.default_rng(0)
    z = rng.uniform(0, 500, (args.designs, 7))
    z[z == 0] = 1e-9
    EF, EG, mu = z[:, None, :4], z[:, None, 4:6], 10 ** np.sqrt(z[:, 6])
    Q, R = np.eye(plant.n), np.eye(plant.m)

    batch = rc.rlqr_gains(plant, EF, EG, mu, Q=Q, R=R)
    t_rlqr = best_of(lambda: rc.rlqr_gains(plant, EF, EG, mu, Q=Q, R=R), args.repeat)
    t_dlqr = best_of(lambda: [control.dlqr(plant.F, plant.G, Q, R) for _ in range(args.designs)], args.repeat)
    per_rlqr, per_dlqr = t_rlqr / args.designs, t_dlqr / args.designs
    ratio = per_rlqr / per_dlqr
    print(f"designs: {args.designs}  (ok {int(batch.ok.sum())}, "
          f"median doubling steps {int(np.median(batch.iterations))})")
    print(f"rlqr_gains (batched): {per_rlqr * 1e6:8.1f} us/design")
    print(f"control.dlqr (loop):  {per_dlqr * 1e6:8.1f} us/call")
    print(f"ratio rlqr/dlqr:      {ratio:8.3f}   (target <= 0.2: {'met' if ratio <= 0.2 else 'NOT met'})")


if __name__ == "__main__":
    main()
