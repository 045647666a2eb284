"""The numerical cores of output-feedback synthesis, each against an independent computation.

* the loop shift: python-control's interconnection of the plant with ``D``
  and the shifted controller equals that of the plant without ``D`` and the
  original controller;
* the two-coordinate frame: its blocks at the transformed variables are the
  congruence, computed here with numpy from the textbook blocks, of the
  blocks at the original variables, and the controller reconstructed in the
  frame has the same transfer function (python-control) as the one
  reconstructed in one set of coordinates;
* the reconstruction itself: the variables of a known controller and
  closed-loop Lyapunov matrix (the change of variables written out here)
  give that controller back;
* the Riccati path's fallbacks.
"""

from __future__ import annotations

import control
import numpy as np
import pytest

import robustctl as rc
from robustctl.synthesis._hinf.generalised import Channel, DynamicGain, Generalised, closed_loop, loop_shift
from robustctl.synthesis._hinf.output_coordinates import Frame
from robustctl.synthesis._hinf.output_lmis import OFPoint, controller, h2_blocks, hinf_block


def random_plant(rng, n=3, m=2, p=2, nw=3, nz=3, discrete=False):
    A = rng.normal(size=(n, n))
    ch = Channel(rng.normal(size=(n, nw)), rng.normal(size=(nz, n)), rng.normal(size=(nz, nw)),
                 rng.normal(size=(nz, m)), rng.normal(size=(p, nw)))
    return Generalised(A, rng.normal(size=(n, m)), rng.normal(size=(p, n)), (ch,), discrete)


def as_ss(A, B, C, D, discrete):
    return control.ss(A, B, C, D, True if discrete else 0)


def same_transfer(a, b, w=(0.1, 0.7, 2.0, 9.0), discrete=False):
    pts = [np.exp(1j * x) if discrete else 1j * x for x in w]
    return all(np.allclose(a(s), b(s), rtol=1e-7, atol=1e-9) for s in pts)


def test_loop_shift_matches_python_control():
    rng = np.random.default_rng(0)
    g = random_plant(rng)
    c = g.channels[0]
    D22 = 0.3 * rng.normal(size=(g.p, g.m))
    K = DynamicGain(rng.normal(size=(2, 2)), rng.normal(size=(2, g.p)), rng.normal(size=(g.m, 2)),
                    0.2 * rng.normal(size=(g.m, g.p)))
    B, C = np.hstack([c.B1, g.B2]), np.vstack([c.C1, g.C2])
    with_d = control.ss(g.A, B, C, np.block([[c.D11, c.D12], [c.D21, D22]]))
    without = control.ss(g.A, B, C, np.block([[c.D11, c.D12], [c.D21, np.zeros_like(D22)]]))
    shifted = with_d.lft(control.ss(*loop_shift(K, D22)))
    assert same_transfer(shifted, without.lft(control.ss(*K)))


def textbook_blocks(g: Generalised, V: OFPoint, level_sq: float):
    """The H-infinity and H2 blocks in one set of coordinates, written out with numpy."""
    c = g.channels[0]
    A, B2, C2 = g.A, g.B2, g.C2
    n = g.n
    AA = np.block([[A @ V.X + B2 @ V.Ch, A + B2 @ V.Dh @ C2], [V.Ah, V.Y @ A + V.Bh @ C2]])
    BB = np.vstack([c.B1 + B2 @ V.Dh @ c.D21, V.Y @ c.B1 + V.Bh @ c.D21])
    CC = np.hstack([c.C1 @ V.X + c.D12 @ V.Ch, c.C1 + c.D12 @ V.Dh @ C2])
    DD = c.D11 + c.D12 @ V.Dh @ c.D21
    P = np.block([[V.X, np.eye(n)], [np.eye(n), V.Y]])
    nw, nz = BB.shape[1], CC.shape[0]
    Z = np.eye(nz)
    if g.discrete:
        hinf = np.block([[P, AA, BB, np.zeros((2 * n, nz))], [AA.T, P, np.zeros((2 * n, nw)), CC.T],
                         [BB.T, np.zeros((nw, 2 * n)), np.eye(nw), DD.T],
                         [np.zeros((nz, 2 * n)), CC, DD, level_sq * np.eye(nz)]])
        cost = np.block([[Z, CC, DD], [CC.T, P, np.zeros((2 * n, nw))], [DD.T, np.zeros((nw, 2 * n)), np.eye(nw)]])
        return hinf, cost, [(0, 2 * n), (2 * n, 4 * n)], [(nz, nz + 2 * n)]
    hinf = np.block([[-(AA + AA.T), -BB, -CC.T], [-BB.T, np.eye(nw), -DD.T], [-CC, -DD, level_sq * np.eye(nz)]])
    cost = np.block([[P, CC.T], [CC, Z]])
    return hinf, cost, [(0, 2 * n)], [(0, 2 * n)]


def congruence(M: np.ndarray, L: np.ndarray, where) -> np.ndarray:
    """``T M T'`` with ``T`` the identity except ``L`` on the diagonal ranges ``where``."""
    T = np.eye(M.shape[0])
    for a, b in where:
        T[a:b, a:b] = L
    return T @ M @ T.T


@pytest.mark.parametrize("discrete", [False, True])
def test_frame_blocks_are_the_congruence_of_the_textbook_blocks(discrete):
    rng = np.random.default_rng(1)
    g = random_plant(rng, discrete=discrete)
    n, m, p = g.n, g.m, g.p
    sym = lambda M: M @ M.T + np.eye(n)  # noqa: E731
    V = OFPoint(sym(rng.normal(size=(n, n))), sym(rng.normal(size=(n, n))), rng.normal(size=(n, n)),
                rng.normal(size=(n, p)), rng.normal(size=(m, n)), rng.normal(size=(m, p)))
    S, T = rng.normal(size=(n, n)) + 3 * np.eye(n), rng.normal(size=(n, n)) + 3 * np.eye(n)
    Si = np.linalg.inv(S)
    Vf = OFPoint(Si @ V.X @ Si.T, T.T @ V.Y @ T, T.T @ V.Ah @ Si.T, T.T @ V.Bh, V.Ch @ Si.T, V.Dh)
    f = Frame(g, S, T)
    L = np.block([[Si, np.zeros((n, n))], [np.zeros((n, n)), T.T]])
    hinf, cost, where_h, where_c = textbook_blocks(g, V, 2.5)
    assert np.allclose(hinf_block(f, Vf, 2.5).M, congruence(hinf, L, where_h), atol=1e-9)
    assert np.allclose(h2_blocks(f, Vf, np.eye(g.channels[0].nz))[1].M, congruence(cost, L, where_c), atol=1e-9)
    # the controller reconstructed in the frame is the one of the textbook coordinates
    K_frame, K_plain = controller(f, Vf), controller(Frame(g, np.eye(n), np.eye(n)), V)
    assert same_transfer(as_ss(*K_frame, discrete), as_ss(*K_plain, discrete), discrete=discrete)


def test_reconstruction_returns_the_controller():
    """Variables of a known controller (the change of variables written out) give that controller back."""
    rng = np.random.default_rng(2)
    g = random_plant(rng)
    n = g.n
    K = DynamicGain(rng.normal(size=(n, n)), rng.normal(size=(n, g.p)), rng.normal(size=(g.m, n)),
                    rng.normal(size=(g.m, g.p)))
    Q = rng.normal(size=(2 * n, 2 * n))
    Pcl = Q @ Q.T + 2 * np.eye(2 * n)               # any closed-loop Lyapunov matrix (the algebra needs no LMI)
    Xcl = np.linalg.inv(Pcl)
    X, M, Y, N = Pcl[:n, :n], Pcl[:n, n:], Xcl[:n, :n], Xcl[:n, n:]
    Ak, Bk, Ck, Dk = K
    A, B2, C2 = g.A, g.B2, g.C2
    V = OFPoint(X, Y, Y @ (A + B2 @ Dk @ C2) @ X + Y @ B2 @ Ck @ M.T + N @ Bk @ C2 @ X + N @ Ak @ M.T,
                Y @ B2 @ Dk + N @ Bk, Dk @ C2 @ X + Ck @ M.T, Dk)
    back = controller(Frame(g, np.eye(n), np.eye(n)), V)
    assert same_transfer(control.ss(*back), control.ss(*K))
    # and the closed loops agree (same poles)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(closed_loop(g, back)[0])),
                       np.sort_complex(np.linalg.eigvals(closed_loop(g, K)[0])), atol=1e-7)


def test_riccati_path_falls_back_at_z_minus_one():
    """A discrete mode at z = -1 has no Tustin image: the LMIs decide."""
    plant = rc.Plant(np.diag([-1.0, 0.5]), [[1.0], [1.0]], 0.1, C=[[1.0, 1.0]])
    ch = dict(Bw=np.hstack([np.eye(2), np.zeros((2, 1))]), Cz=np.vstack([np.eye(2), np.zeros((1, 2))]),
              Dzu=np.array([[0.0], [0.0], [1.0]]), Dyw=np.array([[0.0, 0.0, 1.0]]))
    ctrl = rc.hinf(plant, **ch, synthesis="riccati")
    assert ctrl.info["synthesis"] == "lmi" and "z = -1" in ctrl.info["fallback"]
    ref = rc.hinf(plant, **ch)
    assert ctrl.gamma_opt == pytest.approx(ref.gamma_opt, rel=1e-9)
    C, D = plant.output_matrices()
    P = control.ss(plant.F, np.hstack([ch["Bw"], plant.G]), np.vstack([ch["Cz"], C]),
                   np.block([[np.zeros((3, 3)), ch["Dzu"]], [ch["Dyw"], D]]), 0.1)
    assert control.linfnorm(P.lft(ctrl.controller_statespace()), tol=1e-10)[0] < ctrl.gamma
