"""The argument checks shared by the Kalman filter and the robust filter."""

from __future__ import annotations

import numpy as np

from .._validation import as_batch, as_float_array, as_matrix, check_choice, check_spd
from ..errors import ConvergenceError
from ..systems.plant import Plant, check_plant
from ..systems.stability import UNSTABLE_TOL, immovable_modes
from .estimator import FORMS


def outputs(plant, what: str) -> Plant:
    """``plant`` if it is a :class:`Plant` with measured outputs; else a ``TypeError``/``ValueError`` naming ``C``."""
    check_plant(plant)
    if not plant.has_outputs:
        raise ValueError(f"{what} estimates the state from measured outputs y = C x + D u, but plant has no output "
                         "matrix C (plant.has_outputs is False: the full state is measured, no filter is needed); "
                         "give Plant(F, G, dt, C=...)")
    return plant


def noise_input(plant: Plant, Bw) -> np.ndarray:
    """``Bw`` checked (n rows), else ``plant.Bw``, else the identity (the noise enters every state)."""
    if Bw is not None:
        return as_matrix(Bw, "Bw", rows=plant.n, vector="column", rows_what="the number of states")
    return np.eye(plant.n) if plant.Bw is None else np.array(plant.Bw)


def covariance(value, name: str, size: int, what: str, *, definite: bool) -> np.ndarray:
    """One covariance ``(size, size)``, symmetric positive (semi)definite, symmetrised."""
    arr = as_matrix(value, name, rows=size, cols=size, rows_what=what, cols_what=what)
    return check_spd(arr, name, semidefinite=not definite)


def covariance_stack(value, name: str, size: int, what: str, *, definite: bool) -> np.ndarray:
    """A covariance or a stack ``(B, size, size)`` of them, each checked (the message names ``name[i]``)."""
    arr = as_float_array(value, name)
    if arr.ndim < 3:
        return covariance(arr, name, size, what, definite=definite)[None]
    arr = as_batch(arr, name, (None, size, size), ("", what, what))
    for i in range(arr.shape[0]):  # the checks of one matrix each (a ValueError naming the design)
        arr[i] = check_spd(arr[i], f"{name}[{i}]", semidefinite=not definite)
    return arr


def cross_covariance(N, W: np.ndarray, V: np.ndarray) -> np.ndarray | None:
    """``N = cov(w, v)`` (B, nw, p) or None; ``[[W, N], [N', V]]`` must be positive semidefinite."""
    if N is None:
        return None
    B = max(W.shape[0], V.shape[0])
    nw, p = W.shape[1], V.shape[1]
    arr = as_float_array(N, "N")
    arr = as_matrix(arr, "N", rows=nw, cols=p, rows_what="columns of Bw", cols_what="the number of outputs")[None] \
        if arr.ndim < 3 else as_batch(arr, "N", (None, nw, p), ("", "columns of Bw", "the number of outputs"))
    if arr.shape[0] not in (1, B):
        raise ValueError(f"N must have {B} designs like W and V, got shape {arr.shape}")
    arr = np.broadcast_to(arr, (B, nw, p))
    # Schur complement: W - N V^-1 N' >= 0 (V is positive definite)
    schur = W - arr @ np.linalg.solve(V, arr.swapaxes(1, 2))
    scale = np.maximum(1.0, np.abs(W).max(axis=(1, 2)))
    low = np.linalg.eigvalsh(0.5 * (schur + schur.swapaxes(1, 2))).min(axis=1)
    bad = np.flatnonzero(low < -1e-12 * scale)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"N (the cross-covariance of w and v) is too large: [[W, N], [N', V]] must be positive "
                         f"semidefinite, but W - N V^-1 N' has the eigenvalue {low[i]:.3g}"
                         + (f" (design {i})" if B > 1 else ""))
    return np.array(arr)


def check_form(form, plant: Plant) -> str:
    """``"filter"`` or ``"predictor"``; a continuous-time plant has one form (``"filter"``)."""
    form = check_choice(form, "form", FORMS)
    if form == "predictor" and not plant.is_discrete:
        raise ValueError("form='predictor' needs a discrete-time plant: the continuous-time (Kalman-Bucy) filter "
                         "has one form, form='filter'")
    return form


def design_stack(value, name: str, shape: tuple[int | None, int], what: tuple[str, str],
                 batch: bool) -> np.ndarray:
    """One matrix ``shape`` or, for a batch, also a stack ``(B, *shape)``, as a stack."""
    if not batch:
        return as_matrix(value, name, rows=shape[0], cols=shape[1], rows_what=what[0], cols_what=what[1],
                         allow_empty=True)[None]
    arr = as_float_array(value, name)
    if arr.ndim < 3:
        arr = as_matrix(arr, name, rows=shape[0], cols=shape[1], rows_what=what[0], cols_what=what[1],
                        allow_empty=True)[None]
    return as_batch(arr, name, (None, *shape), ("", *what))


def check_noise_reaches_boundary(F: np.ndarray, Bw: np.ndarray, W: np.ndarray, *, discrete: bool) -> None:
    """``ConvergenceError`` if a mode of ``F`` on the stability boundary is not reached by the noise ``Bw W^1/2``.

    The filter Riccati equation (without cross term; with one, ``F - S V^-1 C``
    and ``W - N V^-1 N'``) has a stabilising solution iff ``(C, F)`` is
    detectable and ``(F, Bw W^1/2)`` has no unreachable mode on the unit circle
    (the imaginary axis) (Lancaster & Rodman, *Algebraic Riccati Equations*,
    1995, Thm 13.1.3, dual form): such a mode (an integrator without noise) is
    estimated ever better but never at a fixed rate. PBH test at the modes
    within ``max(1e-6, 1e3 UNSTABLE_TOL ||F||)`` of the boundary.
    """
    w, Q = np.linalg.eigh(0.5 * (W + W.T))
    root = Bw @ (Q * np.sqrt(np.clip(w, 0.0, None)))
    edge = max(1e-6, 1e3 * UNSTABLE_TOL * max(1.0, float(np.linalg.norm(F, 2))))
    if discrete:
        modes = immovable_modes(F, root, lambda lam: np.abs(np.abs(lam) - 1.0) <= edge)
    else:
        modes = immovable_modes(F, root, lambda lam: np.abs(lam.real) <= edge)
    if modes.size:
        where = "unit circle" if discrete else "imaginary axis"
        raise ConvergenceError(
            f"no stabilising steady-state filter: the mode lambda = {complex(modes[0]):.6g} of F on the {where} is not "
            f"reached by the process noise Bw W Bw' (PBH test), so its estimate converges ever more slowly and no "
            "fixed gain is optimal and stable; add process noise on that mode")
