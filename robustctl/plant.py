"""Linear time-invariant plants ``x[k+1] = F x[k] + G u[k]`` (or ``x' = F x + G u``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import as_matrix, check_positive_scalar, check_square

__all__ = ["Plant"]

_METHODS = ("zoh", "tustin", "euler")


def _frozen(arr: np.ndarray) -> np.ndarray:
    arr = np.array(arr, dtype=np.float64)
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False, repr=False)
class Plant:
    """A state-space plant without outputs.

    Discrete time (``dt > 0``): ``x[k+1] = F x[k] + G u[k]``.
    Continuous time (``dt=None``): ``dx/dt = F x + G u`` (``F``, ``G`` are then
    the usual ``A``, ``B``); only the H-infinity synthesis accepts those.

    Parameters
    ----------
    F : (n, n) array_like
    G : (n, m) array_like (a 1-D array is read as one input column)
    dt : float or None
        Sampling time in seconds, or ``None`` for a continuous-time plant.
    """

    F: np.ndarray
    G: np.ndarray
    dt: float | None

    def __init__(self, F, G, dt: float | None):
        F = check_square(as_matrix(F, "F"), "F")
        n = F.shape[0]
        G = as_matrix(G, "G", rows=n, cols=1 if np.ndim(G) == 1 else None,
                      rows_what="the number of states, from F")
        dt = None if dt is None else check_positive_scalar(dt, "dt")
        object.__setattr__(self, "F", _frozen(F))
        object.__setattr__(self, "G", _frozen(G))
        object.__setattr__(self, "dt", dt)

    # -- sizes -------------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of states."""
        return self.F.shape[0]

    @property
    def m(self) -> int:
        """Number of inputs."""
        return self.G.shape[1]

    @property
    def is_discrete(self) -> bool:
        return self.dt is not None

    # -- constructors ------------------------------------------------------
    @classmethod
    def from_continuous(cls, A, B, dt: float | None, method: str = "zoh") -> "Plant":
        """Discretise ``dx/dt = A x + B u`` with sampling time ``dt``.

        ``method`` is ``"zoh"`` (exact for piecewise-constant inputs, via
        python-control's ``c2d``), ``"tustin"`` (bilinear) or ``"euler"``
        (forward Euler, ``F = I + A dt``, ``G = B dt``). ``dt=None`` keeps the
        plant in continuous time.
        """
        A = check_square(as_matrix(A, "A"), "A")
        B = as_matrix(B, "B", rows=A.shape[0], cols=1 if np.ndim(B) == 1 else None,
                      rows_what="the number of states, from A")
        if dt is None:
            return cls(A, B, None)
        dt = check_positive_scalar(dt, "dt")
        if method not in _METHODS:
            raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
        if method == "euler":
            return cls(np.eye(A.shape[0]) + A * dt, B * dt, dt)
        import control

        n, m = B.shape
        sys = control.ss(A, B, np.zeros((1, n)), np.zeros((1, m)))
        sysd = control.c2d(sys, dt, method="zoh" if method == "zoh" else "tustin")
        return cls(sysd.A, sysd.B, dt)

    @classmethod
    def from_statespace(cls, sys) -> "Plant":
        """Build a plant from a python-control ``StateSpace`` (its C and D are ignored)."""
        import control

        if not isinstance(sys, control.StateSpace):
            raise TypeError(f"sys must be a control.StateSpace, got {type(sys).__name__}")
        if sys.dt is True:
            raise ValueError("sys has an unspecified sampling time (dt=True); give a number")
        return cls(sys.A, sys.B, None if not sys.dt else float(sys.dt))

    def to_statespace(self, C=None, D=None):
        """The plant as a python-control ``StateSpace`` (default outputs: the full state)."""
        import control

        C = np.eye(self.n) if C is None else as_matrix(C, "C", cols=self.n, cols_what="the number of states")
        D = np.zeros((C.shape[0], self.m)) if D is None else as_matrix(
            D, "D", rows=C.shape[0], cols=self.m, rows_what="rows of C", cols_what="the number of inputs")
        return control.ss(self.F, self.G, C, D, 0 if self.dt is None else self.dt)

    def __repr__(self) -> str:
        time = "continuous" if self.dt is None else f"dt={self.dt:g}"
        return f"Plant(n={self.n}, m={self.m}, {time})"
