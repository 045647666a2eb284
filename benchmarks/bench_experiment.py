"""Cost of the paper's whole experiment, run by run, against pymoo's plain NSGA-II on DTLZ2.

Usage::

    python -m benchmarks.bench_experiment [--quick] [--evals 10000] [--runs 50] [--workers 2]
                                          [--problems generic,applied] [--algorithms all] [--out FILE]

Measured in one process, on the same (shared, 2-core) machine; BLAS should
be pinned to one thread (``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1``):

1. **Compilation.** In a fresh copy of ``robustctl`` (no ``__pycache__``, as a
   clone has it) a new process times its first simulation (numba compiles
   the kernel and writes the cache), a second process times the same call
   loading the cache; a third times what a spawned experiment worker pays
   before its first run: importing ``moo.problems``, building the applied
   MOP and evaluating one population.
2. **Kernel.** The applied MOP's simulation (2 payloads x 5406 steps) of 92
   stable random designs, in us per design, with the compiled kernel and the
   numpy reference (best of ``--repeats``), beside a compute bound: the
   floating-point operations of one design's run (``n_flops_per_step`` x
   payloads x steps, counted from n = 4 states and p = 1 input) at the
   core's peak (16 double-precision flops per cycle: two 4-wide FMUL/FMA and
   two 4-wide FADD pipes of AVX2 on AMD Zen, no fused multiply-add since the
   kernel is compiled without fastmath; clock from /proc/cpuinfo).
3. **Runs.** One run of each configuration (MOP x MOEA x {plain, MO-LSP};
   all 40 by default) with :func:`moo.runner.run`, the code path of
   ``python -m moo experiment``, at ``--evals`` evaluations and the
   experiment's first seed. Before each one, pymoo's plain NSGA-II
   (``pymoo.algorithms.moo.nsga2.NSGA2(pop_size=92)``) on DTLZ2 (3
   objectives, pymoo's 12 variables) runs to the same budget: the ratio of
   each configuration is against the peer run next to it, so load drifts
   hit both alike. Wall and process CPU time are both reported; for the
   control-design MOPs also the time spent in the batched RLQR design and in
   the simulation. The full experiment (``--runs`` runs of every
   configuration on ``--workers`` processes) is extrapolated as the sum of
   the per-run times x runs / workers (perfect load balance, no worker
   start-up), once from the wall times and once from the process CPU times:
   on a machine shared with other jobs the wall times are inflated, the CPU
   times much less.

Targets (issue 10): an applied run at most 5x the peer, for NSGA-II and for
MaOEA-DDFC with MO-LSP; the full experiment at most 20 minutes on 2 cores.

``--quick``: NSGA-II and MaOEA-DDFC, plain and with MO-LSP, on both MOPs (8
configurations) and 3 kernel repeats: a couple of minutes. Results go to
``benchmarks/results/experiment.md`` (``experiment_quick.md`` with ``--quick``).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.optimize import minimize
from pymoo.problems import get_problem

from moo.algorithms import ALGORITHMS
from moo.experiment import run_seeds
from moo.problems.applied import AppliedRLQRProblem, PathFollowingErrors
from moo.problems.generic import RegulationErrors
from moo.runner import run
from moo.tuning import RLQRFamily

ROOT = Path(__file__).resolve().parents[1]

QUICK_ALGORITHMS = ("nsga2", "maoea-ddfc")
POP = 92

# -- 1. compilation ------------------------------------------------------------------------
_FIRST_CALL = """
import json, time, numpy as np
t0 = time.perf_counter()
from robustctl.sim.simulator import simulate_linear
t1 = time.perf_counter()
args = (np.array([[-0.5]]), np.array([[1.0]]), np.array([[1.0]]), np.ones((10, 1)))
simulate_linear(*args, x0=[-1.0])
t2 = time.perf_counter()
simulate_linear(*args, x0=[-1.0])
t3 = time.perf_counter()
from robustctl.sim import _kernel as _simkernel
s = _simkernel.closed_loop.stats
print(json.dumps(dict(imp=t1 - t0, first=t2 - t1, second=t3 - t2, hits=sum(s.cache_hits.values()))))
"""

_WORKER_START = """
import json, time, numpy as np
t0 = time.perf_counter()
from moo.problems import make_problem
t1 = time.perf_counter()
p = make_problem("applied")
t2 = time.perf_counter()
p.evaluate(np.random.default_rng(0).uniform(p.xl, p.xu, (92, p.n_var)))
t3 = time.perf_counter()
print(json.dumps(dict(imp=t1 - t0, build=t2 - t1, evaluate=t3 - t2)))
"""


def _child(code: str, cwd: Path, env: dict) -> dict:
    out = subprocess.run([sys.executable, "-c", code], cwd=cwd, env={**os.environ, **env}, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def compilation() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copytree(ROOT / "robustctl", Path(tmp) / "robustctl", ignore=shutil.ignore_patterns("__pycache__"))
        env = dict(PYTHONPATH=tmp, NUMBA_CACHE_DIR="")
        fresh = _child(_FIRST_CALL, Path(tmp), env)
        cached = _child(_FIRST_CALL, Path(tmp), env)
    worker = _child(_WORKER_START, ROOT, dict(PYTHONPATH=str(ROOT)))
    return dict(fresh=fresh, cached=cached, worker=worker)


# -- 2. kernel speed -------------------------------------------------------------------------
def _clock_hz() -> float | None:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("cpu MHz"):
                return float(line.split(":")[1]) * 1e6
    except OSError:
        pass
    return None


def flops_per_step(n: int, p: int) -> int:
    """Flops of one design-step: e = x - r (n), u = K e + u_ff (2 n p), clip (2 p), the two
    squared sums (4 n), x+ = F x + G u + w (2 n^2 - n + 2 n p + n)."""
    return n + 2 * n * p + 2 * p + 4 * n + (2 * n * n - n) + 2 * n * p + n


def kernel_speed(repeats: int, seed: int) -> dict:
    prob = AppliedRLQRProblem()
    Z = np.random.default_rng(seed).uniform(prob.xl, prob.xu, (3 * POP, prob.n_var))
    batch = prob.gains(Z)
    K = batch.K[batch.ok]
    K = K[prob.closed_loop_radius(K).max(axis=1) < 1.0][:POP]
    sim = prob._sim
    best = {}
    for backend in ("numba", "numpy"):
        sim.run(K, keep_trajectories=False, backend=backend)
        times = []
        for _ in range(repeats if backend == "numba" else max(1, repeats // 3)):
            t0 = time.perf_counter()
            sim.run(K, keep_trajectories=False, backend=backend)
            times.append(time.perf_counter() - t0)
        best[backend] = min(times) / K.shape[0]
    hz = _clock_hz()
    flops = flops_per_step(4, 1) * sim.S * sim.T
    bound = flops / (16 * hz) if hz else float("nan")
    return dict(B=K.shape[0], S=sim.S, T=sim.T, numba=best["numba"], numpy=best["numpy"], flops=flops,
                bound=bound, hz=hz)


# -- 3. runs ------------------------------------------------------------------------------------
class _Timers:
    """Time spent in the RLQR design and in the simulation of the control-design MOPs."""

    def __init__(self):
        self.rlqr = self.sim = 0.0
        self._patched = []

    def __enter__(self):
        for cls, name, slot in ((RLQRFamily, "design", "rlqr"),
                                (RegulationErrors, "per_scenario", "sim"),
                                (PathFollowingErrors, "per_scenario", "sim")):
            original = cls.__dict__[name]

            def timed(*args, _f=original, _slot=slot, **kwargs):
                t0 = time.perf_counter()
                try:
                    return _f(*args, **kwargs)
                finally:
                    setattr(self, _slot, getattr(self, _slot) + time.perf_counter() - t0)

            setattr(cls, name, timed)
            self._patched.append((cls, name, original))
        return self

    def __exit__(self, *exc):
        for cls, name, original in self._patched:
            setattr(cls, name, original)


def _timed(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w0, time.process_time() - c0


def peer(evals: int, seed: int) -> tuple[float, float]:
    problem = get_problem("dtlz2")
    _, wall, cpu = _timed(lambda: minimize(problem, NSGA2(pop_size=POP), ("n_eval", evals), seed=seed,
                                           verbose=False))
    return wall, cpu


def runs(problems, algorithms, evals: int, seed: int) -> list[dict]:
    rows = []
    peer(evals, seed)                                            # warm-up (imports, first allocations)
    for problem in problems:
        run(problem, "nsga2", seed=seed, evals=2 * POP)           # warm-up: kernel, problem build
        for alg in algorithms:
            for molsp in (False, True):
                p_wall, p_cpu = peer(evals, seed)
                with _Timers() as t:
                    res, wall, cpu = _timed(lambda: run(problem, alg, seed=seed, evals=evals, molsp=molsp))
                rows.append(dict(problem=problem, algorithm=alg, molsp=molsp, wall=wall, cpu=cpu, rlqr=t.rlqr,
                                 sim=t.sim, n_evals=res.n_evals, peer_wall=p_wall, peer_cpu=p_cpu))
                print(f"  {problem:8s} {alg:12s} {'MO-LSP' if molsp else 'plain ':6s} {wall:6.2f} s "
                      f"(RLQR {t.rlqr:5.2f}, simulation {t.sim:5.2f})  peer {p_wall:5.2f} s  "
                      f"ratio {wall / p_wall:5.1f}", flush=True)
    return rows


# -- report ---------------------------------------------------------------------------------------
def report(args, comp, kern, rows) -> str:
    now = datetime.datetime.now(datetime.UTC)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [(f"# bench_experiment ({now:%Y-%m-%d %H:%M} UTC, {platform.machine()}, Python "
              f"{platform.python_version()}, load average {load:.1f} on {os.cpu_count()} cores"
              f"{', --quick' if args.quick else ''})"), "",
             ("Timings on a shared machine are noisy: every ratio is against a peer measured in the same "
              "process next to it."), "",
             "## Compilation (numba cache)", "",
             "| step | seconds |", "|---|---:|",
             f"| fresh copy, first simulation (compiles, writes the cache) | {comp['fresh']['first']:.2f} |",
             (f"| fresh copy, second process, first simulation (loads the cache: {comp['cached']['hits']} hit) "
              f"| {comp['cached']['first']:.2f} |"),
             (f"| import of robustctl.sim.simulator (numpy, scipy; numba is imported on the first call) "
              f"| {comp['cached']['imp']:.2f} |"),
             f"| spawned worker: import moo.problems | {comp['worker']['imp']:.2f} |",
             f"| spawned worker: build the applied MOP | {comp['worker']['build']:.2f} |",
             (f"| spawned worker: first evaluation of 92 designs (kernel from the cache) "
              f"| {comp['worker']['evaluate']:.2f} |"), "",
             "## Kernel", "",
             (f"Applied MOP simulation, {kern['B']} stable random designs x {kern['S']} payloads x {kern['T']} "
              f"steps (best of the repeats)."), "",
             "| path | us per design | vs numba |", "|---|---:|---:|",
             f"| compiled kernel (numba) | {kern['numba'] * 1e6:.1f} | 1.0 |",
             f"| numpy reference | {kern['numpy'] * 1e6:.1f} | {kern['numpy'] / kern['numba']:.0f}x slower |",
             (f"| compute bound ({kern['flops']} flops at 16 flops/cycle, {kern['hz'] / 1e9:.2f} GHz) "
              f"| {kern['bound'] * 1e6:.1f} | {kern['numba'] / kern['bound']:.1f}x of the bound |"), ""]
    lines += [f"## One run per configuration, {args.evals} evaluations, seed {args.seed}", "",
              ("| MOP | MOEA | MO-LSP | wall s | CPU s | RLQR s | simulation s | peer wall s | wall / peer "
               "| CPU / peer |"), "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['problem']} | {r['algorithm']} | {'yes' if r['molsp'] else 'no'} | {r['wall']:.2f} "
                     f"| {r['cpu']:.2f} | {r['rlqr']:.2f} | {r['sim']:.2f} | {r['peer_wall']:.2f} "
                     f"| {r['wall'] / r['peer_wall']:.1f} | {r['cpu'] / r['peer_cpu']:.1f} |")
    lines += ["", "## Targets and extrapolation", ""]
    for alg, molsp in (("nsga2", False), ("maoea-ddfc", True)):
        hit = [r for r in rows if r["problem"] == "applied" and r["algorithm"] == alg and r["molsp"] == molsp]
        if hit:
            r = hit[0]
            ratio = r["wall"] / r["peer_wall"]
            lines.append(f"- applied {alg}{' + MO-LSP' if molsp else ''}: {ratio:.1f}x pymoo NSGA-II on DTLZ2 "
                         f"(CPU {r['cpu'] / r['peer_cpu']:.1f}x; target <= 5x: {'met' if ratio <= 5 else 'NOT met'})")
    total = {"wall": 0.0, "cpu": 0.0}
    for problem in dict.fromkeys(r["problem"] for r in rows):
        t = {k: sum(r[k] for r in rows if r["problem"] == problem) * args.runs / args.workers for k in total}
        for k in total:
            total[k] += t[k]
        n_cfg = sum(r["problem"] == problem for r in rows)
        lines.append(f"- {problem}: {n_cfg} configurations x {args.runs} runs / {args.workers} workers = "
                     f"{t['wall'] / 60:.1f} min from the wall times ({t['cpu'] / 60:.1f} min from the CPU times)")
    complete = len(rows) == 40
    verdict = (f" (target <= 20 min: {'met' if total['wall'] <= 1200 else 'NOT met'} from the wall times, "
               f"{'met' if total['cpu'] <= 1200 else 'NOT met'} from the CPU times)" if complete
               else " (not all 40 configurations: no target check)")
    lines.append(f"- {'the paper' + chr(39) + 's full experiment' if complete else 'these configurations'}: "
                 f"{total['wall'] / 60:.1f} min on {args.workers} workers from the wall times, "
                 f"{total['cpu'] / 60:.1f} min from the CPU times (what an unloaded machine would take)" + verdict)
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="8 configurations, 3 kernel repeats")
    ap.add_argument("--evals", type=int, default=10000)
    ap.add_argument("--runs", type=int, default=50, help="runs per configuration in the extrapolation")
    ap.add_argument("--workers", type=int, default=2, help="processes in the extrapolation")
    ap.add_argument("--problems", default="generic,applied")
    ap.add_argument("--algorithms", default=None, help="comma-separated names or 'all' (default all; "
                                                        "--quick: nsga2,maoea-ddfc)")
    ap.add_argument("--repeats", type=int, default=None, help="kernel timing repeats (default 10, --quick 3)")
    ap.add_argument("--seed", type=int, default=None, help="default: the experiment's first seed")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    problems = [p for p in args.problems.split(",") if p]
    if args.algorithms in (None, "all"):
        algorithms = list(QUICK_ALGORITHMS) if args.quick and args.algorithms is None else list(ALGORITHMS)
    else:
        algorithms = args.algorithms.split(",")
    unknown = [a for a in algorithms if a not in ALGORITHMS] + [p for p in problems if p not in ("generic", "applied")]
    if unknown or args.evals < POP or args.runs < 1 or args.workers < 1:
        ap.error(f"unknown names {unknown}" if unknown else "--evals >= 92, --runs >= 1, --workers >= 1")
    args.seed = run_seeds(1)[0] if args.seed is None else args.seed
    repeats = args.repeats or (3 if args.quick else 10)
    out = args.out or ROOT / "benchmarks" / "results" / ("experiment_quick.md" if args.quick else "experiment.md")

    print("compilation ...", flush=True)
    comp = compilation()
    print(f"  first call in a fresh copy {comp['fresh']['first']:.2f} s, from the cache "
          f"{comp['cached']['first']:.2f} s", flush=True)
    print("kernel ...", flush=True)
    kern = kernel_speed(repeats, seed=1)
    print(f"  numba {kern['numba'] * 1e6:.1f} us/design, numpy {kern['numpy'] * 1e6:.1f}, bound "
          f"{kern['bound'] * 1e6:.1f}", flush=True)
    print("runs ...", flush=True)
    rows = runs(problems, algorithms, args.evals, args.seed)
    text = report(args, comp, kern, rows)
    print(text)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
