"""The filter recursion's cores on plain arrays, against independent references.

* one step of the closed form against the block (KKT) system of Ishihara, Terra & Cerri (2015), solved
  as one weighted least-squares problem (finite mu, mu = 1e12, mu = inf; with output uncertainty);
* the steady state (doubling + Newton) against scipy's DARE of the filter on the augmented state
  (x, w) (finite mu), against the plain recursion, and the Kalman filter with a cross-covariance
  against scipy's DARE with its cross term;
* the mu -> inf limit, batches against single designs.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from robustctl._kkt import doubling, stein, weighted_lsq
from robustctl.estimation._model import kalman_model, robust_model
from robustctl.estimation._recursion import block_step, step
from robustctl.estimation._steady import steady_state


def spd(rng, k):
    A = rng.normal(size=(k, k))
    return A @ A.T + k * np.eye(k)


def random_model(seed: int, mu, *, output_uncertainty: bool = True, q: int = 2, B: int = 1):
    rng = np.random.default_rng(seed)
    n, m, p, nw = 4, 2, 2, 3
    F = 0.5 * rng.normal(size=(n, n))
    data = dict(F=F, G=rng.normal(size=(n, m)), C=rng.normal(size=(p, n)), D=rng.normal(size=(p, m)),
                Bw=rng.normal(size=(n, nw)), W=spd(rng, nw), V=spd(rng, p))
    unc = dict(H=rng.normal(size=(n, 2)), EF=rng.normal(size=(B, q, n)), EG=rng.normal(size=(B, q, m)),
               EBw=rng.normal(size=(B, q, nw)),
               HC=rng.normal(size=(p, 1)) if output_uncertainty else np.zeros((p, 0)),
               EC=rng.normal(size=(1, n)) if output_uncertainty else np.zeros((0, n)))
    d = robust_model(*data.values(), **unc, mu=np.broadcast_to(np.asarray(mu, float), (B,)).copy(), alpha=0.1)
    return d, data, unc


@pytest.mark.parametrize("mu", [0.37, 3.7, 1e12, np.inf])
@pytest.mark.parametrize("output_uncertainty", [False, True])
def test_closed_form_step_equals_the_block_system(mu, output_uncertainty):
    """x[k|k], P[k|k] and the a-priori x[k|k-1], P[k|k-1] of both forms agree to rounding."""
    d, _, _ = random_model(1, mu, output_uncertainty=output_uncertainty)
    rng = np.random.default_rng(7)
    n, m, p = 4, 2, 2
    Pf_prev = spd(rng, n)
    x_prev, u_prev, u, y = rng.normal(size=n), rng.normal(size=m), rng.normal(size=m), rng.normal(size=p)
    # the closed form from the filtered (x_prev, Pf_prev): the prediction of step k-1, then the update at k
    from robustctl.estimation._recursion import constraint, prediction
    P_pre, Fe, Ge, _ = prediction(Pf_prev[None], np.zeros((1, n, p)), np.eye(p)[None], d)
    P, KE = constraint(P_pre, d)
    M = np.eye(n) - KE[0] @ d.EC[0]
    x_prior = M @ (Fe[0] @ x_prev + Ge[0] @ u_prev)
    g = step(P, d)
    x_filt = x_prior + g.Lf[0] @ (y - d.C @ x_prior - d.D @ u)
    xb, Pb = block_step(x_prev, Pf_prev, u_prev, u, y, d)
    xa, Pa = block_step(x_prev, Pf_prev, u_prev, u, y, d, measure=False)
    scale = np.abs(Pb).max()
    assert np.abs(xb - x_filt).max() < 1e-12 * max(1.0, np.abs(xb).max())
    assert np.abs(Pb - g.Pf[0]).max() < 1e-12 * scale
    assert np.abs(xa - x_prior).max() < 1e-12 * max(1.0, np.abs(xa).max())
    assert np.abs(Pa - P[0]).max() < 1e-12 * np.abs(Pa).max()


def test_weighted_lsq_against_normal_equations():
    """The KKT form equals (A' W A)^-1 A' W b with W = Winv^-1 when Winv is invertible."""
    rng = np.random.default_rng(3)
    A, b, Winv = rng.normal(size=(2, 7, 4)), rng.normal(size=(2, 7, 2)), np.stack([spd(rng, 7) for _ in range(2)])
    z, Pi = weighted_lsq(Winv, A, b)
    W = np.linalg.inv(Winv)
    normal = A.swapaxes(1, 2) @ W @ A
    assert np.allclose(Pi, np.linalg.inv(normal), rtol=1e-12, atol=0)
    assert np.allclose(z, np.linalg.solve(normal, A.swapaxes(1, 2) @ W @ b), rtol=1e-11, atol=1e-13)


def augmented_dare(d, data, unc):
    """The a-priori P (before EC) from scipy's DARE of the Kalman filter on (x, w) (finite mu only)."""
    n, nw = data["Bw"].shape
    p, q, q2 = data["C"].shape[0], d.EF.shape[1], d.EC.shape[1]
    li = float(d.li[0])
    Aa = np.block([[data["F"], data["Bw"]], [np.zeros((nw, n + nw))]])
    Ca = np.vstack([np.hstack([data["C"], np.zeros((p, nw))]), np.hstack([d.EC[0], np.zeros((q2, nw))]),
                    np.hstack([d.EF[0], d.EBw[0]])])
    Qa = scipy.linalg.block_diag(d.Phi1[0], data["W"])
    Ra = scipy.linalg.block_diag(d.R[0], li * np.eye(q2), li * np.eye(q))
    return scipy.linalg.solve_discrete_are(Aa.T, Ca.T, Qa, Ra)[:n, :n]


@pytest.mark.parametrize("mu", [0.37, 3.7, 1e3])
@pytest.mark.parametrize("output_uncertainty", [False, True])
def test_steady_state_against_the_augmented_dare(mu, output_uncertainty):
    d, data, unc = random_model(2, mu, output_uncertainty=output_uncertainty)
    st = steady_state(d)
    assert st.reason[0] == "ok"
    from robustctl.estimation._recursion import constraint
    P_ref = constraint(augmented_dare(d, data, unc)[None], d)[0][0]
    assert np.abs(st.P[0] - P_ref).max() < 1e-9 * np.abs(P_ref).max()
    assert st.residual[0] < 1e-10


@pytest.mark.parametrize("mu", [1e6, 1e12, 1e22, np.inf])
def test_large_mu_steady_state_against_the_plain_recursion(mu):
    """Where doubling alone loses accuracy (Gbar ~ lambda), Newton's refinement restores the fixed point."""
    d, _, _ = random_model(4, mu, output_uncertainty=False, q=1)
    fast = steady_state(d)
    plain = steady_state(d, accelerate=False, tol=1e-14)
    assert fast.reason[0] == "ok" and plain.reason[0] == "ok"
    assert fast.iterations[0] < plain.iterations[0]
    assert np.abs(fast.P[0] - plain.P[0]).max() < 1e-9 * np.abs(plain.P[0]).max()


def test_mu_to_inf_is_the_limit():
    """|P(mu) - P(inf)| shrinks like 1/mu."""
    P_inf = steady_state(random_model(5, np.inf, q=1)[0]).P[0]
    errors = [np.abs(steady_state(random_model(5, mu, q=1)[0]).P[0] - P_inf).max() for mu in (1e2, 1e4, 1e6)]
    assert errors[1] < 2e-2 * errors[0] and errors[2] < 2e-2 * errors[1]
    assert errors[2] < 1e-5 * np.abs(P_inf).max()


def test_batch_equals_single_designs():
    B = 5
    _, data, unc = random_model(6, np.inf, B=B)
    mus = np.array([0.5, 10.0, 1e8, 1e20, np.inf])
    batch = robust_model(*data.values(), **unc, mu=mus, alpha=0.1)
    st = steady_state(batch)
    for i in range(B):
        one = robust_model(*data.values(), **{**unc, "EF": unc["EF"][i:i + 1], "EG": unc["EG"][i:i + 1],
                                              "EBw": unc["EBw"][i:i + 1]}, mu=mus[i:i + 1], alpha=0.1)
        si = steady_state(one)
        assert st.reason[i] == si.reason[0] == "ok"
        assert np.allclose(st.P[i], si.P[0], rtol=1e-10, atol=0)
        assert np.allclose(st.gains.Lf[i], si.gains.Lf[0], rtol=1e-9, atol=1e-12)


def test_kalman_with_cross_covariance_against_scipy():
    rng = np.random.default_rng(8)
    n, m, p, nw = 4, 1, 2, 3
    F, G, C, D, Bw = 0.6 * rng.normal(size=(n, n)), rng.normal(size=(n, m)), rng.normal(size=(p, n)), \
        np.zeros((p, m)), rng.normal(size=(n, nw))
    W, N = spd(rng, nw), 0.3 * rng.normal(size=(nw, p))
    V = spd(rng, p) + N.T @ np.linalg.solve(W, N)
    st = steady_state(kalman_model(F, G, C, D, Bw, W[None], V[None], N[None]))
    P = scipy.linalg.solve_discrete_are(F.T, C.T, Bw @ W @ Bw.T, V, s=Bw @ N)
    Re = C @ P @ C.T + V
    assert np.allclose(st.P[0], P, rtol=1e-10, atol=0)
    g = st.gains
    assert np.allclose(g.Lf[0], P @ C.T @ np.linalg.inv(Re), rtol=1e-10, atol=0)
    assert np.allclose(g.Fe[0] @ g.Lf[0] + g.Je[0], (F @ P @ C.T + Bw @ N) @ np.linalg.inv(Re), rtol=1e-10, atol=0)


def test_doubling_and_stein_against_scipy():
    rng = np.random.default_rng(9)
    A = 0.3 * rng.normal(size=(3, 4, 4))
    C = np.stack([spd(rng, 4) for _ in range(3)])
    X = stein(A, C)
    for i in range(3):
        assert np.allclose(X[i], scipy.linalg.solve_discrete_lyapunov(A[i].T, C[i]), rtol=1e-12, atol=0)
    # X = H + A' X (I + G X)^-1 A is the DARE of (A, B) with G = B R^-1 B', H = Q
    Bm, Q = rng.normal(size=(3, 4, 2)), C
    H, _, settled = doubling(A * 3, Bm @ Bm.swapaxes(1, 2), Q, 1e-14, 64)
    assert settled.all()
    for i in range(3):
        assert np.allclose(H[i], scipy.linalg.solve_discrete_are(3 * A[i], Bm[i], Q[i], np.eye(2)), rtol=1e-10)
