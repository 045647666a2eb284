"""Linear time-invariant plants ``x[k+1] = F x[k] + G u[k] + Bw w[k]``, ``y = C x + D u`` (or continuous)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._validation import as_matrix, check_choice, check_positive_scalar, check_square, frozen, frozen_complex
from .stability import undetectable_modes, unstabilizable_modes

__all__ = ["Plant", "check_plant", "check_plants", "check_vertices"]

_METHODS = ("zoh", "tustin", "euler")


def _singular(M: np.ndarray, scale: float) -> bool:
    """Whether ``M`` is singular up to the rounding of forming it from terms of norm ``scale``.

    Smallest singular value at most ``n eps scale`` (or ``M`` not finite).
    """
    if not np.all(np.isfinite(M)):
        return True
    return bool(np.linalg.svd(M, compute_uv=False)[-1] <= M.shape[0] * np.finfo(float).eps * scale)


@dataclass(frozen=True, eq=False, repr=False)
class Plant:
    r"""A linear time-invariant plant, with measured outputs and a disturbance input when given.

    Discrete time (``dt > 0``) and continuous time (``dt=None``):

    .. math::

        x[k+1] = F x[k] + G u[k] + B_w w[k], \qquad \dot x = F x + G u + B_w w,

        y = C x + D u .

    ``C=None`` means no output model: the whole state is measured (``y = x``,
    :attr:`has_outputs` False), the setting of every state-feedback design.
    ``Bw`` is the input of the disturbance (process noise for the
    estimators, ``w`` for the H-infinity and H2 syntheses), used when those
    are not given one.

    Parameters
    ----------
    F : (n, n) array_like
        State matrix (``A`` in continuous time).
    G : (n, m) array_like
        Input matrix (``B`` in continuous time); a 1-D array is one input column.
    dt : float or None
        Sampling time in seconds, or ``None`` for a continuous-time plant.
    C : (p, n) array_like, optional
        Output matrix of the measured outputs; a 1-D array is one output row.
    D : (p, m) array_like, optional
        Feedthrough from the input to the outputs (zeros by default); needs ``C``.
    Bw : (n, nw) array_like, optional
        Disturbance input matrix; a 1-D array is one disturbance column.

    Attributes
    ----------
    F, G, C, D, Bw : ndarray or None
        The matrices, read-only (``C``, ``D``, ``Bw`` are None when not given).
    dt : float or None
        The sampling time.

    Raises
    ------
    ValueError
        A matrix of the wrong shape or with non-finite entries (the message
        names it and both shapes), ``D`` without ``C``, ``dt <= 0``.
    TypeError
        A non-numeric entry.

    See Also
    --------
    Plant.from_continuous : discretise a continuous model (``Bw`` too).
    robustctl.Controller : the design result, for state and output feedback.

    Examples
    --------
    A double integrator with its position measured:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1, C=[[1.0, 0.0]])
    >>> plant
    Plant(n=2, m=1, p=1, dt=0.1)
    >>> plant.has_outputs, plant.D
    (True, array([[0.]]))
    >>> rc.Plant([[0.5]], [[1.0]], dt=0.1).p      # no output model: y = x
    1
    """

    F: np.ndarray
    G: np.ndarray
    dt: float | None
    C: np.ndarray | None = None
    D: np.ndarray | None = None
    Bw: np.ndarray | None = None

    def __init__(self, F, G, dt: float | None, C=None, D=None, Bw=None):
        F = check_square(as_matrix(F, "F"), "F")
        n = F.shape[0]
        G = as_matrix(G, "G", rows=n, vector="column", rows_what="the number of states, from F")
        dt = None if dt is None else check_positive_scalar(dt, "dt")
        if C is not None:
            C = as_matrix(C, "C", cols=n, vector="row", cols_what="the number of states, from F")
            D = np.zeros((C.shape[0], G.shape[1])) if D is None else as_matrix(
                D, "D", rows=C.shape[0], cols=G.shape[1], rows_what="the number of outputs, rows of C",
                cols_what="the number of inputs, columns of G")
        elif D is not None:
            raise ValueError("D needs C: give the output matrix C (y = C x + D u) or leave D out")
        if Bw is not None:
            Bw = as_matrix(Bw, "Bw", rows=n, vector="column", rows_what="the number of states, from F")
        for name, value in (("F", F), ("G", G), ("dt", dt), ("C", C), ("D", D), ("Bw", Bw)):
            object.__setattr__(self, name, value if value is None or name == "dt" else frozen(value))

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
    def p(self) -> int:
        """Number of measured outputs (``n`` without an output model: the state is measured)."""
        return self.n if self.C is None else self.C.shape[0]

    @property
    def has_outputs(self) -> bool:
        """Whether the plant has an output model ``y = C x + D u`` (False: the whole state is measured)."""
        return self.C is not None

    @property
    def is_discrete(self) -> bool:
        """Whether the plant is discrete-time (``dt`` given)."""
        return self.dt is not None

    def output_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """``(C, D)`` of the measurement: the plant's own, or ``(I, 0)`` without an output model."""
        if self.C is None:
            return np.eye(self.n), np.zeros((self.n, self.m))
        assert self.D is not None
        return self.C, self.D

    @cached_property
    def unstabilizable_modes(self) -> np.ndarray:
        """Eigenvalues of ``F`` that are not stable and that ``G`` cannot move (PBH test).

        Empty for a stabilisable plant; see :mod:`robustctl.systems.stability` for the tolerances.
        """
        return frozen_complex(unstabilizable_modes(self.F, self.G, discrete=self.is_discrete))

    @property
    def is_stabilizable(self) -> bool:
        """Some gain ``u = K x`` makes the loop stable (no ``unstabilizable_modes``)."""
        return self.unstabilizable_modes.size == 0

    @cached_property
    def undetectable_modes(self) -> np.ndarray:
        """Eigenvalues of ``F`` that are not stable and that the outputs ``C`` do not see (PBH test).

        Empty for a detectable plant and for one without an output model (the state is measured).
        """
        C, _ = self.output_matrices()
        return frozen_complex(undetectable_modes(self.F, C, discrete=self.is_discrete))

    @property
    def is_detectable(self) -> bool:
        """Some observer makes the estimation error converge (no ``undetectable_modes``)."""
        return self.undetectable_modes.size == 0

    # -- constructors ------------------------------------------------------
    @classmethod
    def from_continuous(cls, A, B, dt: float | None, method: str = "zoh", *, C=None, D=None, Bw=None) -> Plant:
        r"""Discretise ``dx/dt = A x + B u + Bw w``, ``y = C x + D u`` with sampling time ``dt``.

        Parameters
        ----------
        A : (n, n) array_like
        B : (n, m) array_like
        dt : float or None
            Sampling time; ``None`` keeps the plant in continuous time.
        method : {"zoh", "tustin", "euler"}
            ``"zoh"``: exact for inputs held over each sample (python-control's
            ``c2d``), ``Bw`` too (the disturbance held as well); ``"tustin"``:
            the bilinear transform (it preserves the H-infinity norm), which
            needs ``I - A dt/2`` invertible and changes ``C`` and ``D`` as
            well; ``"euler"``: ``F = I + A dt``, ``G = B dt``, ``Bw dt``.
        C, D, Bw : array_like, optional
            The outputs and the disturbance input (see :class:`Plant`).

        Returns
        -------
        Plant

        Raises
        ------
        ValueError
            ``A dt`` too large for the discrete plant to be finite (naming
            ``A``); ``method="tustin"`` with an eigenvalue of ``A`` at
            ``2/dt`` (smallest singular value of ``I - A dt/2`` at most
            ``n eps (1 + ||A|| dt/2)``), or with both ``C`` and ``Bw`` (the
            Tustin image has a feedthrough from ``w`` to ``y``, which a
            :class:`Plant` does not hold).

        Notes
        -----
        With a zero-order hold,

        .. math::

            F = e^{A\,dt}, \qquad [G \;\; B_{w,d}] = \int_0^{dt} e^{A s}\,ds\, [B \;\; B_w],

        so a disturbance held constant over each sample enters through
        ``B_{w,d}``. A white continuous noise of intensity ``W`` is not held:
        its discrete covariance is :func:`robustctl.noise_covariance`.

        Examples
        --------
        >>> import numpy as np
        >>> import robustctl as rc
        >>> plant = rc.Plant.from_continuous([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]], dt=0.1,
        ...                                  C=[[1.0, 0.0]], Bw=[[0.0], [1.0]])
        >>> bool(np.allclose(plant.G, plant.Bw)), plant.G.ravel().round(3).tolist()
        (True, [0.005, 0.1])
        """
        A = check_square(as_matrix(A, "A"), "A")
        n = A.shape[0]
        B = as_matrix(B, "B", rows=n, vector="column", rows_what="the number of states, from A")
        if dt is None:
            return cls(A, B, None, C=C, D=D, Bw=Bw)
        checked = cls(A, B, None, C=C, D=D, Bw=Bw)             # shapes and finiteness, named
        dt = check_positive_scalar(dt, "dt")
        method = check_choice(method, "method", _METHODS)
        m = B.shape[1]
        inputs = B if checked.Bw is None else np.hstack([B, checked.Bw])
        Cc, Dc = checked.output_matrices()
        Cd, Dd = checked.C, checked.D
        with np.errstate(all="ignore"):
            if method == "euler":
                F, Gall = np.eye(n) + A * dt, inputs * dt
            else:
                half = A * (dt / 2)
                if method == "tustin":
                    if _singular(np.eye(n) - half, 1.0 + float(np.linalg.norm(half, 2))):
                        raise ValueError(f"method='tustin' needs I - A dt/2 invertible, but A has an eigenvalue at "
                                         f"2/dt = {2 / dt:g} (dt={dt:g}); use method='zoh' or another dt")
                    if checked.has_outputs and checked.Bw is not None:
                        raise ValueError("method='tustin' with both C and Bw gives a feedthrough from w to y, "
                                         "which a Plant does not hold; use method='zoh', or discretise the "
                                         "generalised plant with control.c2d and pass its matrices to the design")
                import control

                sysd = control.c2d(control.ss(A, inputs, Cc, np.hstack([Dc, np.zeros((Cc.shape[0],
                                                                                  inputs.shape[1] - m))])),
                                   dt, method=method)
                F, Gall = sysd.A, sysd.B
                if method == "tustin" and checked.has_outputs:
                    Cd, Dd = sysd.C, sysd.D[:, :m]
        if not (np.all(np.isfinite(F)) and np.all(np.isfinite(Gall))):
            raise ValueError(f"A is too large for dt={dt:g}: the discretised plant ({method}) has non-finite "
                             "entries; check the units of A and B or use a smaller dt")
        return cls(F, Gall[:, :m], dt, C=Cd, D=Dd, Bw=None if checked.Bw is None else Gall[:, m:])

    @classmethod
    def from_statespace(cls, sys) -> Plant:
        """A plant from a python-control ``StateSpace``, with its ``C`` and ``D``.

        Parameters
        ----------
        sys : control.StateSpace
            ``C = I`` with ``D = 0`` is read as "the state is measured" (``C=None``).

        Returns
        -------
        Plant

        Raises
        ------
        TypeError
            ``sys`` is not a ``control.StateSpace``.
        ValueError
            ``sys.dt`` is ``True`` (unspecified sampling time).

        Examples
        --------
        >>> import control
        >>> import robustctl as rc
        >>> plant = rc.Plant.from_statespace(control.ss([[-1.0]], [[1.0]], [[2.0]], [[0.0]]))
        >>> plant.C, plant.dt
        (array([[2.]]), None)
        """
        import control

        if not isinstance(sys, control.StateSpace):
            raise TypeError(f"sys must be a control.StateSpace, got {type(sys).__name__}")
        if sys.dt is True:
            raise ValueError("sys has an unspecified sampling time (dt=True); give a number")
        A, B, C, D = (np.asarray(M, dtype=float) for M in (sys.A, sys.B, sys.C, sys.D))
        state = C.shape == (A.shape[0], A.shape[0]) and np.array_equal(C, np.eye(A.shape[0])) and not D.any()
        return cls(A, B, None if not sys.dt else float(sys.dt), C=None if state else C, D=None if state else D)

    def to_statespace(self, C=None, D=None):
        """The plant as a python-control ``StateSpace``, from ``u`` to ``y``.

        Parameters
        ----------
        C, D : array_like, optional
            Outputs to use instead of the plant's own (default: its ``C`` and
            ``D``, or the full state ``C = I``, ``D = 0`` without an output model).

        Returns
        -------
        control.StateSpace

        Examples
        --------
        >>> import robustctl as rc
        >>> rc.Plant([[0.5]], [[1.0]], 0.1, C=[[2.0]]).to_statespace().C
        array([[2.]])
        """
        import control

        own_C, own_D = self.output_matrices()
        if C is None:
            C, default_D = own_C, own_D
        else:
            C = as_matrix(C, "C", cols=self.n, cols_what="the number of states")
            default_D = np.zeros((C.shape[0], self.m))
        D = default_D if D is None else as_matrix(D, "D", rows=C.shape[0], cols=self.m, rows_what="rows of C",
                                                  cols_what="the number of inputs")
        return control.ss(self.F, self.G, C, D, 0 if self.dt is None else self.dt)

    def __repr__(self) -> str:
        time = "continuous" if self.dt is None else f"dt={self.dt:g}"
        outputs = f"p={self.p}, " if self.has_outputs else ""
        return f"Plant(n={self.n}, m={self.m}, {outputs}{time})"


def check_plant(value, name: str = "plant", *, discrete_for: str | None = None) -> Plant:
    """``value`` itself if it is a :class:`~robustctl.Plant`; otherwise an error naming ``name``.

    Parameters
    ----------
    value : object
        What the caller passed as a plant.
    name : str
        The argument's name in the messages.
    discrete_for : str, optional
        A design's name: a continuous-time plant is then refused.

    Returns
    -------
    Plant
        ``value``.

    Raises
    ------
    TypeError
        ``value`` is not a :class:`~robustctl.Plant`.
    ValueError
        ``discrete_for`` is given and the plant is continuous-time.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.validation import check_plant
    >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1)
    >>> check_plant(plant) is plant
    True
    >>> check_plant([[0.5]], "scenario")
    Traceback (most recent call last):
        ...
    TypeError: scenario must be a robustctl.Plant, got list
    """
    if not isinstance(value, Plant):
        raise TypeError(f"{name} must be a robustctl.Plant, got {type(value).__name__}")
    if discrete_for is not None and not value.is_discrete:
        raise ValueError(f"{name} must be discrete-time (dt > 0) for {discrete_for}; discretise it first")
    return value


def check_plants(plants, name: str = "plants", *, like: Plant | None = None, reference: str | None = None,
                 non_empty: bool = True, discrete_for: str | None = None) -> list[Plant]:
    """``plants`` as a list of :class:`~robustctl.Plant` of one size and sampling time.

    The one check of a plant set: polytope vertices, the scenarios of a
    tuning problem, the plants of :meth:`NormBounded.from_plants
    <robustctl.NormBounded.from_plants>`.

    Parameters
    ----------
    plants : sequence of Plant
        A list or tuple of plants.
    name : str
        The argument's name in the messages (``"<name>[i]"`` for an element).
    like : Plant, optional
        The plant every element must match in ``n``, ``m`` and ``dt``
        (default ``plants[0]``).
    reference : str, optional
        How the messages name ``like`` (default ``"<name>[0]"``).
    non_empty : bool
        Refuse an empty sequence.
    discrete_for : str, optional
        A design's name: every plant must then be discrete-time.

    Returns
    -------
    list of Plant

    Raises
    ------
    TypeError
        Anything but a list or tuple of plants (an empty one too, with ``non_empty``).
    ValueError
        ``<name>[i]`` with another size or sampling time than ``like``.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.validation import check_plants
    >>> a, b = rc.Plant([[0.5]], [[1.0]], 0.1), rc.Plant([[0.7]], [[1.0]], 0.1)
    >>> len(check_plants((a, b)))
    2
    >>> check_plants([a, rc.Plant([[0.7]], [[1.0]], 0.2)], "scenarios")
    Traceback (most recent call last):
        ...
    ValueError: scenarios[1] must have the sampling time of scenarios[0] (dt=0.1), got dt=0.2
    """
    what = f"a {'non-empty ' if non_empty else ''}list of robustctl.Plant"
    if isinstance(plants, Plant) or not isinstance(plants, Sequence) or isinstance(plants, (str, bytes)):
        raise TypeError(f"{name} must be {what}, got {type(plants).__name__}")
    if non_empty and len(plants) == 0:
        raise TypeError(f"{name} must be {what}, got an empty {type(plants).__name__}")
    out = [check_plant(p, f"{name}[{i}]", discrete_for=discrete_for) for i, p in enumerate(plants)]
    ref = like if like is not None else (out[0] if out else None)
    reference = reference or f"{name}[0]"
    for i, p in enumerate(out):
        assert ref is not None
        if (p.n, p.m) != (ref.n, ref.m):
            raise ValueError(f"{name}[{i}] must have n={ref.n} states and m={ref.m} inputs like {reference}, "
                             f"got n={p.n}, m={p.m}")
        if p.dt != ref.dt:
            raise ValueError(f"{name}[{i}] must have the sampling time of {reference} (dt={ref.dt}), got dt={p.dt}")
    return out


def check_vertices(plant: Plant, vertices, *, reference: str = "plant", non_empty: bool = False) -> list[Plant]:
    """``[plant, *vertices]``: the vertices of the polytope ``conv{plant, *vertices}``, each checked.

    Used by :func:`robustctl.hinf` and :func:`robustctl.robust_stability`:
    each vertex must be a :class:`~robustctl.Plant` of ``plant``'s size and
    sampling time (:func:`check_plants`).

    Parameters
    ----------
    plant : Plant
        The nominal plant, the first vertex.
    vertices : sequence of Plant or None
        The other vertices; ``None`` (and, unless ``non_empty``, an empty
        list) is the plant alone.
    reference : str
        How the messages name ``plant``.
    non_empty : bool
        Require at least one vertex besides ``plant``.

    Returns
    -------
    list of Plant

    Raises
    ------
    TypeError, ValueError
        As :func:`check_plants`, naming ``vertices[i]``.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.validation import check_vertices
    >>> plant = rc.Plant([[0.5]], [[1.0]], 0.1)
    >>> [v.F.item() for v in check_vertices(plant, [rc.Plant([[0.9]], [[1.0]], 0.1)])]
    [0.5, 0.9]
    >>> check_vertices(plant, None) == [plant]
    True
    """
    if vertices is None and not non_empty:
        return [plant]
    return [plant, *check_plants(vertices, "vertices", like=plant, reference=reference, non_empty=non_empty)]
