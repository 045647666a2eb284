"""Property-based checks: any malformed input gives ValueError/TypeError naming the argument,
never a NaN, a hang or an exception from deep inside numpy."""

import collections
import functools
import os
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import robustctl as rc
from robustctl import rlqr_step, rlqr_step_block
from robustctl.synthesis.hinf_riccati import hinf_riccati
from robustctl.synthesis.lqr import dare
from robustctl.systems.stability import unstabilizable_modes

dims = st.integers(1, 4)
SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(n=dims, m=dims, rows_G=dims, cols_F=dims, dt=st.one_of(st.floats(-1.0, 1.0), st.just(np.nan)))
def test_plant_shapes_and_dt(n, m, rows_G, cols_F, dt):
    F, G = np.zeros((n, cols_F)), np.zeros((rows_G, m))
    valid = cols_F == n and rows_G == n and dt > 0
    if valid:
        p = rc.Plant(F, G, dt)
        assert (p.n, p.m) == (n, m)
    else:
        with pytest.raises(ValueError, match=r"^(F|G|dt) "):
            rc.Plant(F, G, dt)


@SETTINGS
@given(l=dims, cols_EF=dims, rows_EG=dims, cols_EG=dims)
def test_rlqr_shape_errors_name_the_argument(l, cols_EF, rows_EG, cols_EG):
    plant = rc.Plant(0.5 * np.eye(3), np.ones((3, 2)), 0.1)
    EF, EG = np.ones((l, cols_EF)), np.ones((rows_EG, cols_EG))
    if cols_EF == 3 and rows_EG == l and cols_EG == 2:
        # (EF, EG all ones at mu = 10 can destabilise even this stable plant: shapes are the point here)
        assert np.isfinite(rc.rlqr(plant, EF, EG, 10.0, check_stability=False).K).all()
    else:
        with pytest.raises(ValueError, match=r"^(EF|EG) must have"):
            rc.rlqr(plant, EF, EG, 10.0)


@SETTINGS
@given(mu=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5)),
       alpha=st.floats(-1.0, 2.0, allow_nan=False))
def test_rlqr_scalars(mu, alpha):
    plant = rc.Plant(0.5 * np.eye(2), np.eye(2), 0.1)
    EF, EG = np.array([[0.3, 0.1]]), np.array([[1.0, 0.5]])
    bad_mu = not (mu >= 1e-100)  # NaN, 0, negative, or below the documented floor
    if bad_mu or alpha <= 0:
        with pytest.raises(ValueError, match=r"^(mu|alpha) "):
            rc.rlqr(plant, EF, EG, mu, alpha=alpha)
    else:
        try:
            c = rc.rlqr(plant, EF, EG, mu, alpha=alpha)
        except rc.ConvergenceError:
            return  # a clear, named failure is acceptable; silent NaN is not
        assert np.isfinite(c.K).all()


@SETTINGS
@given(where=st.sampled_from(["F", "G", "EF", "EG", "Q", "R", "H"]),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_non_finite_entries_are_named(where, value):
    data = {"F": 0.5 * np.eye(2), "G": np.eye(2), "EF": np.array([[0.3, 0.1]]),
            "EG": np.array([[1.0, 0.5]]), "Q": np.eye(2), "R": np.eye(2), "H": np.ones((2, 1))}
    data[where] = data[where].copy()
    data[where][0, 0] = value

    def design():  # Plant (F, G) or rlqr (the others) refuses the entry
        rc.rlqr(rc.Plant(data["F"], data["G"], 0.1), data["EF"], data["EG"], 10.0, Q=data["Q"], R=data["R"],
                H=data["H"])

    with pytest.raises(ValueError, match=rf"^{where} must have finite entries"):
        design()


@SETTINGS
@given(B=st.integers(1, 5), seed=st.integers(0, 10_000))
def test_batch_never_returns_unflagged_nan(B, seed):
    rng = np.random.default_rng(seed)
    plant = rc.Plant(rng.standard_normal((3, 3)), rng.standard_normal((3, 1)), 0.1)
    EF = rng.uniform(0, 500, (B, 1, 3))
    EG = rng.uniform(0, 500, (B, 1, 1)) * rng.integers(0, 2, (B, 1, 1))
    mu = 10 ** np.sqrt(rng.uniform(0, 500, B))
    mu[rng.random(B) < 0.3] = np.inf
    b = rc.rlqr_gains(plant, EF, EG, mu)
    assert np.isfinite(b.K[b.ok]).all() and np.isfinite(b.P[b.ok]).all()
    assert np.isnan(b.K[~b.ok]).all()
    assert set(b.reason) <= {"ok", "rank", "diverged", "not converged"}


# ---------------------------------------------------------------------------- issue 12, causes 2-7
# Every public function of robustctl's core gets, for each of its arguments, values of each bad kind:
# a boolean, a string (also numeric-looking), a complex number, a ragged nested list, None, a non-finite
# entry, a junk object. Handled well = ValueError/TypeError whose message starts with the argument's name
# (the project's subclasses count). TALLY counts cases tried / handled well per (function, cause); set
# ROBUSTCTL_TALLY=<file> to write the table.
TALLY = collections.defaultdict(lambda: [0, 0])

F2, G2 = np.array([[1.1, 0.2], [0.0, 0.9]]), np.array([[0.0], [1.0]])
PLANT = rc.Plant(F2, G2, 0.1)
EF2, EG2, H2 = np.array([[0.1, 0.2]]), np.array([[0.1]]), np.ones((2, 1))
UNC = rc.NormBounded(H2, EF2, EG2)
CTRL = rc.rlqr(PLANT, EF2, EG2, 1e4)
A2 = np.array([[0.0, 1.0], [-2.0, -3.0]])
I1, I2, X2, DELTA2 = np.eye(1), np.eye(2), np.ones(2), np.array([0.5, -0.5])   # valid default values
RLQR_ARGS = {"EF": EF2, "EG": EG2, "mu": 1e4, "Q": np.eye(2), "R": np.eye(1), "H": H2, "alpha": 0.1,
             "tol": 1e-10, "max_iter": 100}


def _rlqr(**kw):
    a = {**RLQR_ARGS, **kw}
    return rc.rlqr(PLANT, a.pop("EF"), a.pop("EG"), a.pop("mu"), **a)


def _gains(**kw):
    a = {**RLQR_ARGS, "EF": np.ones((3, 1, 2)) * EF2, "mu": [1e2, 1e4, np.inf], **kw}
    return rc.rlqr_gains(PLANT, a.pop("EF"), a.pop("EG"), a.pop("mu"), **a)


def _schedule(**kw):
    a = {**RLQR_ARGS, "horizon": 3, **kw}
    a.pop("tol"), a.pop("max_iter")
    return rc.rlqr_schedule(PLANT, a.pop("EF"), a.pop("EG"), a.pop("mu"), **a)


def _step(**kw):
    a = {"P_next": np.eye(2), "F": F2, "G": G2, "EF": EF2, "EG": EG2, "Q": np.eye(2), "R": np.eye(1), "H": H2,
         "mu": 1e4, "alpha": 0.1, **kw}
    return rlqr_step(**a), rlqr_step_block(**a)


# function -> {argument: (valid value, kind)}; kind "matrix", "scalar" (inf allowed where the function says),
# "int", "flag", "choice"
CASES = {
    "Plant": (lambda F=F2, G=G2, dt=0.1: rc.Plant(F, G, dt), {"F": F2, "G": G2, "dt": 0.1}),
    "Plant.from_continuous": (lambda A=A2, B=G2, dt=0.1, method="zoh": rc.Plant.from_continuous(A, B, dt, method),
                              {"A": A2, "B": G2, "dt": 0.1, "method": "zoh"}),
    "NormBounded": (lambda H=H2, EF=EF2, EG=EG2: rc.NormBounded(H, EF, EG), {"H": H2, "EF": EF2, "EG": EG2}),
    "NormBounded.perturb": (lambda plant=PLANT, Delta=0.5: UNC.perturb(plant, Delta), {"plant": PLANT, "Delta": 0.5}),
    "NormBounded.perturbed_matrices": (lambda Delta=DELTA2: UNC.perturbed_matrices(PLANT, Delta),
                                       {"Delta": np.array([0.5, -0.5])}),
    "Controller": (lambda K=CTRL.K, plant=PLANT: rc.Controller(K, "x", plant), {"K": CTRL.K, "plant": PLANT}),
    "Controller.__call__": (lambda x=X2: CTRL(x), {"x": np.ones(2)}),
    "Controller.closed_loop": (lambda plant=PLANT: CTRL.closed_loop(plant), {"plant": PLANT}),
    "Controller.to_statespace": (lambda plant=PLANT: CTRL.to_statespace(plant), {"plant": PLANT}),
    "design": (lambda method="lqr": rc.design(method, PLANT), {"method": "lqr"}),
    "lqr": (lambda plant=PLANT, Q=I2, R=I1: rc.lqr(plant, Q=Q, R=R),
            {"plant": PLANT, "Q": np.eye(2), "R": np.eye(1)}),
    "dare": (lambda F=F2, G=G2, Q=I2, R=I1: dare(F, G, Q, R),
             {"F": F2, "G": G2, "Q": np.eye(2), "R": np.eye(1)}),
    "rlqr": (_rlqr, {**RLQR_ARGS, "accelerate": True, "implementation": "kkt", "fallback": "newton",
                     "P_N": np.eye(2)}),
    "rlqr_schedule": (_schedule, {"horizon": 3, "EF": EF2, "EG": EG2, "mu": 1e4, "H": H2, "alpha": 0.1,
                                  "P_N": np.eye(2), "implementation": "kkt"}),
    "rlqr_gains": (_gains, {"EF": np.ones((3, 1, 2)) * EF2, "EG": EG2, "mu": np.array([1e2, 1e4, np.inf]),
                            "Q": np.eye(2), "R": np.eye(1), "H": H2, "alpha": 0.1, "tol": 1e-10,
                            "max_iter": 100, "P_N": np.eye(2), "fallback": "newton"}),
    "rlqr_step": (_step, {"P_next": np.eye(2), "F": F2, "G": G2, "EF": EF2, "EG": EG2, "Q": np.eye(2),
                          "R": np.eye(1), "H": H2, "mu": 1e4, "alpha": 0.1}),
    "spectral_radius": (lambda A=F2: rc.spectral_radius(A), {"A": F2}),
    "is_schur_stable": (lambda A=F2: rc.is_schur_stable(A), {"A": F2}),
    "unstabilizable_modes": (lambda F=F2, G=G2: unstabilizable_modes(F, G), {"F": F2, "G": G2}),
}

# ---- the LMI syntheses (hinf, h2, the Riccati reference), pole regions and the robust analysis
BW2, CZ2, DZU2 = np.array([[0.0], [1.0]]), np.vstack([np.eye(2), [[0.0, 0.0]]]), np.array([[0.0], [0.0], [1.0]])
DZW2 = np.zeros((3, 1))
PERF = {"Bw": BW2, "Cz": CZ2, "Dzu": DZU2, "Dzw": DZW2}
UNC_A = rc.NormBounded(0.1 * H2, EF2, EG2)   # small enough for CTRL to be robustly stable (margin 3.15)
VERTEX = UNC_A.perturb(PLANT, 1.0)


def _hinf(plant=PLANT, **kw):
    return rc.hinf(plant, **{"Bw": BW2, "Cz": CZ2, "Dzu": DZU2, **kw})


def _h2(plant=PLANT, **kw):
    return rc.h2(plant, **{"Bw": BW2, "Cz": CZ2, "Dzu": DZU2, **kw})


def _riccati(plant=PLANT, **kw):
    return hinf_riccati(plant, **{"Bw": BW2, "Cz": CZ2, "Dzu": DZU2, **kw})


def _hinf_bound(controller=CTRL, uncertainty=UNC_A, **kw):
    return rc.robust_hinf_bound(controller, uncertainty, **{"Bw": BW2, "Cz": CZ2, "Dzu": DZU2, **kw})


CASES.update({
    "hinf": (_hinf, {"plant": PLANT, **PERF, "vertices": [VERTEX], "gamma": 10.0, "u_max": 100.0,
                     "w_energy": 1.0, "backoff": 1e-3, "extended": False, "poles": rc.Disk(0.0, 0.999),
                     "uncertainty": UNC_A, "solver": "CLARABEL"}),
    "h2": (_h2, {"plant": PLANT, **PERF, "vertices": [VERTEX], "poles": rc.Disk(0.0, 0.999), "backoff": 1e-3,
                 "solver": "CLARABEL"}),
    "hinf_riccati": (_riccati, {"plant": PLANT, **PERF, "rtol": 1e-9, "gamma_max": 1e10}),
    "Disk": (lambda center=0.0, radius=0.5: rc.Disk(center, radius), {"center": 0.0, "radius": 0.5}),
    "HalfPlane": (lambda boundary=-1.0, side="left": rc.HalfPlane(boundary, side), {"boundary": -1.0, "side": "left"}),
    "ConicSector": (lambda apex=0.0, angle=0.5: rc.ConicSector(apex, angle), {"apex": 0.0, "angle": 0.5}),
    "robust_stability": (lambda controller=CTRL, uncertainty=UNC_A: rc.robust_stability(controller, uncertainty),
                         {"controller": CTRL, "uncertainty": UNC_A}),
    "robust_stability(vertices)": (lambda vertices=(VERTEX,): rc.robust_stability(CTRL, vertices=vertices),
                                   {"vertices": [VERTEX]}),
    "robust_stability((plant, K))": (lambda K=CTRL.K: rc.robust_stability((PLANT, K), UNC_A), {"K": CTRL.K}),
    "guaranteed_cost": (lambda controller=CTRL, uncertainty=UNC_A, Q=I2, R=I1, x0=None:
                        rc.guaranteed_cost(controller, uncertainty, Q, R, x0),
                        {"controller": CTRL, "uncertainty": UNC_A, "Q": np.eye(2), "R": np.eye(1), "x0": np.ones(2)}),
    "robust_hinf_bound": (_hinf_bound, {"controller": CTRL, "uncertainty": UNC_A, **PERF}),
    "worst_case": (lambda controller=CTRL, uncertainty=UNC_A, seed=0, n_starts=2:
                   rc.worst_case(controller, uncertainty, seed=seed, n_starts=n_starts),
                   {"controller": CTRL, "uncertainty": UNC_A, "seed": 0, "n_starts": 2}),
})
FLAGS = {"accelerate", "extended"}
CHOICES = {"method", "implementation", "fallback", "solver", "side"}
INTS = {"max_iter", "horizon", "n_starts", "seed"}
OBJECTS = {"vertices", "poles", "uncertainty", "controller"}   # drawn like a plant: anything but the right type
VALID_NAMES = ("kkt", "block", "recursion", "newton", "zoh", "tustin", "euler", "lqr", "rlqr", "hinf", "h2",
               "left", "right", "clarabel", "scs", "scipy", "highs", "osqp", "cvxopt", "mosek")
# None is a documented value of these (default, identity, continuous time, the design plant, no bound, ...)
NONE_OK = {"P_N", "H", "Q", "R", "dt", "Dzw", "vertices", "gamma", "u_max", "w_energy", "poles",
           "uncertainty", "x0", "seed"}
INF_OK = {"mu"}  # inf is a valid value of these
CAUSES = ["bool", "string", "numeric string", "complex", "ragged", "None", "nan", "inf", "object"]
_JUNK = st.sampled_from([{"key": 1}, object(), {1, 2}, b"bytes", print])


def _at_one_entry(arr, make):
    """A nested list like ``arr`` with one (drawn) entry replaced by ``make(entry)``."""
    @st.composite
    def draw(draw_):
        flat = arr.ravel().tolist()
        k = draw_(st.integers(0, len(flat) - 1))
        flat[k] = draw_(make(flat[k]))
        return np.array(flat, dtype=object).reshape(arr.shape).tolist()
    return draw()


def _bad(valid, cause, name):
    """A strategy of bad values of kind ``cause`` shaped like ``valid`` (None when the cause does not apply)."""
    if cause == "None":
        return st.none()
    if cause == "object":
        return _JUNK
    if name in FLAGS:
        return {"bool": None, "string": st.text(max_size=5), "numeric string": st.sampled_from(["1", "0", "True"]),
                "complex": st.just(1j), "ragged": st.just([[True], []]), "nan": st.just(np.nan),
                "inf": st.sampled_from([0, 1, 1.0])}[cause]
    if name in CHOICES:
        return {"bool": st.booleans(), "string": st.text(max_size=6).filter(lambda t: t.lower() not in VALID_NAMES),
                "numeric string": st.just("1"), "complex": st.just(1j), "ragged": st.just([["kkt"], []]),
                "nan": st.just(np.nan), "inf": st.just(np.inf)}[cause]
    if name == "seed" and cause == "ragged":
        return None  # numpy's SeedSequence takes nested sequences of integers as entropy
    if isinstance(valid, rc.Plant) or name in OBJECTS:
        return {"bool": st.booleans(), "string": st.text(max_size=5), "numeric string": st.just("1"),
                "complex": st.just(1j), "ragged": st.just([[1.0], [1.0, 2.0]]), "nan": st.just(np.nan),
                "inf": st.just(np.inf)}[cause]
    arr = np.asarray(valid, dtype=float)
    finite = st.floats(-10, 10, allow_nan=False)
    if cause == "bool":
        if arr.ndim == 0:
            return st.sampled_from([True, False, np.True_, np.False_])
        return st.one_of(st.just(np.ones(arr.shape, dtype=bool)), _at_one_entry(arr, lambda x: st.booleans()))
    if cause == "string":
        text = st.text(min_size=1, max_size=4)
        return text if arr.ndim == 0 else _at_one_entry(arr, lambda x: text)
    if cause == "numeric string":
        return st.just(repr(float(arr))) if arr.ndim == 0 else st.just(arr.astype(str).tolist())
    if cause == "complex":
        imag = st.floats(0.1, 10).map(lambda b: complex(0, b))
        return imag.map(lambda z: float(arr) + z) if arr.ndim == 0 else _at_one_entry(arr, lambda x: imag.map(
            lambda z: x + z))
    if cause == "ragged":
        if arr.ndim == 0:
            return st.just([[1.0], [1.0, 2.0]])
        rows = np.atleast_2d(arr).tolist()

        @st.composite
        def ragged(draw_):
            out = [list(r) for r in rows] + [list(rows[-1])]
            k = draw_(st.integers(0, len(out) - 1))
            out[k] = out[k] + [draw_(finite)] if draw_(st.booleans()) or len(out[k]) == 1 else out[k][:-1]
            return out if arr.ndim <= 2 else [out, [[1.0]]]
        return ragged()
    if name in INF_OK and cause == "inf":
        return None
    bad = st.just(np.nan) if cause == "nan" else st.sampled_from([np.inf, -np.inf])
    if arr.ndim == 0:
        return bad
    return _at_one_entry(arr, lambda x: bad).map(lambda v: np.array(v, dtype=float))


def _handled_well(call, name) -> bool:
    try:
        with np.errstate(all="ignore"):
            call()
    except (TypeError, ValueError) as exc:
        return re.match(rf"{re.escape(name)}\b", str(exc)) is not None or (
            name == "plant" and str(exc).startswith("plant must"))
    except Exception:  # noqa: BLE001 - anything else (numpy, scipy, AttributeError, ...) is not handled well
        return False
    return False  # a bad value accepted


@pytest.fixture(scope="module", autouse=True)
def _write_tally():
    yield
    if os.environ.get("ROBUSTCTL_TALLY") and TALLY:
        with open(os.environ["ROBUSTCTL_TALLY"], "w") as fh:
            fh.writelines(f"{func}\t{cause}\t{tried}\t{good}\n"
                          for (func, cause), (tried, good) in sorted(TALLY.items()))


@pytest.mark.parametrize("func", sorted(CASES))
@pytest.mark.parametrize("cause", CAUSES)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_every_bad_argument_is_named(func, cause, data):
    call, args = CASES[func]
    for name, valid in args.items():
        if cause == "None" and (name in NONE_OK or func.startswith("Controller.")):
            continue  # None is a documented value there
        if cause in ("nan", "inf") and func in ("spectral_radius", "is_schur_stable"):
            continue  # documented: radius inf, unstable (checked in test_stability)
        strategy = _bad(valid, cause, name)
        if strategy is None:
            continue
        value = data.draw(strategy, label=name)
        TALLY[(func, cause)][0] += 1
        ok = _handled_well(functools.partial(call, **{name: value}), name)
        TALLY[(func, cause)][1] += ok
        assert ok, (func, name, cause, value)


@pytest.mark.parametrize("func", sorted(CASES))
def test_the_valid_calls_of_the_table_work(func):
    CASES[func][0]()


@SETTINGS
@given(seed=st.integers(0, 10_000), mode=st.one_of(st.floats(1.0, 3.0), st.floats(-3.0, -1.0), st.floats(-0.95, 0.95)),
       mu=st.sampled_from([1.0, 1e6, np.inf]))
def test_unstabilisable_plants_raise_in_every_design_and_flag_in_the_batch(seed, mode, mu):
    """Cause 2: a constructed uncontrollable mode; |mode| >= 1 -> NotStabilizableError from lqr and rlqr."""
    rng = np.random.default_rng(seed)
    T = np.linalg.qr(rng.standard_normal((3, 3)))[0] * [1.0, 2.0, 3.0]  # well conditioned (cond <= 3): F stays O(1)
    F = np.zeros((3, 3))
    F[:2, :2], F[:2, 2], F[2, 2] = 0.5 * rng.standard_normal((2, 2)), rng.standard_normal(2), mode
    G = np.vstack([rng.standard_normal((2, 1)), [[0.0]]])
    plant = rc.Plant(T @ F @ np.linalg.inv(T), T @ G, 0.1)
    EF, EG = rng.uniform(0.1, 1, (1, 3)), rng.uniform(0.5, 1, (1, 1))
    TALLY[("lqr / rlqr / rlqr_gains", "unstabilisable")][0] += 1
    if abs(mode) < 1:
        assert plant.is_stabilizable
        assert rc.lqr(plant).is_stabilizing()
        TALLY[("lqr / rlqr / rlqr_gains", "unstabilisable")][1] += 1
        return
    for design in (lambda: rc.lqr(plant), lambda: rc.rlqr(plant, EF, EG, mu)):
        with pytest.raises(rc.NotStabilizableError, match=r"^plant is not stabilisable: its mode lambda"):
            design()
    b = rc.rlqr_gains(plant, EF, EG, [mu, 2 * mu])
    assert list(b.reason) == ["unstabilizable"] * 2 and np.isnan(b.K).all()
    TALLY[("lqr / rlqr / rlqr_gains", "unstabilisable")][1] += 1


@SETTINGS
@given(dt=st.floats(0.01, 1.0), other=st.floats(-5.0, 5.0), scale=st.floats(1e200, 1e300))
@example(dt=0.8585158091592887, other=2.0, scale=1e200)  # I - A dt/2 = diag(eps/2, 0.14): cond 1.3e15 < 1/eps
def test_discretisation_failures_name_A(dt, other, scale):
    """Cause 6 (tustin with I - A dt/2 singular) and 5 (A dt overflowing is A's fault, not F's)."""
    A = np.diag([2.0 / dt, other])
    for bad, method, match in ((A, "tustin", r"^method='tustin' needs I - A dt/2 invertible"),
                               (scale * np.eye(2), "zoh", r"^A is too large")):
        TALLY[("Plant.from_continuous", "discretisation")][0] += 1
        with pytest.raises(ValueError, match=match):
            rc.Plant.from_continuous(bad, [[1.0], [1.0]], dt=dt, method=method)
        TALLY[("Plant.from_continuous", "discretisation")][1] += 1


@SETTINGS
@given(shape=st.sampled_from([(2,), (4, 2), (3, 5, 2)]), seed=st.integers(0, 1000),
       value=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_controller_refuses_non_finite_states(shape, seed, value):
    """Cause 7: a NaN or inf state anywhere in a stack is refused, never passed through."""
    x = np.random.default_rng(seed).standard_normal(shape)
    x.flat[seed % x.size] = value
    TALLY[("Controller.__call__", "non-finite state")][0] += 1
    with pytest.raises(ValueError, match=r"^x must have finite entries"):
        CTRL(x)
    TALLY[("Controller.__call__", "non-finite state")][1] += 1


def test_issue_12_booleans_in_the_lmi_syntheses_and_the_analysis():
    """Cause 3 for the LMI syntheses: u_max=True was accepted as a bound of 1."""
    cases = [(lambda: _hinf(u_max=True), TypeError, "^u_max must be a positive number, got a boolean"),
             (lambda: _hinf(u_max=[True]), TypeError, "^u_max must be a positive number, got booleans"),
             (lambda: _hinf(backoff=True), TypeError, "^backoff must be a real number, got a boolean"),
             (lambda: _h2(backoff="0.1"), TypeError, "^backoff must be a real number, got str"),
             (lambda: _hinf(gamma=True), TypeError, r"^gamma must be a real number > 0, got a boolean"),
             (lambda: _hinf(extended=1), TypeError, r"^extended must be a bool \(True or False\), got 1"),
             (lambda: rc.Disk(0.0, True), TypeError, r"^radius must be a real number > 0, got a boolean"),
             (lambda: rc.ConicSector(0.0, 1j), TypeError, "^angle must be a real number, got complex"),
             (lambda: rc.worst_case(CTRL, UNC_A, seed=True), TypeError, "^seed must be None, an integer"),
             (lambda: rc.worst_case(CTRL, UNC_A, seed="x"), TypeError, "^seed must be None, an integer"),
             (lambda: _riccati(gamma_max=True), TypeError, "^gamma_max must be a real number > 0")]
    for call, err, match in cases:
        with pytest.raises(err, match=match):
            call()
    m2 = rc.Plant(F2, np.ones((2, 2)), 0.1)
    kw = dict(Bw=BW2, Cz=np.vstack([np.eye(2), np.zeros((2, 2))]), Dzu=np.vstack([np.zeros((2, 2)), np.eye(2)]))
    with pytest.raises(ValueError, match=r"^u_max must be a scalar or have 2 entries \(the number of inputs\)"):
        rc.hinf(m2, **kw, u_max=[1.0, 2.0, 3.0])
    with pytest.raises(TypeError, match=r"^u_max must be a positive number or 2 positive numbers, got str"):
        rc.hinf(m2, **kw, u_max="1")
    with pytest.raises(ValueError, match=r"^u_max must be > 0 for every entry, got \[1.0, -2.0\]"):
        rc.hinf(m2, **kw, u_max=[1.0, -2.0])


@pytest.mark.parametrize("mu", [4.49e307, 1.7e308])
def test_rlqr_mu_near_the_float_limit_is_finite_and_silent(mu):
    """Hypothesis found an overflow warning in the reported lambda = (1 + alpha) mu ||H'H|| at mu = 4.49e307."""
    plant = rc.Plant(0.5 * np.eye(2), np.eye(2), 0.1)
    EF, EG = np.array([[0.3, 0.1]]), np.array([[1.0, 0.5]])
    c = rc.rlqr(plant, EF, EG, mu, alpha=2.0)
    ref = rc.rlqr(plant, EF, EG, np.inf, alpha=2.0)
    assert np.isfinite(c.K).all() and c.info["lambda"] == np.inf
    np.testing.assert_allclose(c.K, ref.K, rtol=1e-9)
