"""Mixed H2/H-infinity synthesis (``rc.h2hinf``), state and output feedback.

The mixed optimum has no closed form; the references are

* its limits: a loose H-infinity bound gives the H2 optimum (python-control's
  ``h2syn`` for output feedback, the LQR cost for state feedback), and no
  controller meets a bound below the H-infinity optimum (``hinfsyn``);
* the returned controller's closed loop, assembled and measured by
  python-control (``lft``, ``linfnorm``, ``norm(., 2)``): the H-infinity bound
  is met and the H2 norm is at most the reported bound;
* monotonicity: a looser H-infinity bound never raises the H2 bound.
"""

from __future__ import annotations

import control
import numpy as np
import pytest
from test_output_feedback import generalised, loop, regular_case, scherer_example7

import robustctl as rc
from robustctl.errors import InfeasibleError


def strictly_proper(sys):
    """``sys`` without a feedthrough of rounding size (``Dc Dyw2`` is zero only to rounding when ``Dyw2`` has
    fewer columns than rows; python-control calls any nonzero feedthrough an infinite H2 norm)."""
    assert np.abs(sys.D).max() < 1e-12
    return control.ss(sys.A, sys.B, sys.C, 0)


def check_output(plant, ctrl, hinf_ch, h2_ch):
    Pi, P2 = generalised(plant, **hinf_ch), generalised(plant, **h2_ch)
    hinf_norm = control.linfnorm(loop(Pi, ctrl), tol=1e-10)[0]
    h2_norm = control.norm(strictly_proper(loop(P2, ctrl)), 2)
    assert hinf_norm < ctrl.gamma
    assert h2_norm <= ctrl.h2_bound
    return hinf_norm, h2_norm


@pytest.fixture(scope="module")
def example7():
    plant, hinf_ch, h2_ch = scherer_example7()
    gam = control.hinfsyn(generalised(plant, **hinf_ch), 1, 1)[2]
    P2 = generalised(plant, **h2_ch)
    h2_opt = control.norm(P2.lft(control.h2syn(P2, 1, 1)), 2)
    return plant, hinf_ch, h2_ch, gam, h2_opt


def mixed(plant, hinf_ch, h2_ch, gamma, **kw):
    return rc.h2hinf(plant, gamma=gamma, **hinf_ch, Cz2=h2_ch["Cz"], Dzu2=h2_ch["Dzu"], **kw)


def test_loose_bound_gives_the_h2_optimum(example7):
    plant, hinf_ch, h2_ch, gam, h2_opt = example7
    ctrl = mixed(plant, hinf_ch, h2_ch, 1e3 * gam)
    assert ctrl.K is None and ctrl.order == 3 and ctrl.info["feedback"] == "output"
    assert ctrl.h2_opt == pytest.approx(h2_opt, rel=1e-3)
    check_output(plant, ctrl, hinf_ch, h2_ch)


def test_tight_bound_is_met_and_h2_bound_decreases(example7):
    plant, hinf_ch, h2_ch, gam, h2_opt = example7
    bounds = []
    for factor in (1.05, 1.5, 3.0):
        ctrl = mixed(plant, hinf_ch, h2_ch, factor * gam)
        check_output(plant, ctrl, hinf_ch, h2_ch)
        assert ctrl.h2_opt >= h2_opt * (1 - 1e-6)          # never below the unconstrained optimum
        bounds.append(ctrl.h2_opt)
    assert bounds[0] > bounds[1] > bounds[2]
    # the H2-optimal controller violates the tightest bound: the constraint is active there
    P = generalised(plant, **hinf_ch)
    assert control.linfnorm(P.lft(control.h2syn(generalised(plant, **h2_ch), 1, 1)))[0] > 1.05 * gam


def test_bound_below_the_hinf_optimum_is_infeasible(example7):
    plant, hinf_ch, h2_ch, gam, _ = example7
    with pytest.raises(InfeasibleError, match="gamma"):
        mixed(plant, hinf_ch, h2_ch, 0.95 * gam)


def test_separate_disturbance_of_the_h2_channel():
    plant, ch = regular_case(4, 1)
    gam = control.hinfsyn(generalised(plant, **ch), plant.p, plant.m)[2]
    rng = np.random.default_rng(5)
    h2_ch = dict(Bw=rng.normal(size=(4, 1)), Cz=ch["Cz"], Dzu=ch["Dzu"], Dyw=np.array([[0.4], [0.1]]))
    ctrl = rc.h2hinf(plant, gamma=1.2 * gam, **ch, Cz2=h2_ch["Cz"], Dzu2=h2_ch["Dzu"], Bw2=h2_ch["Bw"],
                     Dyw2=h2_ch["Dyw"])
    check_output(plant, ctrl, ch, h2_ch)


def test_discrete_output_feedback():
    plant, ch = regular_case(3, 0)
    Pd = control.c2d(generalised(plant, **ch), 0.1, "tustin")
    nw, nz = ch["Bw"].shape[1], ch["Cz"].shape[0]
    dplant = rc.Plant(Pd.A, Pd.B[:, nw:], 0.1, C=Pd.C[nz:], D=Pd.D[nz:, nw:])
    dch = dict(Bw=Pd.B[:, :nw], Cz=Pd.C[:nz], Dzu=Pd.D[:nz, nw:], Dyw=Pd.D[nz:, :nw], Dzw=Pd.D[:nz, :nw])
    gam = rc.hinf(dplant, **dch, synthesis="riccati").gamma_opt
    ctrl = rc.h2hinf(dplant, gamma=1.3 * gam, **dch, Cz2=dch["Cz"], Dzu2=dch["Dzu"], Dzw2=dch["Dzw"])
    assert control.linfnorm(loop(Pd, ctrl), tol=1e-10)[0] < ctrl.gamma
    assert control.norm(loop(Pd, ctrl), 2) <= ctrl.h2_bound


def test_state_feedback():
    plant, hinf_ch, h2_ch = scherer_example7()
    splant = rc.Plant(plant.F, plant.G, None)
    Bw = hinf_ch["Bw"]
    lq = rc.h2(splant, Bw=Bw, Cz=h2_ch["Cz"], Dzu=h2_ch["Dzu"])     # the LQR cost (tested against scipy there)
    sf = rc.hinf(splant, Bw=Bw, Cz=hinf_ch["Cz"], Dzu=hinf_ch["Dzu"]).gamma_opt
    for factor in (1.2, 1e3):
        ctrl = rc.h2hinf(splant, gamma=factor * sf, Bw=Bw, Cz=hinf_ch["Cz"], Dzu=hinf_ch["Dzu"], Cz2=h2_ch["Cz"],
                         Dzu2=h2_ch["Dzu"])
        assert ctrl.K is not None and ctrl.info["feedback"] == "state"
        A = plant.F + plant.G @ ctrl.K
        hinf_loop = control.ss(A, Bw, hinf_ch["Cz"] + hinf_ch["Dzu"] @ ctrl.K, 0)
        h2_loop = control.ss(A, Bw, h2_ch["Cz"] + h2_ch["Dzu"] @ ctrl.K, 0)
        assert control.linfnorm(hinf_loop, tol=1e-10)[0] < ctrl.gamma
        assert control.norm(h2_loop, 2) <= ctrl.h2_bound
        assert ctrl.h2_opt >= lq.h2_opt * (1 - 1e-6)
    assert ctrl.h2_opt == pytest.approx(lq.h2_opt, rel=1e-3)
    with pytest.raises(InfeasibleError, match="gamma"):
        rc.h2hinf(splant, gamma=0.95 * sf, Bw=Bw, Cz=hinf_ch["Cz"], Dzu=hinf_ch["Dzu"], Cz2=h2_ch["Cz"],
                  Dzu2=h2_ch["Dzu"])


def test_design_and_bad_input(example7):
    plant, hinf_ch, h2_ch, gam, _ = example7
    ctrl = rc.design("h2hinf", plant, gamma=2 * gam, **hinf_ch, Cz2=h2_ch["Cz"], Dzu2=h2_ch["Dzu"])
    assert isinstance(ctrl, rc.H2HinfController)
    with pytest.raises(ValueError, match="gamma"):
        mixed(plant, hinf_ch, h2_ch, -1.0)
    with pytest.raises(ValueError, match="Cz2"):
        rc.h2hinf(plant, gamma=2 * gam, **hinf_ch, Cz2=np.ones((2, 2)), Dzu2=np.ones((2, 1)))
    with pytest.raises(ValueError, match="Dzw2 must be zero"):
        mixed(plant, hinf_ch, h2_ch, 2 * gam, Dzw2=np.ones((3, 1)))
