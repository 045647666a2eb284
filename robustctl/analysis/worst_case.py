"""The worst-case search over ``||Delta|| <= 1`` (:func:`robustctl.worst_case`).

Projected gradient ascent on the spectral radius (or abscissa) of
``A + H Delta E`` from the worst-case directions and random extreme points.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from .._validation import as_rng, check_int, frozen
from ..systems.controller import Controller
from ..systems.plant import Plant
from ..systems.stability import is_stable
from ..systems.uncertainty import NormBounded
from ._common import _ASCENT_ITER, _radius, _uncertain_loop
from .results import WorstCase


def _polar(M: np.ndarray) -> np.ndarray:
    """The nearest matrix with every singular value 1 (``U V'`` of ``M = U S V'``)."""
    U, _, Vt = np.linalg.svd(M, full_matrices=False)
    return U @ Vt


def _project(D: np.ndarray) -> np.ndarray:
    """Projection onto ``||D||_2 <= 1``: singular values clipped at 1."""
    U, s, Vt = np.linalg.svd(D, full_matrices=False)
    return (U * np.minimum(s, 1.0)) @ Vt


class _Objective:
    """Spectral radius (or abscissa) of ``A + H D E`` and its gradient in ``D``, counting evaluations."""

    def __init__(self, A, H, E, discrete):
        self.A, self.H, self.E, self.discrete = A, H, E, discrete
        self.count = 0

    def _eig(self, D):
        self.count += 1
        return scipy.linalg.eig(self.A + self.H @ D @ self.E, left=True, right=True)

    def value(self, D) -> float:
        self.count += 1
        return _radius(self.A + self.H @ D @ self.E, self.discrete)

    def value_grad(self, D) -> tuple[float, np.ndarray]:
        # d lambda = y^H H dD E x / (y^H x) for a simple eigenvalue (y^H A = lambda y^H)
        lam, Y, X = self._eig(D)
        i = int(np.argmax(np.abs(lam) if self.discrete else lam.real))
        x, y = X[:, i], Y[:, i]
        den = y.conj() @ x  # ~0 only at a defective eigenvalue: keep the direction
        g = np.outer(y.conj() @ self.H, self.E @ x) / (den if abs(den) > 1e-300 else 1.0)
        if self.discrete:
            f = float(abs(lam[i]))
            grad = (np.conj(lam[i]) * g).real / f if f > 0 else g.real
        else:
            f, grad = float(lam[i].real), g.real
        return f, grad


def _ascend(obj: _Objective, D: np.ndarray) -> tuple[float, np.ndarray]:
    """Projected gradient ascent with a step that doubles on success and halves on failure."""
    f, g = obj.value_grad(D)
    step = 1.0
    for _ in range(_ASCENT_ITER):
        gn = float(np.linalg.norm(g))
        if gn == 0.0 or step < 1e-10:
            break
        Dn = _project(D + step * g / gn)
        fn = obj.value(Dn)
        if fn > f + 1e-15 * max(1.0, abs(f)):
            D = Dn
            f, g = obj.value_grad(D)
            step = min(2.0 * step, 2.0)
        else:
            step *= 0.5
    return f, D


def worst_case(controller: Controller | tuple[Plant, ArrayLike], uncertainty: NormBounded, *,
               seed=None, n_starts: int = 20) -> WorstCase:
    r"""Search ``||Delta||_2 <= 1`` for the perturbation that most destabilises ``u = K x``.

    Maximises the spectral radius (discrete time) or the spectral abscissa
    (continuous time) of ``A + H Delta E`` by projected gradient ascent
    (gradient of a simple eigenvalue, projection by clipping singular
    values; at most 200 steps per start) from

    * the boundary points along the worst-case directions: ``+-`` the polar
      factor (all singular values 1) and ``+-`` the rank-one part of the
      gradient at ``Delta = 0``, and ``+-`` the normalised real part of the
      small-gain destabiliser ``v u^H`` (``T(e^{j w*}) v = sigma u`` at the
      peak frequency of ``T = E (zI - A)^-1 H``, python-control's
      ``linfnorm``); for a scalar ``Delta`` these are the vertices ``+-1``;
    * ``n_starts`` random extreme points (polar factors of Gaussian matrices).

    A search, not a certificate: the value is a lower bound on the worst
    case (compare :func:`robust_stability` for the upper side).

    Parameters
    ----------
    controller : Controller or (Plant, (m, n) array_like)
        The gain ``K`` and the nominal plant.
    uncertainty : NormBounded
        ``[dF dG] = H Delta [EF EG]``.
    seed : None, int, SeedSequence or Generator
        For the random starts (``np.random.default_rng``).
    n_starts : int, default 20
        Number of random starts (>= 0).

    Returns
    -------
    WorstCase
        The worst ``Delta`` found, its spectral radius (abscissa), whether
        it destabilises the loop and the number of eigenvalue problems solved.

    Raises
    ------
    ValueError
        ``n_starts`` not an integer ``>= 0``; sizes that do not match the plant.
    TypeError
        ``controller`` or ``uncertainty`` of the wrong type.

    See Also
    --------
    robust_stability : the certified margin (the upper side).

    Notes
    -----
    For a simple eigenvalue ``lambda`` of ``A + H Delta E`` with right and
    left eigenvectors ``x`` and ``y``, the ascent uses [1]_

    .. math::

        \frac{\partial \lambda}{\partial \Delta} =
        \frac{(H^T \bar y)(E x)^T}{y^H x} ,

    of ``|lambda|`` (discrete) or ``Re lambda`` (continuous), and projects
    each step back onto ``||Delta||_2 <= 1`` by clipping the singular values.

    References
    ----------
    .. [1] J. H. Wilkinson, *The Algebraic Eigenvalue Problem*, Oxford 1965,
       Ch. 2 (first-order perturbation of a simple eigenvalue).

    Examples
    --------
    An LQR of a double integrator whose input gain may be off by up to
    300 %: the search finds the destabilising end, which a fine grid over
    the scalar ``Delta`` confirms:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> unc = rc.NormBounded([[0.0], [0.1]], [[0.0, 0.0]], [[3.0]])
    >>> wc = rc.worst_case(ctrl, unc)
    >>> wc.destabilizing, round(wc.radius, 5)
    (True, 1.37186)
    >>> A, H, E = ctrl.closed_loop(), unc.H, unc.EF + unc.EG @ ctrl.K
    >>> grid = max(abs(np.linalg.eigvals(A + H * d @ E)).max() for d in np.linspace(-1.0, 1.0, 201))
    >>> bool(np.isclose(wc.radius, grid, rtol=1e-9))
    True
    """
    import control

    plant, K, unc = _uncertain_loop(controller, uncertainty)
    try:
        n_starts = check_int(n_starts, "n_starts", minimum=0)
    except TypeError as exc:  # worst_case has raised ValueError for every bad n_starts: keep that type
        raise ValueError(str(exc)) from None
    rng = as_rng(seed)
    discrete = plant.is_discrete
    A, H, E = plant.F + plant.G @ K, unc.H, unc.EF + unc.EG @ K
    p, l = unc.p, unc.l
    obj = _Objective(A, H, E, discrete)
    nominal, g0 = obj.value_grad(np.zeros((p, l)))
    starts = []
    if np.any(g0):
        U, _, Vt = np.linalg.svd(g0)
        starts += [_polar(g0), np.outer(U[:, 0], Vt[0])]
    if is_stable(A, discrete=discrete) and np.any(H) and np.any(E):
        sys = control.ss(A, H, E, np.zeros((l, p)), plant.dt if discrete else 0)
        _, w = control.linfnorm(sys)
        z = np.exp(1j * w * plant.dt) if discrete else 1j * w
        Tz = E @ np.linalg.solve(z * np.eye(plant.n) - A, H)
        U, _s, Vh = np.linalg.svd(Tz)
        Dc = np.outer(Vh[0].conj(), U[:, 0].conj()).real  # Re(v u^H)
        if np.any(Dc):
            starts.append(Dc / np.linalg.norm(Dc, 2))
    starts = [sgn * S for S in starts for sgn in (1.0, -1.0)]
    starts += [_polar(rng.standard_normal((p, l))) for _ in range(n_starts)]
    best_f, best_D = nominal, np.zeros((p, l))
    for S in starts:
        f, D = _ascend(obj, S)
        if f > best_f:
            best_f, best_D = f, D
    worst = A + H @ best_D @ E
    return WorstCase(frozen(best_D), _radius(worst, discrete), not is_stable(worst, discrete=discrete), nominal,
                     obj.count)
