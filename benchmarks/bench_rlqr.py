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

Then the plain recursion alone (``robustctl.synthesis._rlqr.steady.recursion``, the
fallback of designs the doubling leaves unsettled), the compiled kernel
(``robustctl.synthesis._rlqr.kernel``, what ``rlqr_gains`` runs) against the numpy
reference in the same process, best of ``--repeat`` interleaved:

* the generic MOP's fallback designs (``z`` uniform in its search space,
  those on which the doubling misses the acceptance test; ``max_iter=50``)
  in calls of 2 designs (a generic NSGA-II run makes about 65 such calls of
  1-2 designs) and all in one call;
* the ``ill`` truck designs above, ``max_iter=2000``.

    python -m benchmarks.bench_rlqr [--repeat 5]
"""

from __future__ import annotations

import argparse
import time

import control
import numpy as np

import robustctl as rc
from robustctl import _kkt
from robustctl.models.truck import lqr_weights, truck_plant
from robustctl.synthesis._rlqr import kernel, steady
from robustctl.synthesis._rlqr.model import build
from robustctl.synthesis._rlqr.step import kkt_step


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
    recursion_rows(args.repeat, build(plant, *ill, Q=Q, R=R, H=H, alpha=0.1, batch=True), Q)
    doubling_rows(args.repeat, plant, Q, R, H, rng)


def generic_fallback_designs(count: int):
    """The generic MOP's designs on which the doubling misses the acceptance test (its model, weights)."""
    from moo.problems.generic import GenericRLQRProblem

    p = GenericRLQRProblem()
    EF, EG, mu = p.decode(np.random.default_rng(1).uniform(p.xl, p.xu, (count, p.n_var)))
    d = build(p.plant, EF, EG, mu, Q=p.Q, R=p.R, H=p.H, alpha=p.alpha, batch=True)
    with np.errstate(all="ignore"):
        X, _, settled = steady.doubling(d, steady.DOUBLING_TOL)
        ev = steady.evaluate(X, d, kkt_step)
    return d.select(settled & steady.healthy(ev.P) & ~ev.accepted(steady.DEFAULT_TOL)), p.max_iter


def recursion_rows(repeat: int, ill, Q_ill) -> None:
    """The plain recursion: compiled kernel against the numpy reference, interleaved in one process."""
    tol = steady.DEFAULT_TOL
    d, max_iter = generic_fallback_designs(3000)
    pairs = [d.select(np.arange(i, i + 2)) for i in range(0, d.size - 1, 2)]
    cases = [(f"generic fallback, calls of 2 designs ({len(pairs)} calls)", pairs, np.eye(3), max_iter),
             (f"generic fallback, {d.size} designs in one call", [d], np.eye(3), max_iter),
             (f"truck ill, {ill.size} designs in one call", [ill], Q_ill, 2000)]
    print(f"plain recursion (tol {tol:g}): compiled kernel vs numpy reference, best of {repeat}")
    for label, batches, P0, cap in cases:
        def compiled(batches=batches, P0=P0, cap=cap):
            for b in batches:
                kernel.recursion(b, P0, tol, cap, steady.DIVERGED)

        def numpy(batches=batches, P0=P0, cap=cap):
            with np.errstate(all="ignore"):
                for b in batches:
                    steady.recursion(b, kkt_step, P0, tol, cap)

        compiled()                                                 # loads (or compiles) the kernel
        t_c, t_n = [], []
        for _ in range(repeat):
            t_c.append(best_of(compiled, 1))
            t_n.append(best_of(numpy, 1))
        c, n = min(t_c) / len(batches), min(t_n) / len(batches)
        steps = sum(int(kernel.recursion(b, P0, tol, cap, steady.DIVERGED)[1].sum()) for b in batches)
        print(f"  {label:52s} kernel {c * 1e6:9.1f} us/call  numpy {n * 1e6:9.1f} us/call  ratio {c / n:6.4f} "
              f"({steps} design-steps: kernel {c * len(batches) / steps * 1e6:.2f} us, "
              f"numpy {n * len(batches) / steps * 1e6:.2f} us per design-step)")


def doubling_rows(repeat: int, plant, Q, R, H, rng) -> None:
    """The doubling steps: compiled kernel against the numpy reference from the same standard form."""
    print(f"doubling steps (tol {steady.DOUBLING_TOL:g}): compiled kernel vs numpy reference, best of {repeat}")
    for B in (92, 2000):
        d = build(plant, *designs(rng, B, False), Q=Q, R=R, H=H, alpha=0.1, batch=True)
        A, Gs, Hs = steady.standard_form(d)
        active = steady.healthy(Hs) & steady.healthy(Gs)
        args = (A, Gs, Hs, steady.DOUBLING_TOL)
        _kkt.doubling(*args, steady.DOUBLING_MAX_STEPS, active)     # loads (or compiles) it
        t_c, t_n = [], []
        for _ in range(repeat):
            t_c.append(best_of(lambda: _kkt.doubling(*args, steady.DOUBLING_MAX_STEPS,
                                                       active), 3))
            t_n.append(best_of(lambda: steady.doubling_loop(*args, active), 3))
        c, n = min(t_c), min(t_n)
        print(f"  truck, {B:4d} designs in one call  kernel {c * 1e6 / B:7.2f} us/design  "
              f"numpy {n * 1e6 / B:7.2f} us/design  ratio {c / n:6.4f}")


if __name__ == "__main__":
    main()
