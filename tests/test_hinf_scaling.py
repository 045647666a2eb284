"""The syntheses do not depend on the units of the disturbance ``w`` and the performance output ``z``.

Scaling ``z`` by ``a`` (``Cz, Dzu, Dzw``) and ``w`` by ``b`` (``Bw, Dzw``; the
input bound's ``w_energy`` by ``1 / b^2``, the same set of disturbances)
scales every level by ``a b`` and leaves the optimal gain unchanged. Swept
over ``a, b`` from 1e-6 to 1e6 on random plants and on the truck with the
weights of the authors' code (``Q = diag(1, 1, 25000, 100)``, ``R = 33535``,
``Bw = ones``), where the LMI synthesis failed and the Riccati bisection
stopped at 3.2 times the optimum before the channels were scaled inside.

References: the unscaled design (level / (a b) to 1e-6 relative), python-control's
``linfnorm`` of every scaled closed loop (it meets the scaled level, and
for one plant no gain beats the Riccati optimum), the game-Riccati
bisection, scipy's DARE (the H2 optimum), the exact worst-case input.

Gains: where the gain is a function of the data (the optimum's own gain of
one discrete plant, the Riccati bisection, H2) it agrees to 1e-5. A gain of
a centring problem (continuous time, vertices, the extended LMI, an
uncertainty) is one strictly feasible point found to the centring
tolerance: a perturbation of the data by 1e-15 relative moves it by up to
5e-5 (measured on the msd polytope with the extended LMI, before and after
this change; 1.4e-4 over these scales), so it is compared at 1e-3.

Every gain's closed loop is evaluated by ``linfnorm`` in the reference
units (``||T_zw||`` in units ``a, b`` is ``a b`` times that): python-control's
``linfnorm`` of one and the same loop misses the peak on scaled data (the
truck with the norm-bounded uncertainty at ``Delta = 1``: 11964 instead of
12999 at ``a = 1e6``; a 2e5-point frequency grid gives 12998.6).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from test_hinf import MSD_BW, MSD_CZ, MSD_DZU, cl_norm, msd, random_case, worst_case_input

import robustctl as rc
from robustctl.models import truck
from robustctl.synthesis.hinf_riccati import hinf_riccati

SCALES = [(1e-6, 1.0), (1e6, 1.0), (1.0, 1e-6), (1.0, 1e6), (1e-3, 1e3), (1e6, 1e6), (1e-6, 1e-6)]
LEVEL_RTOL = 1e-6
GAIN_RTOL = 1e-5            # a gain that is a function of the data
CENTRED_GAIN_RTOL = 1e-3    # a centring problem's gain (module docstring)
DETERMINED = {"optimum-certified", "optimum"}


def authors_truck():
    """The truck with the weights of the authors' code: z = [sqrt(Q) x; sqrt(R) u], Bw = H = ones."""
    Q, R = np.diag([1.0, 1.0, 25000.0, 100.0]), np.array([[33535.0]])
    return (truck.truck_plant(0.0), np.ones((4, 1)), *rc.lq_output(Q, R))


def scaled(perf: dict, a: float, b: float, **kw) -> dict:
    """``z`` times ``a`` and ``w`` times ``b`` (``w_energy`` over ``b^2``: the same disturbances)."""
    out = dict(perf, Bw=b * perf["Bw"], Cz=a * perf["Cz"], Dzu=a * perf["Dzu"])
    if perf.get("Dzw") is not None:
        out["Dzw"] = a * b * perf["Dzw"]
    if "w_energy" in kw:
        kw = dict(kw, w_energy=kw["w_energy"] / b**2)
    return {**out, **kw}


def relative_change(K, K_ref) -> float:
    return float(np.max(np.abs(K - K_ref)) / np.max(np.abs(K_ref)))


def one_plant_cases():
    """``(name, plant, channels)`` of every synthesis: a discrete plant with Dzw, a continuous one, the truck."""
    plant, Bw, Cz, Dzu, Dzw = random_case(1, 4, 2, 2, discrete=True, cross=True)
    yield "discrete, Dzw", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu, Dzw=Dzw)
    plant, Bw, Cz, Dzu, _ = random_case(2, 5, 2, 2, discrete=False)
    yield "continuous", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu)
    plant, Bw, Cz, Dzu = authors_truck()
    yield "truck, authors' weights", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu)


def truck_polytope():
    plant, Bw, Cz, Dzu = authors_truck()
    return "truck polytope", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu), dict(vertices=[truck.truck_plant(300.0)])


def hinf_cases():
    for case in one_plant_cases():
        yield (*case, {})
    yield truck_polytope()
    plant, Bw, Cz, Dzu = authors_truck()
    yield "msd polytope", msd(1.0), dict(Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU), dict(vertices=[msd(4.0)])
    yield "msd extended", msd(1.0), dict(Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU), dict(vertices=[msd(4.0)],
                                                                                  extended=True)
    yield "truck, steering limit", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu), dict(u_max=truck.STEER_LIMIT,
                                                                            w_energy=1e-3)
    rplant, rBw, rCz, rDzu, _ = random_case(1, 4, 2, 2, discrete=True)
    free = rc.hinf(rplant, Bw=rBw, Cz=rCz, Dzu=rDzu)
    yield "discrete, input bound", rplant, dict(Bw=rBw, Cz=rCz, Dzu=rDzu), dict(
        u_max=0.5 * worst_case_input(rplant, free.K, rBw, 1.0), w_energy=1.0)
    yield "truck, norm-bounded", plant, dict(Bw=Bw, Cz=Cz, Dzu=Dzu), dict(
        uncertainty=rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]]))
    uplant, uBw, uCz, uDzu, _ = random_case(3, 4, 2, 2, discrete=True)
    yield "discrete, norm-bounded", uplant, dict(Bw=uBw, Cz=uCz, Dzu=uDzu), dict(
        uncertainty=rc.NormBounded(0.2 * np.ones((4, 1)), 0.3 * np.ones((1, 4)), 0.1 * np.ones((1, 2))))


def guaranteed_plants(plant, kw):
    """The plants on which the level is checked: the vertices, or the uncertainty's extremes (Delta = +-1)."""
    plants = [plant, *kw.get("vertices", [])]
    unc = kw.get("uncertainty")
    if unc is not None:
        plants += [unc.perturb(plant, d) for d in (-1.0, 1.0)]
    return plants


@pytest.mark.parametrize("name,plant,perf,kw", [pytest.param(*c, id=c[0]) for c in hinf_cases()])
def test_hinf_level_and_gain_do_not_depend_on_the_units(name, plant, perf, kw):
    ref = rc.hinf(plant, **perf, **kw)
    optimum = None
    if not kw:   # one plant: the Riccati optimum, a lower bound of every gain's norm
        optimum = hinf_riccati(plant, **perf)
        assert ref.gamma_opt == pytest.approx(optimum.gamma, rel=1e-5)
    determined = ref.info["gain_from"] in DETERMINED
    for a, b in SCALES:
        args = scaled(perf, a, b, **kw)
        ctrl = rc.hinf(plant, **args)
        assert ctrl.gamma_opt / (a * b) == pytest.approx(ref.gamma_opt, rel=LEVEL_RTOL), (a, b)
        assert ctrl.gamma / (a * b) == pytest.approx(ref.gamma, rel=LEVEL_RTOL), (a, b)
        assert relative_change(ctrl.K, ref.K) <= (GAIN_RTOL if determined else CENTRED_GAIN_RTOL), (a, b)
        # the guarantee ||T_zw|| < gamma in the scaled units, i.e. gamma / (a b) in the reference ones
        norm = max(cl_norm(p, ctrl.K, perf["Bw"], perf["Cz"], perf["Dzu"], perf.get("Dzw"))
                   for p in guaranteed_plants(plant, kw))
        assert norm <= ctrl.gamma / (a * b) * (1 + 1e-6), (a, b)
        if optimum is not None:
            assert norm >= optimum.gamma_low * (1 - 1e-6), (a, b)
        if "u_max" in kw:
            worst = worst_case_input(plant, ctrl.K, args["Bw"], args["w_energy"])
            assert np.all(worst <= kw["u_max"] * (1 + 1e-9)), (a, b)
            assert np.allclose(ctrl.info["u_bound"], ref.info["u_bound"], rtol=1e-6), (a, b)


def test_the_authors_truck_weights_need_no_scaling_by_hand():
    """The reported case: ConvergenceError unscaled, 10441.67 after z / sqrt(r) by hand; the bisection gave 33429."""
    plant, Bw, Cz, Dzu = authors_truck()
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    s = 1.0 / np.sqrt(33535.0)
    by_hand = rc.hinf(plant, Bw=Bw, Cz=s * Cz, Dzu=s * Dzu)
    assert ctrl.gamma == pytest.approx(by_hand.gamma / s, rel=LEVEL_RTOL)
    assert ctrl.gamma == pytest.approx(10441.67, rel=1e-6)
    ric = hinf_riccati(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    assert ric.gamma == pytest.approx(hinf_riccati(plant, Bw=Bw, Cz=s * Cz, Dzu=s * Dzu).gamma / s, rel=1e-8)
    assert ctrl.gamma_opt == pytest.approx(ric.gamma, rel=1e-6)
    # both gains meet their levels (linfnorm), and the optimum is not 3x lower than the bisection's level
    assert cl_norm(plant, ric.K, Bw, Cz, Dzu) <= ric.gamma * (1 + 1e-8)
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma * (1 + 1e-6)
    assert ric.gamma_low <= cl_norm(plant, ctrl.K, Bw, Cz, Dzu) * (1 + 1e-8)


def test_a_fixed_level_with_a_pole_region_does_not_depend_on_the_units():
    """``gamma`` given in the caller's units (times a b) and a pole region: the same gain, which meets both."""
    plant, Bw, Cz, Dzu = authors_truck()
    perf, region = dict(Bw=Bw, Cz=Cz, Dzu=Dzu), rc.Disk(0.0, 0.9999)
    ref = rc.hinf(plant, **perf, gamma=10500.0, poles=region)
    for a, b in SCALES:
        ctrl = rc.hinf(plant, **scaled(perf, a, b), gamma=10500.0 * a * b, poles=region)
        assert ctrl.gamma == 10500.0 * a * b and relative_change(ctrl.K, ref.K) <= GAIN_RTOL, (a, b)
        assert cl_norm(plant, ctrl.K, **perf) <= 10500.0
        assert np.all(region.contains(np.linalg.eigvals(plant.F + plant.G @ ctrl.K)))
        with pytest.raises(rc.InfeasibleError, match="gamma="):   # below the optimum 10431.2
            rc.hinf(plant, **scaled(perf, a, b), gamma=10400.0 * a * b)


@pytest.mark.parametrize("name,plant,perf", [pytest.param(*c, id=c[0]) for c in one_plant_cases()])
def test_riccati_bisection_does_not_depend_on_the_units(name, plant, perf):
    ref = hinf_riccati(plant, **perf)
    for a, b in SCALES:
        args = scaled(perf, a, b)
        res = hinf_riccati(plant, **args)
        assert res.gamma / (a * b) == pytest.approx(ref.gamma, rel=LEVEL_RTOL), (a, b)
        assert relative_change(res.K, ref.K) <= GAIN_RTOL, (a, b)
        np.testing.assert_allclose(res.P / a**2, ref.P, rtol=1e-5, atol=1e-8 * np.abs(ref.P).max())
        assert cl_norm(plant, res.K, **perf) <= res.gamma / (a * b) * (1 + 1e-8), (a, b)


def h2_cases():
    for case in one_plant_cases():
        yield (*case, {})
    yield truck_polytope()


def lqr_cost(plant, Bw, Cz, Dzu, Dzw=None) -> float:
    """The H2 optimum of one plant: sqrt(trace(Bw' P Bw) + trace(Dzw' Dzw)), P from scipy's Riccati solvers."""
    are = scipy.linalg.solve_discrete_are if plant.is_discrete else scipy.linalg.solve_continuous_are
    P = are(plant.F, plant.G, Cz.T @ Cz, Dzu.T @ Dzu, s=Cz.T @ Dzu)
    return float(np.sqrt(np.trace(Bw.T @ P @ Bw) + (0.0 if Dzw is None else np.sum(Dzw**2))))


@pytest.mark.parametrize("name,plant,perf,kw", [pytest.param(*c, id=c[0]) for c in h2_cases()])
def test_h2_cost_and_gain_do_not_depend_on_the_units(name, plant, perf, kw):
    ref = rc.h2(plant, **perf, **kw)
    if not kw:
        assert ref.h2_opt == pytest.approx(lqr_cost(plant, **perf), rel=1e-6)
    for a, b in SCALES:
        args = scaled(perf, a, b)
        ctrl = rc.h2(plant, **args, **kw)
        assert ctrl.h2_opt / (a * b) == pytest.approx(ref.h2_opt, rel=LEVEL_RTOL), (a, b)
        assert relative_change(ctrl.K, ref.K) <= GAIN_RTOL, (a, b)
        # the closed-loop H2 norms (Gramians, computed in the scaled units) meet the scaled bound
        assert np.all(ctrl.info["h2_norms"] <= ctrl.h2_bound * (1 + 1e-6)), (a, b)
        np.testing.assert_allclose(ctrl.info["h2_norms"] / (a * b), ref.info["h2_norms"], rtol=LEVEL_RTOL)
