r"""The discrete covariance of a continuous white noise over one sample (Van Loan's method)."""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .._validation import as_matrix, check_positive_scalar, check_spd, check_square

__all__ = ["noise_covariance"]


def noise_covariance(A, Bw, W, dt: float) -> np.ndarray:
    r"""The covariance ``Wd`` of the process noise of a sampled plant driven by continuous white noise.

    For ``dx/dt = A x + Bw w`` with ``w`` white of intensity ``W``
    (``E w(t) w(s)' = W delta(t - s)``), the sampled state obeys
    ``x[k+1] = F x[k] + v[k]`` with ``F = e^{A dt}`` and ``v[k]`` white with
    covariance ``Wd`` below; a discrete plant with ``Bw = I`` and ``W = Wd``
    is its exact model (e.g. for :func:`robustctl.kalman`).

    Parameters
    ----------
    A : (n, n) array_like
        Continuous state matrix.
    Bw : (n, nw) array_like
        Noise input matrix (a 1-D array is one column).
    W : (nw, nw) array_like or float
        Noise intensity, symmetric positive semidefinite.
    dt : float
        Sampling time, positive.

    Returns
    -------
    Wd : (n, n) ndarray
        Symmetric positive semidefinite.

    Raises
    ------
    ValueError
        Shapes that do not match (named), ``W`` not symmetric positive
        semidefinite, ``dt <= 0``.

    Notes
    -----
    .. math::

        W_d = \int_0^{dt} e^{A s} B_w W B_w' e^{A' s}\, ds .

    Van Loan's method takes it from one matrix exponential,

    .. math::

        \exp\left(\begin{bmatrix} -A & B_w W B_w' \\ 0 & A' \end{bmatrix} dt\right)
        = \begin{bmatrix} \cdot & E_{12} \\ 0 & E_{22} \end{bmatrix},
        \qquad W_d = E_{22}' E_{12} .

    References
    ----------
    .. [1] C. F. Van Loan, "Computing integrals involving the matrix
       exponential", IEEE Trans. Automatic Control 23(3), 395-404, 1978.

    Examples
    --------
    A scalar plant ``dx/dt = a x + w`` has ``Wd = W (e^{2 a dt} - 1) / (2 a)``:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> a, W, dt = -2.0, 3.0, 0.1
    >>> Wd = rc.noise_covariance([[a]], [[1.0]], [[W]], dt)
    >>> bool(np.isclose(Wd[0, 0], W * (np.exp(2 * a * dt) - 1) / (2 * a), rtol=1e-12))
    True
    """
    A = check_square(as_matrix(A, "A"), "A")
    n = A.shape[0]
    Bw = as_matrix(Bw, "Bw", rows=n, vector="column", rows_what="the number of states, from A")
    W = check_spd(as_matrix(W, "W", rows=Bw.shape[1], cols=Bw.shape[1], rows_what="columns of Bw",
                            cols_what="columns of Bw"), "W", semidefinite=True)
    dt = check_positive_scalar(dt, "dt")
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -A, Bw @ W @ Bw.T, A.T
    E = scipy.linalg.expm(M * dt)
    Wd = E[n:, n:].T @ E[:n, n:]
    return 0.5 * (Wd + Wd.T)
