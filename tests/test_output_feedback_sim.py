"""robustctl.sim.output_feedback: u = K(z) (y - r) runs against python-control's forced_response and a plain loop."""

from __future__ import annotations

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.sim import simulate_output_feedback


def _random_loop(rng, n=3, m=2, p=2, nc=2, B=4, feedthrough=False):
    """A random plant and B random controllers whose loops are stable for F scaled by 0.9 .. 1.1."""
    F = rng.standard_normal((n, n))
    F *= 0.8 / np.abs(np.linalg.eigvals(F)).max()
    plant = rc.Plant(F, rng.standard_normal((n, m)), 0.1, C=rng.standard_normal((p, n)),
                     D=0.3 * rng.standard_normal((p, m)) if feedthrough else None)
    mats = []
    while len(mats) < B:
        Ac = rng.standard_normal((nc, nc))
        if nc:
            Ac *= 0.7 / np.abs(np.linalg.eigvals(Ac)).max()
        ctrl = rc.Controller.dynamic(Ac, 0.3 * rng.standard_normal((nc, p)), 0.3 * rng.standard_normal((m, nc)),
                                     0.2 * rng.standard_normal((m, p)), "random", plant)
        scaled = [rc.Plant(F * s, plant.G, 0.1, C=plant.C, D=plant.D) for s in (0.9, 1.0, 1.1)]
        if all(ctrl.is_stabilizing(q) for q in scaled):
            mats.append((ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc))
    return plant, rc.ControllerBatch(plant, *(np.stack(M) for M in zip(*mats, strict=True)))


def _python_control(plant, ctrl, r, x0):
    """y, u of u = K(z) (y - r) by control.interconnect and forced_response (states: plant, then controller).

    With feedthroughs in both (an algebraic loop interconnect refuses), from x0 = 0: u by control.feedback
    (u = K (-r + P u)), then y = P u.
    """
    p, m, nc = plant.p, plant.m, ctrl.Ac.shape[0]
    dt = plant.dt
    T = r.shape[0]
    if np.any(plant.D) and np.any(ctrl.Dc):
        assert not np.any(x0)
        P, K = plant.to_statespace(), ctrl.controller_statespace()
        u = control.forced_response(control.feedback(K, P, sign=+1), T=np.arange(T) * dt, U=-r.T).outputs
        y = control.forced_response(P, T=np.arange(T) * dt, U=u).outputs
        return np.atleast_2d(y).T, np.atleast_2d(u).T
    P = control.ss(plant.F, plant.G, plant.C, plant.D, dt, inputs=[f"u[{i}]" for i in range(m)],
                   outputs=[f"y[{i}]" for i in range(p)], name="P")
    K = control.ss(ctrl.Ac, ctrl.Bc, ctrl.Cc, ctrl.Dc, dt, inputs=[f"e[{i}]" for i in range(p)],
                   outputs=[f"u[{i}]" for i in range(m)], name="K")
    err = control.summing_junction(inputs=["y", "-r"], output="e", dimension=p, name="sum")
    loop = control.interconnect([P, K, err], inplist=[f"r[{i}]" for i in range(p)],
                                outlist=[*(f"y[{i}]" for i in range(p)), *(f"u[{i}]" for i in range(m))])
    resp = control.forced_response(loop, T=np.arange(T) * dt, U=r.T, X0=np.r_[x0, np.zeros(nc)])
    return resp.outputs[:p].T, resp.outputs[p:].T


@pytest.mark.parametrize("feedthrough", [False, True])
def test_runs_equal_python_control_forced_response(feedthrough):
    rng = np.random.default_rng(7 + feedthrough)
    plant, batch = _random_loop(rng, feedthrough=feedthrough)
    others = [rc.Plant(plant.F * s, plant.G, 0.1) for s in (0.9, 1.1)]        # no outputs: the batch's C, D
    T = 60
    r = np.cumsum(0.1 * rng.standard_normal((T, plant.p)), axis=0)
    x0 = np.zeros(plant.n) if feedthrough else rng.standard_normal(plant.n)
    res = simulate_output_feedback(batch, [plant, *others], T, x0=x0, reference=r)
    assert res.outputs.shape == (4, 3, T, 2) and not res.diverged.any()
    for s, scenario in enumerate([plant, *others]):
        sp = rc.Plant(scenario.F, scenario.G, 0.1, C=plant.C, D=plant.D)
        for b in range(len(batch)):
            y, u = _python_control(sp, batch[b], r, x0)
            np.testing.assert_allclose(res.outputs[b, s], y, rtol=0, atol=1e-8 * max(1.0, np.abs(y).max()))
            np.testing.assert_allclose(res.inputs[b, s], u, rtol=0, atol=1e-8 * max(1.0, np.abs(u).max()))
    np.testing.assert_allclose(res.errors, res.outputs - r)


def test_static_output_feedback_and_saturation_against_a_plain_loop():
    rng = np.random.default_rng(3)
    plant, batch = _random_loop(rng, nc=0)
    T, lim = 40, 0.3
    r = np.ones((T, plant.p))
    x0 = rng.standard_normal(plant.n)
    res = simulate_output_feedback(batch, [plant], T, x0=x0, reference=r, u_limit=lim)
    for b in range(len(batch)):
        x = x0.copy()
        for k in range(T):
            u = np.clip(batch.Dc[b] @ (plant.C @ x - r[k]), -lim, lim)
            np.testing.assert_allclose(res.inputs[b, 0, k], u, atol=1e-12)
            np.testing.assert_allclose(res.outputs[b, 0, k], plant.C @ x, atol=1e-12)
            x = plant.F @ x + plant.G @ u
    assert res.saturated_steps.max() > 0


def test_saturation_keeps_the_controller_on_the_measured_output():
    rng = np.random.default_rng(4)
    plant, batch = _random_loop(rng, nc=2, B=2)
    T, lim = 30, np.array([0.2, np.inf])                      # the second input unlimited
    res = simulate_output_feedback(batch, [plant], T, reference=np.ones((T, 2)), u_limit=lim)
    for b in range(2):
        x, xc = np.zeros(plant.n), np.zeros(2)
        for k in range(T):
            e = plant.C @ x - 1.0
            u = np.clip(batch.Cc[b] @ xc + batch.Dc[b] @ e, -lim, lim)
            np.testing.assert_allclose(res.inputs[b, 0, k], u, atol=1e-12)
            np.testing.assert_allclose(res.controller_states[b, 0, k], xc, atol=1e-12)
            x, xc = plant.F @ x + plant.G @ u, batch.Ac[b] @ xc + batch.Bc[b] @ e
    np.testing.assert_array_equal(np.abs(res.inputs[..., 0]).max() <= 0.2, True)


def test_backends_agree_and_bad_input_is_named():
    rng = np.random.default_rng(5)
    plant, batch = _random_loop(rng, feedthrough=True)
    a = simulate_output_feedback(batch, [plant], 20, x0=np.ones(3))
    b = simulate_output_feedback(batch, [plant], 20, x0=np.ones(3), backend="numpy")
    np.testing.assert_allclose(a.outputs, b.outputs, rtol=1e-12, atol=1e-14)
    with pytest.raises(ValueError, match="u_limit: saturation with a plant feedthrough D != 0"):
        simulate_output_feedback(batch, [plant], 20, u_limit=1.0)
    with pytest.raises(ValueError, match=r"reference must have p=2 columns"):
        simulate_output_feedback(batch, [plant], 20, reference=np.ones((20, 3)))
    with pytest.raises(ValueError, match=r"x0 must be a finite \(3,\)"):
        simulate_output_feedback(batch, [plant], 20, x0=np.ones(2))
    with pytest.raises(TypeError, match=r"batch must be a robustctl\.ControllerBatch"):
        simulate_output_feedback(np.zeros((1, 2, 2)), [plant], 20)
    with pytest.raises(ValueError, match="must be discrete-time"):
        simulate_output_feedback(batch, [rc.Plant(plant.F, plant.G, None, C=plant.C, D=plant.D)], 20)
