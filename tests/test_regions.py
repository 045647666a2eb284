"""LMI pole regions (robustctl.systems.regions) and pole placement in the H-infinity synthesis.

References: the closed-form definitions of each region (|z - c| < r,
Re z < a, |Im z| < tan(angle) (apex - Re z)), the eigenvalues of the closed
loop (numpy), linfnorm of python-control, and the Kronecker form of
Chilali & Gahinet's M_D(A, X) written out with numpy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_hinf import MSD_BW, MSD_CZ, MSD_DZU, RTOL, cl_norm, msd, random_case

import robustctl as rc
from robustctl import ConicSector, Disk, HalfPlane, InfeasibleError, Plant
from robustctl.systems.regions import as_regions, region_lmi

POINTS = np.array([0.0, 0.5, -0.5, 0.95, 1.2, -3.0, 0.3 + 0.4j, 0.3 - 0.4j, -1 + 2j, -2 + 0.5j, -0.1 + 1j, 4j])


def closed_form(region, z):
    z = np.asarray(z, dtype=complex)
    if isinstance(region, Disk):
        return np.abs(z - region.center) < region.radius
    if isinstance(region, HalfPlane):
        return z.real < region.boundary if region.side == "left" else z.real > region.boundary
    return np.abs(z.imag) < math.tan(region.angle) * (region.apex - z.real)


@pytest.mark.parametrize("region", [Disk(0.0, 1.0), Disk(0.3, 0.5), HalfPlane(-1.0), HalfPlane(0.2, "right"),
                                    ConicSector(0.0, math.pi / 4), ConicSector(-0.5, 0.3)], ids=repr)
def test_characteristic_function_is_the_region(region):
    assert np.array_equal(region.contains(POINTS), closed_form(region, POINTS))
    lo, hi = region.real_interval()
    inside = [x for x in np.linspace(-10, 10, 2001) if closed_form(region, x)]
    assert min(inside) == pytest.approx(max(lo, -10), abs=0.011)
    assert max(inside) == pytest.approx(min(hi, 10), abs=0.011)


@pytest.mark.parametrize("region", [Disk(0.2, 0.7), HalfPlane(-0.5), ConicSector(0.1, 0.6)], ids=repr)
def test_region_lmi_is_chilali_gahinets_kronecker_form(region):
    rng = np.random.default_rng(1)
    A, R = rng.normal(size=(3, 3)), rng.normal(size=(3, 3))
    X = R @ R.T + np.eye(3)
    expected = -(np.kron(region.L, X) + np.kron(region.M, A @ X) + np.kron(region.M.T, (A @ X).T))
    assert np.allclose(region_lmi(region, A @ X, X).value, expected)


def test_region_lmi_decides_the_spectrum():
    """With X the Lyapunov solution of the scaled matrix, the disk LMI is positive iff the poles are inside."""
    import scipy.linalg

    rng = np.random.default_rng(2)
    A = rng.normal(size=(4, 4))
    rho = np.max(np.abs(np.linalg.eigvals(A)))
    for radius, inside in ((1.1 * rho, True), (0.9 * rho, False)):
        try:
            X = scipy.linalg.solve_discrete_lyapunov(A / radius, np.eye(4))
        except np.linalg.LinAlgError:
            continue
        lam = np.linalg.eigvalsh(region_lmi(Disk(0.0, radius), A @ X, X).value)
        assert (lam.min() > 0 and np.linalg.eigvalsh(X).min() > 0) == inside


def test_bad_regions_are_named():
    with pytest.raises(ValueError, match="radius must be > 0"):
        Disk(0.0, 0.0)
    with pytest.raises(TypeError, match="center must be a real number"):
        Disk(1j, 1.0)
    with pytest.raises(ValueError, match="side must be 'left' or 'right'"):
        HalfPlane(0.0, "up")
    with pytest.raises(ValueError, match=r"angle must be in \(0, pi/2\)"):
        ConicSector(0.0, math.pi / 2)
    with pytest.raises(ValueError, match="boundary must be finite"):
        HalfPlane(np.inf)
    with pytest.raises(TypeError, match="apex must be a real number"):
        ConicSector(True, 0.3)
    assert as_regions(None) == () and as_regions(Disk()) == (Disk(),)
    with pytest.raises(TypeError, match=r"poles\[1\] must be a Disk"):
        as_regions([Disk(), "left"])
    with pytest.raises(TypeError, match="poles must be a Disk, HalfPlane, ConicSector or a non-empty list"):
        as_regions([])


# ------------------------------------------------------------ in the H-infinity synthesis
@pytest.mark.parametrize("regions", [Disk(0.0, 0.5), Disk(0.3, 0.4), [Disk(0.0, 0.6), HalfPlane(0.0, "right")]],
                         ids=repr)
def test_hinf_discrete_poles_lie_in_the_region(regions):
    plant, Bw, Cz, Dzu, _ = random_case(1, 4, 2, 2, discrete=True)
    free = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu)
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, poles=regions)
    poles = ctrl.closed_loop_poles()
    assert all(np.all(closed_form(r, poles)) for r in as_regions(regions))
    assert ctrl.gamma_opt >= free.gamma_opt * (1 - RTOL)           # the region costs performance
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma * (1 + RTOL)
    assert ctrl.info["poles"] == as_regions(regions)


@pytest.mark.parametrize("regions", [HalfPlane(-2.0), ConicSector(0.0, math.pi / 4),
                                     [HalfPlane(-1.0), ConicSector(-0.5, 0.5), Disk(-5.0, 5.0)]], ids=repr)
def test_hinf_continuous_poles_lie_in_the_region(regions):
    plant, Bw, Cz, Dzu, _ = random_case(3, 4, 2, 2, discrete=False)
    ctrl = rc.hinf(plant, Bw=Bw, Cz=Cz, Dzu=Dzu, poles=regions)
    assert all(np.all(closed_form(r, ctrl.closed_loop_poles())) for r in as_regions(regions))
    assert cl_norm(plant, ctrl.K, Bw, Cz, Dzu) <= ctrl.gamma * (1 + RTOL)


def test_hinf_polytopic_poles_at_every_vertex_and_between():
    region = Disk(0.9, 0.08)
    ctrl = rc.hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(4.0)], poles=region)
    for mass in np.linspace(1.0, 4.0, 7):     # affine in 1/mass: the hull, by quadratic D-stability
        p = msd(mass)
        assert np.all(closed_form(region, np.linalg.eigvals(p.F + p.G @ ctrl.K)))
        assert cl_norm(p, ctrl.K, MSD_BW, MSD_CZ, MSD_DZU) <= ctrl.gamma * (1 + RTOL)


def test_unreachable_regions_say_why():
    plant = Plant(np.diag([0.5, 0.2]), [[0.0], [1.0]], 0.1)    # mode 0.5 is not reached by G
    kw = dict(Bw=np.eye(2), Cz=np.vstack([np.eye(2), [[0, 0]]]), Dzu=[[0.0], [0.0], [1.0]])
    with pytest.raises(InfeasibleError, match=r"mode lambda = 0\.5.*lies outside the pole region Disk.*PBH"):
        rc.hinf(plant, **kw, poles=Disk(0.0, 0.3))
    with pytest.raises(InfeasibleError, match=r"no point in common.*stability region \|z\| < 1"):
        rc.hinf(plant, **kw, poles=Disk(2.0, 0.5))
    with pytest.raises(InfeasibleError, match="no point in common"):
        rc.hinf(plant, **kw, poles=[Disk(0.0, 0.3), HalfPlane(0.5, "right")])
    cont = Plant(np.diag([-0.5, 1.0]), [[0.0], [1.0]], None)
    with pytest.raises(InfeasibleError, match=r"stability region Re z < 0"):
        rc.hinf(cont, **kw, poles=HalfPlane(1.0, "right"))
    # reachable for each plant, but not with one Lyapunov matrix for two very different vertices
    with pytest.raises((InfeasibleError, rc.ConvergenceError), match="pole"):
        rc.hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, vertices=[msd(50.0)], poles=Disk(0.5, 0.01))


def test_poles_need_the_standard_lmi():
    with pytest.raises(ValueError, match="poles is supported with the standard LMI only"):
        rc.hinf(msd(1.0), Bw=MSD_BW, Cz=MSD_CZ, Dzu=MSD_DZU, poles=Disk(0.0, 0.9), extended=True)
