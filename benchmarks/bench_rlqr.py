"""Batched RLQR gains versus python-control's dlqr, in the same process.

Designs of the paper's 4-state truck with two identical steering columns
(G2 = [G G], ``robustctl.models.truck.truck_plant(doubled=True)``) and the
applied MOP's weights, z drawn uniformly from its search space
(0, 500]^7 = (EF (4), EG (2), (log10 mu)^2), timed against ``control.dlqr``
calls on the same plant. Three batches:

* ``uniform``: 2000 designs (target: the batched RLQR costs at most one fifth
  of a dlqr call per design, ratio <= 0.2);
* ``ill``: 1000 ill-conditioned designs, EG2 / EG1 = 1 +- 0.002 (nearly
  dependent split of the doubled column; doubling misses the acceptance test
  on about a quarter of them), with each ``fallback`` of ``rlqr_gains``;
* ``92``: one population (92 designs) and one design per call, for the fixed
  cost of a call.

    python benchmarks/bench_rlqr.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import time

import control
import numpy as np

import robustctl as rc
from robustctl.models.truck import lqr_weights, truck_plant


def best_of(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def designs(rng, count: int, ill: bool):
    z = rng.uniform(0, 500, (count, 7))
    z[z == 0] = 1e-9
    if ill:
        z[:, 5] = z[:, 4] * (1 + rng.uniform(-0.002, 0.002, count))
    return z[:, None, :4], z[:, None, 4:6], 10 ** np.sqrt(z[:, 6])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    plant = truck_plant(0.0, doubled=True)
    Q, R = lqr_weights(doubled=True)
    H = np.ones((plant.n, 1))
    rng = np.random.default_rng(0)

    def dlqr() -> float:  # the peer, timed next to every row (the machine's load changes)
        return best_of(lambda: [control.dlqr(plant.F, plant.G, Q, R) for _ in range(50)], args.repeat) / 50

    def run(label, EF, EG, mu, fallback="recursion"):
        def call():
            return rc.rlqr_gains(plant, EF, EG, mu, Q=Q, R=R, H=H, max_iter=2000, fallback=fallback)
        batch = call()
        peer = dlqr()
        t = best_of(call, args.repeat) / len(mu)
        peer = 0.5 * (peer + dlqr())
        print(f"{label:34s} {t * 1e6:8.1f} us/design  dlqr {peer * 1e6:6.1f} us  ratio {t / peer:6.3f}  "
              f"(ok {int(batch.ok.sum())}/{len(mu)}, max iterations {int(batch.iterations.max())})")
        return t, t / peer

    _, ratio = run("uniform 2000, fallback=recursion", *designs(rng, 2000, False))
    print(f"  target ratio <= 0.2: {'met' if ratio <= 0.2 else 'NOT met'}")
    ill = designs(rng, 1000, True)
    t_rec, _ = run("ill 1000, fallback=recursion", *ill)
    t_new, _ = run("ill 1000, fallback=newton", *ill, fallback="newton")
    print(f"  newton / recursion on ill designs: {t_new / t_rec:.3f}")
    EF, EG, mu = designs(rng, 92, False)
    t92, _ = run("population 92", EF, EG, mu)
    t1, r1 = run("one design per call", EF[:1], EG[:1], mu[:1])
    print(f"  per call: 92 designs {t92 * 92e3:.3f} ms, 1 design {t1 * 1e3:.3f} ms "
          f"(fixed cost ~ {r1:.1f} dlqr calls)")


if __name__ == "__main__":
    main()
