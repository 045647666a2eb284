r"""State feedback with input memory: ``u[k] = K x[k] + K_input u[k-1]``.

A law that feeds back the previous input as well as the state is a static
gain on the plant augmented by that input,

.. math::

    \begin{bmatrix} x \\ u_{prev} \end{bmatrix}^+ =
    \begin{bmatrix} F & 0 \\ 0 & 0 \end{bmatrix}
    \begin{bmatrix} x \\ u_{prev} \end{bmatrix} +
    \begin{bmatrix} G \\ I \end{bmatrix} u ,
    \qquad u = [K \;\; K_{input}] \begin{bmatrix} x \\ u_{prev} \end{bmatrix},

(:func:`with_input_memory`), so its closed loop and its
robust stability are those of the augmented loop. The delayed
full-information H-infinity law of :mod:`robustctl.synthesis.hinf_game`
(``K = K_e``, ``K_input = K_u``) is one; :class:`InputMemoryFeedback` with
``K_input=None`` is the plain static law ``u = K x``, so one type holds
both (:meth:`robustctl.models.pathfollow.PathFollowing.run_laws` simulates a mixed
list).

References
----------
G. F. Franklin, J. D. Powell, M. L. Workman, *Digital Control of Dynamic
Systems*, 3rd ed., Addison-Wesley 1998, Sec. 8.1 (a delayed input as an
extra state of the discrete model).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._validation import as_float_array, as_matrix, frozen
from .plant import Plant, check_plant
from .stability import is_stable
from .uncertainty import NormBounded, check_norm_bounded

__all__ = ["InputMemoryFeedback", "with_input_memory"]


@dataclass(frozen=True, eq=False, repr=False)
class InputMemoryFeedback:
    r"""The law ``u[k] = K x[k] + K_input u[k-1]`` (``u[-1] = 0``); ``K_input=None``: ``u = K x``.

    Sign convention ``u = K x`` (the paper's), as :class:`robustctl.Controller`.
    Calling the law, ``law(x, u_prev)``, gives the input for a state (or a
    stack of states).

    Parameters
    ----------
    K : (m, n) array_like
        State gain.
    K_input : (m, m) array_like, optional
        Gain on the previous applied input; None (default) for a static law.

    Attributes
    ----------
    K : (m, n) ndarray
        State gain.
    K_input : (m, m) ndarray or None
        Gain on the previous applied input; None for a static law.

    Raises
    ------
    ValueError
        ``K_input`` not ``m x m`` for the ``m`` rows of ``K``; non-finite entries.

    See Also
    --------
    with_input_memory : the augmented plant.
    robustctl.synthesis.hinf_game : the delayed full-information law.

    Notes
    -----
    The law is the static gain ``[K  K_input]`` on the plant augmented by
    the previous input [1]_,

    .. math::

        \begin{bmatrix} x \\ u_{prev} \end{bmatrix}^+ =
        \left(\begin{bmatrix} F & 0 \\ 0 & 0 \end{bmatrix} +
        \begin{bmatrix} G \\ I \end{bmatrix}
        \begin{bmatrix} K & K_{input} \end{bmatrix}\right)
        \begin{bmatrix} x \\ u_{prev} \end{bmatrix},

    whose matrix is :meth:`closed_loop`.

    References
    ----------
    .. [1] G. F. Franklin, J. D. Powell, M. L. Workman, *Digital Control of
       Dynamic Systems*, 3rd ed., Addison-Wesley 1998, Sec. 8.1.

    Examples
    --------
    A law that feeds back the previous input: simulated step by step, it
    gives the state that the powers of its augmented closed loop give.

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
    >>> law = rc.InputMemoryFeedback([[-3.0, -2.0]], [[0.5]])
    >>> law.is_stabilizing(plant)
    True
    >>> x, u_prev = np.array([1.0, 0.0]), np.zeros(1)
    >>> for _ in range(20):
    ...     u = law(x, u_prev)
    ...     x, u_prev = plant.F @ x + plant.G @ u, u
    >>> xa = np.linalg.matrix_power(law.closed_loop(plant), 20) @ [1.0, 0.0, 0.0]
    >>> bool(np.allclose(xa, np.r_[x, u_prev]))
    True

    The delayed full-information law of the game Riccati recursion on the
    paper's truck, closed around the plant augmented by the previous input:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.synthesis.hinf_game import hinf_game
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> Q, R = np.diag([1.0, 1.0, 25000.0, 100.0]), [[33535.0]]
    >>> g = hinf_game(plant, Bw=np.ones((4, 1)), Q=Q, R=R, gamma=14350.0, P_final=np.eye(4))
    >>> law = rc.InputMemoryFeedback(g.K_e, g.K_u)
    >>> law.gain.shape, law.closed_loop(plant).shape, law.is_stabilizing(plant)
    ((1, 5), (5, 5), True)
    """

    K: np.ndarray
    K_input: np.ndarray | None = None

    def __post_init__(self):
        K = as_matrix(self.K, "K")
        object.__setattr__(self, "K", frozen(K))
        if self.K_input is not None:
            m = K.shape[0]
            Ku = as_matrix(self.K_input, "K_input", rows=m, cols=m, rows_what="the rows of K",
                           cols_what="the rows of K")
            object.__setattr__(self, "K_input", frozen(Ku))

    @property
    def n(self) -> int:
        """Number of states."""
        return self.K.shape[1]

    @property
    def m(self) -> int:
        """Number of inputs."""
        return self.K.shape[0]

    @property
    def has_memory(self) -> bool:
        """Whether the law feeds back the previous input (``K_input`` is given)."""
        return self.K_input is not None

    @property
    def gain(self) -> np.ndarray:
        """The static gain on the augmented state: ``[K K_input]`` (m, n + m), or ``K`` without memory."""
        return self.K if self.K_input is None else np.hstack([self.K, self.K_input])

    def __call__(self, x: ArrayLike, u_prev: ArrayLike | None = None) -> np.ndarray:
        """``K x + K_input u_prev`` for one state (n,) or a stack (..., n); ``u_prev`` defaults to zero.

        Parameters
        ----------
        x : (n,) or (..., n) array_like
            State(s).
        u_prev : (m,) or (..., m) array_like, optional
            Previous applied input(s); ignored by a static law.

        Returns
        -------
        (m,) or (..., m) ndarray
            The input(s).

        Raises
        ------
        ValueError
            ``x`` or ``u_prev`` with the wrong last axis.
        """
        xa = as_float_array(x, "x")
        if xa.shape[-1:] != (self.n,):
            raise ValueError(f"x must have {self.n} entries in its last axis (the number of states), "
                             f"got shape {xa.shape}")
        u = xa @ self.K.T
        if u_prev is None or self.K_input is None:
            return u
        up = as_float_array(u_prev, "u_prev")
        if up.shape[-1:] != (self.m,):
            raise ValueError(f"u_prev must have {self.m} entries in its last axis (the number of inputs), "
                             f"got shape {up.shape}")
        return u + up @ self.K_input.T

    def _check(self, plant: Plant) -> None:
        check_plant(plant, discrete_for=None if self.K_input is None else "a law with input memory")
        if (plant.n, plant.m) != (self.n, self.m):
            raise ValueError(f"plant must have n={self.n} states and m={self.m} inputs (the shape of K), "
                             f"got n={plant.n}, m={plant.m}")

    def augmented_plant(self, plant: Plant) -> Plant:
        """The plant the law is a static gain of: ``plant`` with ``u[k-1]`` as extra states (or ``plant``).

        Parameters
        ----------
        plant : Plant
            A discrete plant of the law's size (a static law also takes a continuous one).

        Returns
        -------
        Plant
            :func:`with_input_memory` of ``plant``, or ``plant`` for a static law.
        """
        self._check(plant)
        if self.K_input is None:
            return plant
        aug = with_input_memory(plant)
        assert isinstance(aug, Plant)
        return aug

    def augmented_uncertainty(self, uncertainty: NormBounded, plant: Plant) -> NormBounded:
        """``[dF dG] = H Delta [EF EG]`` on the augmented plant: ``[H; 0]``, ``[EF 0]``, ``EG`` (``u[k-1]`` exact).

        Parameters
        ----------
        uncertainty : NormBounded
            The uncertainty of ``plant``.
        plant : Plant
            The plant.

        Returns
        -------
        NormBounded
            The uncertainty of :meth:`augmented_plant` (``uncertainty`` for a static law).
        """
        self._check(plant)
        if self.K_input is None:
            return uncertainty
        aug = with_input_memory(plant, uncertainty)
        assert isinstance(aug, tuple)
        return aug[1]

    def closed_loop(self, plant: Plant) -> np.ndarray:
        """``F_a + G_a gain``: the closed loop on the augmented state, (n + m, n + m) (or ``F + G K``).

        Parameters
        ----------
        plant : Plant
            The plant.

        Returns
        -------
        ndarray
            (n + m, n + m) with input memory, else (n, n).
        """
        p = self.augmented_plant(plant)
        return p.F + p.G @ self.gain

    def is_stabilizing(self, plant: Plant) -> bool:
        """Whether :meth:`closed_loop` is stable (margin of :mod:`robustctl.systems.stability`).

        Parameters
        ----------
        plant : Plant
            The plant.

        Returns
        -------
        bool
        """
        return is_stable(self.closed_loop(plant), discrete=plant.is_discrete)

    def __repr__(self) -> str:
        with np.printoptions(precision=4, linewidth=100):
            k = np.array2string(self.K, separator=", ")
            ku = None if self.K_input is None else np.array2string(self.K_input, separator=", ")
        return f"InputMemoryFeedback(K={k}, K_input={ku})"


def with_input_memory(plant: Plant, uncertainty: NormBounded | None = None
                      ) -> Plant | tuple[Plant, NormBounded]:
    """The plant with the previous input as a state, for laws ``u[k] = K_e x[k] + K_u u[k-1]``.

    ``[x; u_prev]+ = [[F, 0], [0, 0]] [x; u_prev] + [G; I] u``, so the law is the
    static gain ``[K_e K_u]`` on the augmented state (its closed loop can then
    be checked, e.g. by :func:`robustctl.robust_stability`). With
    ``uncertainty`` (``[dF dG] = H Delta [EF EG]``) the augmented one is
    returned too: ``H_a = [H; 0]``, ``EF_a = [EF 0]``, ``EG`` unchanged
    (``u_prev`` is exactly known).

    Parameters
    ----------
    plant : Plant
        The plant ``(F, G)``.
    uncertainty : NormBounded, optional
        Its uncertainty.

    Returns
    -------
    Plant or (Plant, NormBounded)
        The augmented plant (n + m states), with the augmented uncertainty
        when ``uncertainty`` is given.

    Raises
    ------
    TypeError
        ``plant`` is not a Plant, ``uncertainty`` not a NormBounded.
    ValueError
        An uncertainty of another size.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.systems.input_memory import with_input_memory
    >>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
    >>> aug = with_input_memory(plant)
    >>> aug
    Plant(n=3, m=1, dt=0.1)
    >>> bool(np.array_equal(aug.F, np.block([[plant.F, np.zeros((2, 1))], [np.zeros((1, 3))]])))
    True
    """
    check_plant(plant)
    n, m = plant.n, plant.m
    Fa = np.zeros((n + m, n + m))
    Fa[:n, :n] = plant.F
    aug = Plant(Fa, np.vstack([plant.G, np.eye(m)]), plant.dt)
    if uncertainty is None:
        return aug
    check_norm_bounded(uncertainty, plant)
    H, EF, EG = uncertainty.H, uncertainty.EF, uncertainty.EG
    return aug, NormBounded(np.vstack([H, np.zeros((m, H.shape[1]))]), np.hstack([EF, np.zeros((EF.shape[0], m))]),
                            EG)
