"""Robust H-infinity state feedback for a norm-bounded uncertainty (hinf(..., uncertainty=NormBounded)).

The guarantee is checked on perturbed plants F + H Delta EF, G + H Delta EG
with python-control's linfnorm (SLICOT AB13DD), for sampled extreme points
of the unit ball (all singular values of Delta equal to 1, the vertices of
the spectral-norm ball) and for the worst one found by a local search from
the best samples. Nothing here uses the LMI code.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize
from test_hinf import MSD_BW, MSD_CZ, MSD_DZU, RTOL, cl_norm, msd, random_case

import robustctl as rc
from robustctl import InfeasibleError, NormBounded


def polar(Z: np.ndarray) -> np.ndarray:
    """The extreme point U V' of the unit ball nearest Z (all singular values 1)."""
    U, _, Vt = np.linalg.svd(Z, full_matrices=False)
    return U @ Vt


def perturbed_norm(plant, unc, K, Delta, Bw, Cz, Dzu) -> float:
    p = unc.perturb(plant, Delta)
    A = p.F + p.G @ K
    stable = np.max(np.abs(np.linalg.eigvals(A))) < 1 if p.is_discrete else np.max(np.linalg.eigvals(A).real) < 0
    return cl_norm(p, K, Bw, Cz, Dzu) if stable else np.inf


def worst_sampled(plant, unc, K, Bw, Cz, Dzu, n_samples=40, seed=0) -> float:
    """Largest linfnorm over random extreme points of the unit ball, then a local search from the best."""
    rng = np.random.default_rng(seed)
    shape = (unc.p, unc.l)
    samples = [polar(rng.normal(size=shape)) for _ in range(n_samples)]
    values = [perturbed_norm(plant, unc, K, D, Bw, Cz, Dzu) for D in samples]
    best = samples[int(np.argmax(values))]
    res = scipy.optimize.minimize(lambda z: -perturbed_norm(plant, unc, K, polar(z.reshape(shape)), Bw, Cz, Dzu),
                                  best.ravel(), method="Nelder-Mead", options={"maxiter": 150, "xatol": 1e-4})
    return max(*values, -res.fun)


def uncertain_case(discrete: bool, scale: float):
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete)
    rng = np.random.default_rng(0)
    unc = NormBounded(scale * rng.normal(size=(4, 2)), 0.2 * rng.normal(size=(3, 4)), 0.2 * rng.normal(size=(3, 2)))
    return plant, Bw, Cz, Dzu, unc


@pytest.mark.parametrize("discrete,scale", [(True, 0.5), (True, 1.0), (False, 0.5)])
def test_robust_bound_holds_on_sampled_and_worst_perturbations(discrete, scale):
    plant, Bw, Cz, Dzu, unc = uncertain_case(discrete, scale)
    nominal = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    robust = rc.design("hinf", plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=unc)
    worst = worst_sampled(plant, unc, robust.K, Bw, Cz, Dzu)
    assert worst <= robust.gamma * (1 + RTOL)
    assert worst >= 0.9 * robust.gamma_opt                         # the S-procedure bound is nearly tight here
    assert robust.gamma_opt >= nominal.gamma_opt
    # the nominal gain does not keep its own level under the same uncertainty
    assert worst_sampled(plant, unc, nominal.K, Bw, Cz, Dzu) > robust.gamma
    assert robust.info["uncertainty"] is unc and robust.info["multipliers"][0] > 0


def test_scalar_uncertainty_vertices_on_the_payload_of_a_mass():
    """dF, dG along 1/mass: the norm-bounded segment between two masses, checked at Delta = -1, 0, 1 and between."""
    lo, hi = msd(1.0), msd(2.0)
    mid = rc.Plant(0.5 * (lo.F + hi.F), 0.5 * (lo.G + hi.G), lo.dt)
    dF, dG = 0.5 * (hi.F - lo.F), 0.5 * (hi.G - lo.G)
    # [dF dG] is rank one here (only the acceleration row changes): H = e2, [EF EG] = its second row
    unc = NormBounded([[0.0], [1.0]], dF[1:2], dG[1:2])
    ctrl = rc.hinf(mid, Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, uncertainty=unc)
    for delta in np.linspace(-1.0, 1.0, 9):
        assert perturbed_norm(mid, unc, ctrl.K, [[delta]], MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.gamma * (1 + RTOL)
    assert cl_norm(lo, ctrl.K, MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.gamma * (1 + RTOL)


@pytest.mark.parametrize("discrete", [True, False])
def test_without_uncertainty_it_is_the_nominal_design(discrete):
    plant, Bw, Cz, Dzu, unc = uncertain_case(discrete, 1.0)
    nominal = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    zero_H = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=NormBounded(np.zeros((4, 2)), unc.EF, unc.EG))
    assert zero_H.gamma_opt == nominal.gamma_opt and np.array_equal(zero_H.K, nominal.K)
    zero_E = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=NormBounded(unc.H, 0 * unc.EF, 0 * unc.EG))
    assert zero_E.gamma_opt == nominal.gamma_opt and zero_E.info["uncertainty"] is None
    # the S-procedure itself, with an uncertainty too small to matter
    tiny = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=NormBounded(1e-6 * unc.H, unc.EF, unc.EG))
    assert tiny.gamma_opt == pytest.approx(nominal.gamma_opt, rel=1e-5)
    assert tiny.info["uncertainty"] is not None


def test_robust_design_with_vertices_input_bound_and_poles():
    unc = NormBounded([[0.0], [0.05]], [[0.3, 0.1]], [[0.0]])
    region = rc.Disk(0.9, 0.09)
    ctrl = rc.hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)], uncertainty=unc,
                   u_max=5.0, poles=region)
    for mass in (1.0, 2.5, 4.0):
        for delta in (-1.0, 0.0, 1.0):
            assert perturbed_norm(msd(mass), unc, ctrl.K, [[delta]], MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.gamma * (1 + RTOL)
        poles = np.linalg.eigvals(msd(mass).F + msd(mass).G @ ctrl.K)
        assert np.all(np.abs(poles - 0.9) < 0.09)
    assert ctrl.info["u_bound"][0] <= 5.0 and len(ctrl.info["multipliers"]) == 2


def test_too_large_uncertainty_is_infeasible_and_bad_input_is_named():
    plant, Bw, Cz, Dzu, unc = uncertain_case(False, 1.0)
    with pytest.raises(InfeasibleError, match=r"for every \|\|Delta\|\| <= 1 of the norm-bounded uncertainty"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=NormBounded(10 * unc.H, unc.EF, unc.EG))
    with pytest.raises(TypeError, match=r"uncertainty must be a robustctl\.NormBounded"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=(unc.H, unc.EF, unc.EG))
    with pytest.raises(ValueError, match="uncertainty is for n=3 states"):
        rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=NormBounded(np.ones((3, 1)), np.ones((1, 3)),
                                                                       np.ones((1, 2))))
    dplant, *_ = random_case(1, 4, 2, 2, True)
    with pytest.raises(ValueError, match="uncertainty is supported with the standard LMI only"):
        rc.hinf(dplant, Bw=Bw, Cz=Cz, Dzu=Dzu, uncertainty=unc, extended=True)
