"""Benchmark: the steady-state Kalman filter and the batched robust filter against python-control's dlqe.

The paper's truck (``robustctl.models.truck.truck_plant``) with three sensors
(lateral error, heading error, yaw rate: ``C`` selects ``rho``, ``theta``,
``psidot``), process noise on every state (``Bw = I``); the noise levels are
illustrative (speed does not depend on them). Two targets of issue 33, each a
ratio against ``control.dlqe`` (SLICOT through slycot when installed) timed in
the same process:

* ``rc.kalman``, one steady-state design per call: at most 1.5 times one
  ``control.dlqe`` call;
* ``rc.robust_kalman_gains`` for 1000 uncertainty models (``EF`` (1, 4), ``EG``
  (1, 1), ``H`` = ones, drawn as the applied MOP draws ``z``: uniform in
  (0, 500] each, ``(log10 mu)^2`` uniform in (0, 500], so ``mu`` reaches 1e22):
  at most 0.2 times 1000 ``control.dlqe`` calls.

Each row alternates the peer and ours for ``--rounds`` rounds (``--calls``
calls of each per round; the load of a shared machine changes between
rounds) and reports the median of the per-round ratios and the median
times. BLAS threads are pinned to 1 unless the environment says otherwise.
The compiled doubling kernel is loaded (or compiled) before the timing.

Results go to ``benchmarks/results/estimation.md``.

Usage: python -m benchmarks.bench_estimation [--rounds 15] [--calls 200] [--batch 1000]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import control  # noqa: E402
import numpy as np  # noqa: E402

import robustctl as rc  # noqa: E402
from benchmarks._report import header, write  # noqa: E402
from robustctl.models.truck import truck_plant  # noqa: E402

#: Sensors of the truck: lateral error rho [m], heading error theta [rad], yaw rate psidot [rad/s].
C_TRUCK = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.0]])
W_TRUCK = np.diag([1e-2, 1e-3, 1e-4, 1e-5])
V_TRUCK = np.diag([0.05**2, 0.01**2, 0.002**2])


def truck_with_sensors() -> rc.Plant:
    base = truck_plant(0.0)
    return rc.Plant(base.F, base.G, base.dt, C=C_TRUCK)


def designs(rng, count: int):
    """``(EF, EG, mu)`` drawn as the applied MOP draws its decision vector."""
    z = rng.uniform(0, 500, (count, 6))
    z[z == 0] = 1e-9
    return z[:, None, :4], z[:, None, 4:5], 10 ** np.sqrt(z[:, 5])


def timed(fn, calls: int) -> float:
    t0 = time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.perf_counter() - t0) / calls


def interleaved(peer, ours, rounds: int, peer_calls: int, our_calls: int):
    """Median per-round ratio and median times (seconds per call) of ``ours`` against ``peer``."""
    peer(), ours()
    tp, to = [], []
    for _ in range(rounds):
        tp.append(timed(peer, peer_calls))
        to.append(timed(ours, our_calls))
    tp, to = np.array(tp), np.array(to)
    return float(np.median(to / tp)), float(np.median(tp)), float(np.median(to)), float(np.max(to / tp))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--batch", type=int, default=1000)
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "estimation.md")
    args = ap.parse_args(argv)
    plant = truck_with_sensors()
    F, I4 = plant.F, np.eye(plant.n)

    def dlqe():
        return control.dlqe(F, I4, C_TRUCK, W_TRUCK, V_TRUCK)

    # the same design, both ways
    est = rc.kalman(plant, W_TRUCK, V_TRUCK, form="predictor")
    Lp, P, _ = dlqe()
    agree = max(float(np.abs(est.L - Lp).max() / np.abs(Lp).max()), float(np.abs(est.P - P).max() / np.abs(P).max()))

    single = interleaved(dlqe, lambda: rc.kalman(plant, W_TRUCK, V_TRUCK), args.rounds, args.calls, args.calls)

    EF, EG, mu = designs(np.random.default_rng(0), args.batch)
    H = np.ones((plant.n, 1))

    def batch():
        return rc.robust_kalman_gains(plant, W_TRUCK, V_TRUCK, H=H, EF=EF, EG=EG, mu=mu)

    result = batch()
    rounds = max(3, args.rounds // 3)
    many = interleaved(lambda: [dlqe() for _ in range(args.batch)], batch, rounds, 1, 1)
    single_ok = single[0] <= 1.5
    many_ok = many[0] <= 0.2

    cmd = "python -m benchmarks.bench_estimation " + " ".join(sys.argv[1:] if argv is None else argv)
    lines = header("Estimation: the Kalman filter and the batched robust filter against control.dlqe", cmd.strip())
    lines += [
        (f"The paper's truck (n = 4, m = 1) with three sensors (rho, theta, psidot), Bw = I. Peer: "
         f"`control.dlqe` (python-control {control.__version__}) on the same plant, timed in the same process, "
         f"alternating with ours for each round; medians over the rounds, BLAS on one thread. "
         f"`rc.kalman` against `dlqe` on this plant: gains and a-priori covariance agree to {agree:.1e} (relative)."),
        "",
        "| what | peer | ours | ours / peer: median (max) | target | met |",
        "|---|---|---|---|---|---|",
        (f"| steady-state `rc.kalman`, one design per call ({args.rounds} rounds x {args.calls} calls) | "
         f"{single[1] * 1e6:.1f} us | {single[2] * 1e6:.1f} us | **{single[0]:.2f}** ({single[3]:.2f}) | <= 1.5 | "
         f"{'yes' if single_ok else 'NO'} |"),
        (f"| `rc.robust_kalman_gains`, {args.batch} uncertainty models in one call against {args.batch} `dlqe` "
         f"calls ({rounds} rounds) | {many[1] * 1e3:.1f} ms | {many[2] * 1e3:.1f} ms | **{many[0]:.3f}** "
         f"({many[3]:.3f}) | <= 0.2 | {'yes' if many_ok else 'NO'} |"),
        "",
        (f"Robust batch: {int(result.ok.sum())}/{len(result)} designs ok; iterations (doubling steps plus Newton "
         f"steps) {np.bincount(result.iterations).tolist()} (count per number of iterations), per design "
         f"{many[2] / args.batch * 1e6:.1f} us."),
    ]
    print("\n".join(lines[3:]))
    write(lines, args.out)


if __name__ == "__main__":
    main()
