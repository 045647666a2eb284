"""Where MOMBI-II's final points sit on DTLZ2 at 8 objectives (Deb & Jain protocol), and why the targets are missed.

Usage::

    .venv/bin/python -m benchmarks.investigations.many_objectives_mombi2_placement [--seeds 0-2]
        [--variants default,zero-1e-6,...]

Each run is ``bench_protocol``'s protocol task (population 156, the 120 + 36
two-layer directions, 500 generations, protocol operators; about 4 s). For the
final population, normalised with the run's own ideal/nadir estimate, it prints:
IGD to all / the 120 boundary / the 36 inner targets (and, once, that of the
ASF optima ``w' / ||w'||``, ``w'`` the weight with zeros read as the zero
weight); how many directions get no point (nearest direction by angle) and the
largest count; the size of the R2 ranking's first rank and how many weights
have their ASF winner nearest to themselves; the median distance of each
weight's ASF winner to its target and the median relative ASF gap
``ASF(winner | w) / ASF(target | w) - 1``; the mean number of components of an
inner winner below half its target's; the median distance to the front and
the dense-front IGD (``bench_protocol.dense_score``).

Variants swap one ingredient in the objects a run builds (library code untouched):
``zero-<v>`` zero weight components read as ``v`` (default 1e-2); ``true-norm``
ideal 0 and nadir 1 throughout, instead of MOMBI-II's estimate; ``gens-<k>x``
``k`` times the generations; ``random-ties`` a random key replaces the norm in
the survival's tie rule (rank, norm); ``pbi`` the R2 ranking's ASF replaced by
PBI (theta = 5, not MOMBI-II: a contrast that isolates the scalarising function).
"""

from __future__ import annotations

import argparse
import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):   # before numpy loads
    os.environ.setdefault(_var, "1")

import moocore  # noqa: E402
import numpy as np  # noqa: E402
from pymoo.optimize import minimize  # noqa: E402

from benchmarks import bench_protocol as bp  # noqa: E402
from moo.algorithms import mombi2  # noqa: E402
from moo.algorithms.mombi2 import R2RankingSurvival, asf_matrix, r2_ranking, zero_weight  # noqa: E402

M, N_BOUNDARY = 8, 120


class TrueNormSurvival(R2RankingSurvival):
    """The survival with DTLZ2's true ideal (0) and nadir (1) in place of the estimate."""

    def _do(self, problem, pop, *args, **kwargs):
        self.ideal, self.nadir = np.zeros(M), np.ones(M)
        out = super()._do(problem, pop, *args, **kwargs)
        self.ideal, self.nadir = np.zeros(M), np.ones(M)
        rank, norm = r2_ranking(out.get("F"), self.weights, self.ideal, self.nadir)
        return out.set("rank", rank, "r2_norm", norm)


def random_tie_ranking(F, weights, ideal, nadir):
    """``r2_ranking`` whose second output (the survival's tie key) is random."""
    rank, _ = r2_ranking(F, weights, ideal, nadir)
    return rank, np.random.default_rng(len(F) + int(1e6 * F.sum()) % 2**31).random(len(F))


def pbi_matrix(F_norm, weights, zero=None, theta=5.0):
    """PBI ``d1 + theta d2`` (along / off the weight's line) in place of the ASF, for the ``pbi`` variant."""
    U = weights / np.linalg.norm(weights, axis=1, keepdims=True)
    d1 = F_norm @ U.T
    d2 = np.sqrt(np.maximum((F_norm ** 2).sum(axis=1, keepdims=True) - d1 ** 2, 0.0))
    return d1 + theta * d2


REBIND = {"random-ties": ("r2_ranking", random_tie_ranking), "pbi": ("asf_matrix", pbi_matrix)}


def run(seed: int, variant: str):
    problem, algorithm, (crit, n_gen) = bp.build(bp.Task("protocol", "mombi2", "dtlz2", M, seed, "protocol"))
    survival = algorithm.survival
    if variant.startswith("zero-"):
        survival.weights = np.where(survival.weights > 0, survival.weights, float(variant[5:]))
    elif variant == "true-norm":
        algorithm.survival = TrueNormSurvival(survival.weights)
    elif variant.startswith("gens-"):
        n_gen *= int(variant[5:-1])
    name, replacement = REBIND.get(variant, ("r2_ranking", r2_ranking))
    setattr(mombi2, name, replacement)              # the name the survival looks up; the file is untouched
    try:
        res = minimize(problem, algorithm, (crit, n_gen), seed=seed)
    finally:
        setattr(mombi2, name, {"r2_ranking": r2_ranking, "asf_matrix": asf_matrix}[name])
    s = res.algorithm.survival
    return np.asarray(res.F, dtype=float), s.ideal, s.nadir


def placement(F, ideal, nadir) -> dict[str, float]:
    W = bp.protocol_directions(M)
    inner = np.arange(len(W)) >= N_BOUNDARY
    T = bp.on_front("dtlz2", W)
    Fn = (F - ideal) / (nadir - ideal)
    cos = (Fn / np.linalg.norm(Fn, axis=1, keepdims=True)) @ (W / np.linalg.norm(W, axis=1, keepdims=True)).T
    count = np.bincount(cos.argmax(axis=1), minlength=len(W))
    rank, _ = r2_ranking(F, W, ideal, nadir)
    asf = asf_matrix(Fn, W)
    winner = asf.argmin(axis=0)
    asf_target = asf_matrix(T, W)[np.arange(len(W)), np.arange(len(W))]
    gap = asf[winner, np.arange(len(W))] / asf_target - 1
    dist = np.linalg.norm(Fn[winner] - T, axis=1)
    below = (Fn[winner[inner]] < 0.5 * T[inner]).sum(axis=1)
    igd = {name: float(moocore.igd(F, ref=T[sel])) for name, sel in
           (("igd", slice(None)), ("igd_b", ~inner), ("igd_i", inner))}
    return {**igd, "empty_b": int((count[~inner] == 0).sum()), "empty_i": int((count[inner] == 0).sum()),
            "max_count": int(count.max()), "rank1": int((rank == 1).sum()),
            "own": int((cos[winner].argmax(axis=1) == np.arange(len(W))).sum()),
            "dist_b": float(np.median(dist[~inner])), "dist_i": float(np.median(dist[inner])),
            "gap_b": float(np.median(gap[~inner])), "gap_i": float(np.median(gap[inner])),
            "below_i": float(below.mean()), "front": float(np.median(bp.front_distance("dtlz2", F))),
            "dense": bp.dense_score("dtlz2", M, F, len(F))[0]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", default="0-2")
    ap.add_argument("--variants", default="default,zero-1e-6,zero-0.1,true-norm,random-ties,gens-4x")
    args = ap.parse_args(argv)
    W = bp.protocol_directions(M)
    optima = np.where(W > 0, W, zero_weight(M))       # the ASF's minimiser on the sphere is along w with zeros read
    optima = optima / np.linalg.norm(optima, axis=1, keepdims=True)
    print(f"DTLZ2, M = {M}, {bp.GENERATIONS['dtlz2'][M]} generations; zero weight {zero_weight(M):g}; targets: 120 "
          f"boundary (b) + 36 inner (i); IGD of the ASF optima {moocore.igd(optima, ref=bp.on_front('dtlz2', W)):.4f}")
    print("| variant | seed | IGD | IGD b / i | empty b / i | max pts/dir | rank 1 | own winner | "
          "winner-target dist b / i | ASF gap b / i | inner comps < half | dist to front | dense IGD |")
    print("|---|---:|---:|---|---|---:|---:|---:|---|---|---:|---:|---:|")
    for variant in args.variants.split(","):
        for seed in bp.parse_seeds(args.seeds):
            p = placement(*run(seed, variant))
            print(f"| {variant} | {seed} | {p['igd']:.4f} | {p['igd_b']:.4f} / {p['igd_i']:.4f} | "
                  f"{p['empty_b']} / {p['empty_i']} | {p['max_count']} | {p['rank1']} | {p['own']} | "
                  f"{p['dist_b']:.3f} / {p['dist_i']:.3f} | {p['gap_b']:.2e} / {p['gap_i']:.2e} | "
                  f"{p['below_i']:.1f} | {p['front']:.1e} | {p['dense']:.3f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
