r"""The performance output of a quadratic cost: ``z = Cz x + Dzu u`` with ``|z|^2 = x'Qx + u'Ru``.

An LQ cost ``sum_k x'Qx + u'Ru`` is the energy of the output

.. math::

    z = \begin{bmatrix} Q^{1/2} \\ 0 \end{bmatrix} x
      + \begin{bmatrix} 0 \\ R^{1/2} \end{bmatrix} u ,
    \qquad C_z'C_z = Q,\quad D_{zu}'D_{zu} = R,\quad C_z'D_{zu} = 0,

the form the H-infinity and H2 syntheses (:func:`robustctl.hinf`,
:func:`robustctl.h2`) and :func:`robustctl.synthesis.hinf_riccati.hinf_riccati` take
their criterion in. :func:`lq_output` builds it.

References
----------
K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*, Prentice
Hall 1996, Sec. 14.1 (the LQ cost as the energy of ``z``, with
``Dzu'[Cz Dzu] = [0 I]`` after scaling).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .._validation import as_matrix, check_spd

__all__ = ["lq_output"]


def _sqrt_psd(M: np.ndarray) -> np.ndarray:
    """Symmetric square root of a symmetric PSD matrix (entrywise for a diagonal one)."""
    if not np.any(M - np.diag(np.diag(M))):
        return np.diag(np.sqrt(np.maximum(np.diag(M), 0.0)))
    w, V = np.linalg.eigh(M)
    root = (V * np.sqrt(np.maximum(w, 0.0))) @ V.T
    return 0.5 * (root + root.T)


def lq_output(Q: ArrayLike, R: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    r"""``(Cz, Dzu)`` of the output ``z = [Q^{1/2} x; R^{1/2} u]`` whose energy is the LQ cost.

    ``Cz = [Q^{1/2}; 0]`` (``(n + m, n)``) and ``Dzu = [0; R^{1/2}]``
    (``(n + m, m)``), so that ``Cz'Cz = Q``, ``Dzu'Dzu = R`` and
    ``Cz'Dzu = 0`` (module docstring).

    ``M^{1/2}`` is the symmetric positive semidefinite square root
    ``V diag(sqrt(lambda)) V'`` from the eigendecomposition
    ``M = V diag(lambda) V'``; it exists for every PSD matrix, also a
    singular one, where a Cholesky factor may not. A diagonal weight gets
    the entrywise square root of its diagonal, exactly.

    Parameters
    ----------
    Q : (n, n) array_like
        State weight, symmetric positive semidefinite.
    R : (m, m) array_like or float
        Input weight, symmetric positive semidefinite (the syntheses need
        it positive definite).

    Returns
    -------
    Cz : (n + m, n) ndarray
    Dzu : (n + m, m) ndarray

    Raises
    ------
    ValueError
        ``Q`` or ``R`` not square, not symmetric or not positive semidefinite.

    See Also
    --------
    robustctl.hinf, robustctl.h2 : take the criterion as ``(Cz, Dzu)``.

    Notes
    -----
    For every ``x`` and ``u``

    .. math::

        \|C_z x + D_{zu} u\|^2 = x^T Q x + u^T R u ,

    since ``Cz'Cz = Q``, ``Dzu'Dzu = R`` and ``Cz'Dzu = 0``: the LQ cost is
    the energy (squared 2-norm) of ``z`` [1]_.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall 1996, Sec. 14.1.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> Cz, Dzu = rc.lq_output(np.diag([4.0, 9.0]), [[16.0]])
    >>> Cz
    array([[2., 0.],
           [0., 3.],
           [0., 0.]])
    >>> Dzu.ravel()
    array([0., 0., 4.])

    A weight with coupling gets its symmetric square root; the energy of
    ``z`` is the cost:

    >>> Q = np.array([[2.0, 1.0], [1.0, 2.0]])
    >>> Cz, Dzu = rc.lq_output(Q, [[0.5]])
    >>> x, u = np.array([0.3, -1.2]), np.array([2.0])
    >>> bool(np.isclose(np.sum((Cz @ x + Dzu @ u) ** 2), x @ Q @ x + 0.5 * u @ u))
    True
    """
    Qa = check_spd(as_matrix(Q, "Q"), "Q", semidefinite=True)
    Ra = check_spd(as_matrix(R, "R"), "R", semidefinite=True)
    n, m = Qa.shape[0], Ra.shape[0]
    Cz = np.vstack([_sqrt_psd(Qa), np.zeros((m, n))])
    Dzu = np.vstack([np.zeros((n, m)), _sqrt_psd(Ra)])
    return Cz, Dzu
