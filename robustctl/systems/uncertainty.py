"""Norm-bounded parametric uncertainty ``[dF dG] = H Delta [EF EG]``, ``||Delta|| <= 1``.

Reference: Cerri, Terra & Ishihara (2009), "Recursive robust regulator for
discrete-time state-space systems", and Sayed (2001), "A framework for
state-space estimation with uncertain models", IEEE TAC 46(7).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .._validation import as_batch, as_float_array, as_matrix, check_int, check_positive_scalar, frozen
from .plant import Plant, check_plant, check_plants

__all__ = ["NormBounded", "check_norm_bounded"]


def _domain(value) -> float | str | None:
    """``None``, ``"continuous"`` or a positive finite sampling time (``ValueError`` naming ``domain``)."""
    if value is None or value == "continuous":
        return value
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
            and np.isfinite(value) and value > 0:
        return float(value)
    raise ValueError(f"domain must be None, 'continuous' or a positive sampling time, got {value!r}")


def _domain_of(plant: Plant) -> float | str:
    return "continuous" if plant.dt is None else float(plant.dt)


def _domain_text(domain: float | str) -> str:
    return "continuous-time plants" if domain == "continuous" else f"discrete-time plants with dt={domain:g}"


@dataclass(frozen=True, eq=False, repr=False)
class NormBounded:
    r"""Uncertainty ``dF = H Delta EF``, ``dG = H Delta EG`` with ``||Delta||_2 <= 1``.

    The uncertain plant of the robust LQR [1]_ and of the robust analysis
    (:func:`robustctl.robust_stability`, :func:`robustctl.guaranteed_cost`):
    ``H`` says which state equations the uncertainty enters, ``EF`` and
    ``EG`` how it depends on the state and the input, ``Delta`` (``p x l``,
    unknown, possibly time-varying) how large it is.

    Parameters
    ----------
    H : (n, p) array_like
        Input matrix of the uncertainty (a 1-D array is one column).
    EF : (l, n) array_like
        State part of the uncertainty's output (a 1-D array is one row).
    EG : (l, m) array_like
        Input part of the uncertainty's output (a 1-D array is one row).
    domain : None, "continuous" or float
        The time domain of the plants the model is about: ``"continuous"``, or
        the sampling time ``dt`` of discrete-time plants. :meth:`check_plant`
        (and so every analysis that takes the model) refuses a plant of another
        domain. ``None`` (the default of a hand-built model) leaves it
        unchecked; :meth:`from_plants` records the plants' domain.

    Attributes
    ----------
    H, EF, EG : ndarray
        The matrices, read-only.
    n, m, p, l : int
        States, inputs, rows and columns of ``Delta`` (the properties below).
    domain : None, "continuous" or float
        The time domain (see Parameters).

    Raises
    ------
    ValueError
        Shapes that do not agree (the message names the matrix and both
        shapes), non-finite entries, a ``domain`` that is not None,
        ``"continuous"`` or a positive sampling time.
    TypeError
        A non-numeric entry.

    See Also
    --------
    NormBounded.from_plants : the model that covers a set of plants.
    robustctl.rlqr : the robust LQR for this uncertainty.
    robustctl.robust_stability : its stability margin for a given gain.

    Notes
    -----
    The uncertain plant is

    .. math::

        x[k+1] = (F + H \Delta E_F)\, x[k] + (G + H \Delta E_G)\, u[k],
        \qquad \|\Delta\|_2 \le 1,

    so under ``u = K x`` the closed loop is ``A + H Delta E`` with
    ``A = F + G K`` and ``E = EF + EG K``: the nominal loop in feedback with
    ``Delta`` through ``p = E x`` and ``q = Delta p`` [2]_.

    References
    ----------
    .. [1] J. P. Cerri, M. H. Terra, J. Y. Ishihara, "Recursive robust
       regulator for discrete-time state-space systems", American Control
       Conference 2009, 3077-3082.
    .. [2] A. H. Sayed, "A framework for state-space estimation with
       uncertain models", IEEE Trans. Automatic Control 46(7), 998-1013, 2001.

    Examples
    --------
    A double integrator whose input gain is known to 30 %:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> unc = rc.NormBounded(H=[[0.0], [0.1]], EF=[[0.0, 0.0]], EG=[[0.3]])
    >>> unc
    NormBounded(n=2, m=1, p=1, l=1)
    >>> low = unc.perturb(plant, [[-1.0]])
    >>> bool(np.allclose(low.G, plant.G + np.array([[0.0], [0.1]]) * -1.0 * 0.3))
    True
    """

    H: np.ndarray
    EF: np.ndarray
    EG: np.ndarray
    domain: float | str | None = None

    def __init__(self, H, EF, EG, *, domain: float | str | None = None):
        EF = as_matrix(EF, "EF")
        l, n = EF.shape
        H = as_matrix(H, "H", rows=n, vector="column", rows_what="the number of states, from EF's columns")
        EG = as_matrix(EG, "EG", rows=l, rows_what="the rows of EF")
        object.__setattr__(self, "H", frozen(H))
        object.__setattr__(self, "EF", frozen(EF))
        object.__setattr__(self, "EG", frozen(EG))
        object.__setattr__(self, "domain", _domain(domain))

    @property
    def n(self) -> int:
        """Columns of EF (the number of states)."""
        return self.EF.shape[1]

    @property
    def m(self) -> int:
        """Columns of EG (the number of inputs)."""
        return self.EG.shape[1]

    @property
    def p(self) -> int:
        """Columns of H (rows of Delta)."""
        return self.H.shape[1]

    @property
    def l(self) -> int:  # noqa: E743 - the paper's name
        """Rows of EF and EG (columns of Delta)."""
        return self.EF.shape[0]

    def check_plant(self, plant: Plant) -> None:
        """Raise ``TypeError`` if ``plant`` is not a :class:`Plant`, ``ValueError`` if its sizes or domain differ.

        Parameters
        ----------
        plant : Plant
            The plant the uncertainty is meant for (same ``n`` and ``m``).

        Raises
        ------
        TypeError
            ``plant`` is not a :class:`~robustctl.Plant`.
        ValueError
            Its number of states or inputs differs from the uncertainty's,
            or its time domain (continuous, or the sampling time) from the
            uncertainty's ``domain`` when that is set.
        """
        check_plant(plant)
        if (plant.n, plant.m) != (self.n, self.m):
            raise ValueError(f"uncertainty is for n={self.n} states and m={self.m} inputs, "
                             f"plant has n={plant.n}, m={plant.m}")
        if self.domain is not None and _domain_of(plant) != self.domain:
            got = "continuous time" if plant.dt is None else f"dt={plant.dt:g}"
            raise ValueError(f"uncertainty is for {_domain_text(self.domain)} (its domain), plant has {got}")

    def _deltas(self, Delta) -> np.ndarray:
        D = as_float_array(Delta, "Delta")
        if D.ndim == 0 or (D.ndim == 1 and self.p == 1 and self.l == 1):
            D = D.reshape(-1, 1, 1) if D.ndim else D.reshape(1, 1, 1)
        elif D.ndim == 2:
            D = D[None]
        D = as_batch(D, "Delta", (None, self.p, self.l), ("", "columns of H", "rows of EF"))
        norms = np.linalg.norm(D, ord=2, axis=(1, 2))
        if np.any(norms > 1 + 1e-12):
            raise ValueError(f"Delta must be a contraction (||Delta||_2 <= 1), got norm {norms.max():.6g}")
        return D

    def perturb(self, plant: Plant, Delta) -> Plant:
        """The plant ``(F + H Delta EF, G + H Delta EG)`` for one ``Delta``.

        Parameters
        ----------
        plant : Plant
            The nominal plant.
        Delta : (p, l) array_like or float
            One contraction (``||Delta||_2 <= 1``); a scalar if ``p = l = 1``.

        Returns
        -------
        Plant
            The perturbed plant; its outputs and disturbance input are kept.

        Raises
        ------
        ValueError
            ``Delta`` of the wrong shape, of norm above 1, or more than one.
        """
        self.check_plant(plant)
        D = self._deltas(Delta)
        if D.shape[0] != 1:
            raise ValueError(f"perturb takes one Delta; got {D.shape[0]} (use perturbed_matrices)")
        F, G = self.perturbed_matrices(plant, D[0])
        return replace(plant, F=F[0], G=G[0])   # outputs and disturbance input kept

    def perturbed_matrices(self, plant: Plant, Deltas) -> tuple[np.ndarray, np.ndarray]:
        """Stacked perturbed matrices for S realisations ``Deltas`` of shape (S, p, l).

        Parameters
        ----------
        plant : Plant
            The nominal plant.
        Deltas : (S, p, l) array_like
            Contractions; one (p, l) matrix is ``S = 1``, and a 1-D array with
            ``p = l = 1`` is read as S scalar realisations.

        Returns
        -------
        F : (S, n, n) ndarray
            ``F + H Delta_s EF`` for each realisation.
        G : (S, n, m) ndarray
            ``G + H Delta_s EG`` for each realisation.

        Raises
        ------
        ValueError
            A realisation of the wrong shape or of norm above 1.

        Examples
        --------
        >>> import numpy as np
        >>> import robustctl as rc
        >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
        >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.3]])
        >>> F, G = unc.perturbed_matrices(plant, [-1.0, 0.0, 1.0])
        >>> F.shape, G.shape
        ((3, 2, 2), (3, 2, 1))
        >>> bool(np.allclose(G[:, 1, 0], 0.1 + 0.1 * 0.3 * np.array([-1.0, 0.0, 1.0])))
        True
        """
        self.check_plant(plant)
        D = self._deltas(Deltas)
        HD = np.einsum("np,spl->snl", self.H, D)
        return plant.F + HD @ self.EF, plant.G + HD @ self.EG

    @classmethod
    def from_plants(cls, nominal: Plant, plants: Sequence[Plant], *, rank: int | None = None,
                    tol: float = 1e-10) -> NormBounded:
        r"""The norm-bounded model about ``nominal`` that contains every plant of ``plants``.

        With the deviations ``D_i = [F_i - F, G_i - G]`` (``n x (n + m)``) of the
        plants from the nominal ``(F, G)``, the model ``[dF dG] = H Delta E``,
        ``E = [EF EG]``, is built from the two subspaces every ``D_i`` lives in
        (singular value decompositions of the stacked deviations [1]_):

        * the column space: ``[D_1 ... D_N] = U S V'``, singular values
          ``s_1 >= s_2 >= ...``; ``U_p`` its first ``p`` left singular vectors;
        * the row space: ``[D_1; ...; D_N] = X S' W'``, singular values
          ``s'_1 >= ...``; ``W_l`` its first ``l`` right singular vectors;

        where ``p`` and ``l`` are the numerical ranks (singular values above
        ``tol / 2`` times ``d = max_i ||D_i||_2``, at most ``rank``). Each
        direction is weighted by the square root of its share of the
        deviations, ``S_h = diag(sqrt(s_k / s_1))``,
        ``S_e = diag(sqrt(s'_j / s'_1))``, so that a direction in which the
        plants hardly deviate gets a correspondingly small share of the
        uncertainty (with orthonormal ``H`` and ``E`` every direction of
        ``Delta`` could reach the size of the largest deviation, a far more
        conservative model when the deviations are close to low rank). Then
        ``D_i = U_p S_h Delta0_i S_e W_l'`` with the least-squares solution
        ``Delta0_i = S_h^-1 U_p' D_i W_l S_e^-1`` (``H^+ D_i E^+``; its
        entries satisfy ``|(Delta0_i)_kj| <= sqrt(s_1 s'_1)``, since
        ``|u_k' D_i w_j| <= min(s_k, s'_j)``), and the smallest common
        scaling ``c = max_i ||Delta0_i||_2`` puts every ``Delta_i`` in the
        unit ball:

        .. math::

            H = \sqrt{c}\, U_p S_h, \qquad [E_F\; E_G] = \sqrt{c}\, S_e W_l', \qquad
            \Delta_i = \Delta^0_i / c, \qquad \max_i \|\Delta_i\|_2 = 1,

        attained by the plant(s) that deviate most (so a one-parameter family
        ``(F + theta F1, G + theta G1)``, ``|theta| <= 1``, fitted on its two
        extreme plants, is reproduced exactly, with ``||Delta|| = 1`` at both
        ends). The model is checked to contain every plant: each deviation is
        reproduced by its ``Delta_i`` to ``||D_i - H Delta_i E||_2 <= tol d``
        (guaranteed by the truncation when ``rank`` is not given; with a
        ``rank`` too small to represent the deviations a ``ValueError`` says
        which plant does not fit and by how much).

        The set ``{H Delta E : ||Delta|| <= 1}`` contains the plants (and
        their convex hull, the unit ball being convex) but in general also
        plants beyond them: a certificate against it is conservative for the
        plant set, never optimistic. ``(a H, E / a)`` is the same model.

        Parameters
        ----------
        nominal : Plant
            The nominal plant ``(F, G)``, about which the deviations are taken
            (a design's plant; it need not be one of ``plants``).
        plants : sequence of Plant
            The plants to cover (same ``n``, ``m`` and ``dt`` as ``nominal``),
            e.g. :func:`robustctl.sample_plants` at the ends of a parameter range.
        rank : int, optional
            Upper bound on ``p`` and ``l`` (the sizes of ``Delta``); default:
            the numerical ranks.
        tol : float
            Relative tolerance of the ranks and of the containment check (see above).

        Returns
        -------
        NormBounded
            ``H`` (n x p), ``EF`` (l x n), ``EG`` (l x m); its ``domain`` is
            the plants' (``"continuous"`` or their ``dt``).

        Raises
        ------
        ValueError
            A plant of another size or sampling time (naming ``plants[i]``), no
            plant deviating from ``nominal``, or a deviation the model cannot
            reproduce with the given ``rank``.

        References
        ----------
        .. [1] G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed.,
           Johns Hopkins 2013, Sec. 2.4 (the SVD and its truncation error) and
           5.5 (least squares with the pseudo-inverse).

        Examples
        --------
        >>> import numpy as np
        >>> import robustctl as rc
        >>> nominal = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.0], [0.1]], dt=0.1)
        >>> plants = [rc.Plant(nominal.F, nominal.G * s, dt=0.1) for s in (0.8, 1.2)]
        >>> unc = rc.NormBounded.from_plants(nominal, plants)
        >>> unc
        NormBounded(n=2, m=1, p=1, l=1, domain=0.1)
        >>> bool(np.allclose(abs(unc.H @ unc.EG), [[0.0], [0.02]]))
        True

        Both plants lie in the model, at ``Delta = -1`` and ``+1``:

        >>> sign = float(np.sign((unc.H @ unc.EG)[1, 0]))
        >>> bool(np.allclose(unc.perturb(nominal, [[sign]]).G, plants[1].G))
        True
        """
        check_plant(nominal, "nominal")
        plants = check_plants(plants, "plants", like=nominal, reference="nominal")
        cap = None if rank is None else check_int(rank, "rank")
        tol = check_positive_scalar(tol, "tol")
        if tol >= 1:
            raise ValueError(f"tol must be < 1 (a relative tolerance), got {tol}")
        nom = np.hstack([nominal.F, nominal.G])
        D = np.stack([np.hstack([p.F, p.G]) - nom for p in plants])               # (N, n, n + m)
        d = float(np.linalg.norm(D, ord=2, axis=(1, 2)).max())
        if not d > 0:
            raise ValueError("plants do not deviate from nominal (every [F_i - F, G_i - G] is zero): "
                             "there is no uncertainty to model")
        U, su, _ = np.linalg.svd(np.concatenate(list(D), axis=1), full_matrices=False)
        _, sv, Wt = np.linalg.svd(np.concatenate(list(D), axis=0), full_matrices=False)
        p = int(np.count_nonzero(su > 0.5 * tol * d))
        l = int(np.count_nonzero(sv > 0.5 * tol * d))
        if cap is not None:
            p, l = min(p, cap), min(l, cap)
        Sh, Se = np.sqrt(su[:p] / su[0]), np.sqrt(sv[:l] / sv[0])
        H0, E0 = U[:, :p] * Sh, Se[:, None] * Wt[:l]
        Delta = np.einsum("np,snk,kl->spl", U[:, :p] / Sh, D, Wt[:l].T / Se)        # H0^+ D_i E0^+
        c = float(np.linalg.norm(Delta, ord=2, axis=(1, 2)).max())
        H, E, Delta = np.sqrt(c) * H0, np.sqrt(c) * E0, Delta / c
        resid = np.linalg.norm(D - np.einsum("np,spl,lk->snk", H, Delta, E), ord=2, axis=(1, 2)) / d
        worst = int(np.argmax(resid))
        if resid[worst] > tol:
            raise ValueError(f"a model with Delta of size {p} x {l} (rank={rank}) reproduces the deviation of "
                             f"plants[{worst}] only to a relative error of {resid[worst]:.3g} > tol={tol:g}; "
                             "allow a larger rank (or a larger tol)")
        n = nominal.n
        return cls(H, E[:, :n], E[:, n:], domain=_domain_of(nominal))

    def __repr__(self) -> str:
        domain = "" if self.domain is None else f", domain={self.domain!r}"
        return f"NormBounded(n={self.n}, m={self.m}, p={self.p}, l={self.l}{domain})"


def check_norm_bounded(value, plant: Plant, name: str = "uncertainty") -> NormBounded:
    """``value`` if it is a :class:`~robustctl.NormBounded` of ``plant``'s size.

    Parameters
    ----------
    value : object
        The argument to check.
    plant : Plant
        The plant it must fit (same ``n`` and ``m``).
    name : str
        The argument's name in the messages.

    Returns
    -------
    NormBounded
        ``value`` itself.

    Raises
    ------
    TypeError
        ``value`` is not a :class:`~robustctl.NormBounded` (message naming ``name``).
    ValueError
        Its sizes do not match ``plant``'s.

    Examples
    --------
    >>> import robustctl as rc
    >>> from robustctl.systems.uncertainty import check_norm_bounded
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> check_norm_bounded(rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[0.3]]), plant)
    NormBounded(n=2, m=1, p=1, l=1)
    >>> check_norm_bounded(rc.NormBounded([[0.1]], [[0.0]], [[0.3]]), plant)
    Traceback (most recent call last):
    ...
    ValueError: uncertainty is for n=1 states and m=1 inputs, plant has n=2, m=1
    """
    if not isinstance(value, NormBounded):
        raise TypeError(f"{name} must be a robustctl.NormBounded, got {type(value).__name__}")
    value.check_plant(plant)
    return value
