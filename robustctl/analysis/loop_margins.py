r"""Loop margins of a feedback loop: disk, gain and phase margins and the sensitivity peaks.

:func:`loop_margins` breaks the loop of a controller at the plant input (or
output) and measures how much gain and phase variation there the loop
tolerates: the disk margin ``alpha`` (loop-at-a-time and, for several loops,
simultaneous), the classical gain and phase margins, and the peaks of the
sensitivity ``S`` and the complementary sensitivity ``T``.

*Margin* has other meanings in this library: the ``margin`` of
:func:`robustctl.robust_stability` is a robust-stability radius (the
largest scaling of a norm-bounded uncertainty or polytope with stability
certified), and :func:`robustctl.margins_report` tabulates those radii next
to the loop margins of this module. The loop margins here are properties
of the nominal loop's frequency response.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .._validation import as_float_array, check_choice, check_real
from ..systems.controller import Controller, ControllerBatch
from ..systems.interconnect import loop_transfer
from ..systems.stability import stability_of_eigenvalues
from . import _hinfnorm
from . import _loop_kernels as kern
from ._common import _loop

__all__ = ["LoopMargins", "loop_margins", "disk_ranges"]


def disk_ranges(alpha, skew: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    r"""Gain and phase variations that a disk margin ``alpha`` with skew ``skew`` guarantees.

    The disk of multiplicative loop variations
    :math:`f = \frac{1 + \frac{1 - \sigma}{2} \delta}{1 - \frac{1 + \sigma}{2} \delta}`,
    :math:`|\delta| < \alpha`, meets the real axis at
    :math:`g_{min} = \frac{2 - \alpha (1 - \sigma)}{2 + \alpha (1 + \sigma)}` and
    :math:`g_{max} = \frac{2 + \alpha (1 - \sigma)}{2 - \alpha (1 + \sigma)}`
    (``inf`` once :math:`\alpha (1 + \sigma) \ge 2`), and contains the unit
    phasors :math:`e^{j \phi}` with
    :math:`\cos \phi \ge \frac{1 + g_{min} g_{max}}{g_{min} + g_{max}}`
    (:math:`g_{min}` when :math:`g_{max}` is infinite).

    Parameters
    ----------
    alpha : float or array_like
        Disk margins (>= 0).
    skew : float, default 0
        The skew :math:`\sigma`: 0 balanced, 1 the disk of ``S``, -1 of ``T``.

    Returns
    -------
    gain_range : ndarray (..., 2)
        ``[g_min, g_max]``: the loop gain may be scaled by any real factor in
        this range (``g_min`` floored at 0: a disk that reaches 0 allows any
        reduction).
    phase_range : ndarray (...)
        ``phi`` in degrees: any phase change in ``[-phi, phi]`` is tolerated
        (180 when the disk contains the whole unit circle).

    See Also
    --------
    loop_margins

    References
    ----------
    .. [1] P. Seiler, A. Packard, P. Gahinet, "An introduction to disk
       margins", IEEE Control Systems Magazine 40(5), 78-95, 2020.

    Examples
    --------
    MATLAB's ``dm2gm(0.6, 0.75)`` gives ``[0.6066, 2.2632]`` and 34.2267 degrees:

    >>> import numpy as np
    >>> from robustctl.analysis.loop_margins import disk_ranges
    >>> gain, phase = disk_ranges(0.6, 0.75)
    >>> bool(np.allclose(gain, [0.6066, 2.2632], atol=1e-4) and abs(phase - 34.2267) < 1e-4)
    True
    """
    a = as_float_array(alpha, "alpha")
    s = check_real(skew, "skew")
    if np.any(a < 0):
        raise ValueError(f"alpha must be >= 0, got {a.min():g}")
    with np.errstate(divide="ignore", invalid="ignore"):
        gmin = (2.0 - a * (1.0 - s)) / (2.0 + a * (1.0 + s))
        gmax = (2.0 + a * (1.0 - s)) / (2.0 - a * (1.0 + s))
        half_plane = a * (1.0 + s) == 2.0
        cos = np.where(half_plane, gmin, (1.0 + gmin * gmax) / (gmin + gmax))
    phase = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    gain = np.stack([np.maximum(gmin, 0.0), np.where(a * (1.0 + s) >= 2.0, np.inf, gmax)], axis=-1)
    return gain, phase


@dataclass(frozen=True, eq=False, repr=False)
class LoopMargins:
    r"""Result of :func:`loop_margins`: the margins of one loop, or of each loop of a stack.

    Shapes: every entry is a number for one loop transfer and an array
    (B,) for a stack of B; the loop-at-a-time entries (``alpha_loops``,
    ``gain_margin``, ``phase_margin`` and their frequencies) have a last
    axis (m,) over the m loops when there are several (m > 1), and none
    for one loop. Frequencies are in rad per time unit (``theta / dt`` in
    discrete time, ``theta`` in ``[0, pi]``); ``inf`` is ``w = inf``.

    Parameters
    ----------
    at : str
        Where the loop is broken: ``"input"``, ``"output"``, or ``"loop"``
        (a loop transfer given as it is).
    skew : float
        The skew :math:`\sigma` of the disk margins.
    dt : float or None
        Sampling time (None: continuous time).
    alpha : float or (B,) ndarray
        The disk margin: the loop stays stable for every simultaneous,
        independent variation of the m loops by factors in the disk of
        :func:`disk_ranges`, :math:`1 / \sup_\omega \mu(S + \frac{\sigma - 1}{2} I)`.
        Exact for one loop (to the level sets' ``2e-10`` relative); for
        several, a lower bound (``alpha_exact`` False): ``mu`` is replaced by
        its D-scaled upper bound on a sweep refined at its peak. 0 where the
        nominal loop is unstable.
    alpha_freq : float or (B,) ndarray
        The frequency of the peak.
    alpha_loops, alpha_loops_freq : float or ndarray
        The loop-at-a-time disk margins (one loop varied, the others closed:
        :math:`1 / \|S_{ii} + \frac{\sigma - 1}{2}\|_\infty`, exact) and their frequencies.
    alpha_exact : bool
        True for one loop (``alpha`` computed by level sets), False for
        several (``alpha`` a lower bound from the bound on ``mu``).
    gain_margin, gain_margin_freq : float or ndarray
        Classical gain margin of each loop (others closed), absolute, as
        :func:`control.stability_margins` picks it: ``1 / |l(j w)|`` at the
        crossing of the negative real axis closest to 1 in ``|log|``
        (``w = 0`` included; in discrete time ``theta = pi`` too, which
        python-control leaves out); ``inf`` with frequency NaN where ``l``
        never crosses it.
    phase_margin, phase_margin_freq : float or ndarray
        Classical phase margin in degrees, ``angle(l) mod 360 - 180`` at the
        gain crossover (``|l| = 1``, ``w > 0``) smallest in absolute value;
        ``inf`` with frequency NaN where ``|l|`` never crosses 1.
    S_peak, S_peak_freq, T_peak, T_peak_freq : float or (B,) ndarray
        :math:`\|S\|_\infty` and :math:`\|T\|_\infty` (largest singular
        value over frequency) and where they occur; ``inf`` where the loop
        is unstable.
    stable : bool or (B,) ndarray
        The nominal closed loop is stable. Where it is not, the disk margin is
        0 and the peaks are ``inf``, while the classical margins are still
        those of the frequency response of ``l`` (they then measure the
        distance to the boundary that the loop has already crossed, not a
        robustness).
    reason : str or (B,) ndarray
        ``"ok"``, ``"unstable"``, ``"ill-posed"`` (``I + L(inf)`` is singular:
        every entry NaN) or ``"not finite"`` (a NaN or infinite entry in the
        data: every entry NaN).

    Attributes
    ----------
    gain_range : ndarray (..., 2)
        ``[g_min, g_max]``: the real gain factors that ``alpha`` guarantees (:func:`disk_ranges`).
    phase_range : float or ndarray
        ``phi`` in degrees: the phase changes in ``[-phi, phi]`` that ``alpha`` guarantees.

    See Also
    --------
    loop_margins : makes it.

    Examples
    --------
    Seiler, Packard & Gahinet's first example: a disk margin of 0.46, that is
    gains from 0.63 to 1.59 and +-25.8 degrees at once:

    >>> import control
    >>> import robustctl as rc
    >>> m = rc.loop_margins(control.tf(25, [1, 10, 10, 10]))
    >>> round(m.alpha, 2), m.gain_range.round(2).tolist(), round(m.phase_range, 1)
    (0.46, [0.63, 1.59], 25.8)
    """

    at: str
    skew: float
    dt: float | None
    alpha: Any
    alpha_freq: Any
    alpha_loops: Any
    alpha_loops_freq: Any
    alpha_exact: bool
    gain_margin: Any
    gain_margin_freq: Any
    phase_margin: Any
    phase_margin_freq: Any
    S_peak: Any
    S_peak_freq: Any
    T_peak: Any
    T_peak_freq: Any
    stable: Any
    reason: Any

    @property
    def gain_range(self) -> np.ndarray:
        """``[g_min, g_max]`` (..., 2) that ``alpha`` guarantees for ``skew`` (:func:`disk_ranges`)."""
        return disk_ranges(np.nan_to_num(self.alpha, nan=0.0), self.skew)[0]

    @property
    def phase_range(self) -> Any:
        """``phi`` (degrees) with ``[-phi, phi]`` guaranteed by ``alpha`` for ``skew`` (:func:`disk_ranges`)."""
        phase = disk_ranges(np.nan_to_num(self.alpha, nan=0.0), self.skew)[1]
        return float(phase) if np.ndim(phase) == 0 else phase

    def __repr__(self) -> str:
        if np.ndim(self.alpha) == 0:
            g = self.gain_range
            return (f"LoopMargins(at={self.at!r}, skew={self.skew:g}, alpha={self.alpha:.4g} "
                    f"(gain {g[0]:.4g} to {g[1]:.4g}, phase +-{self.phase_range:.4g} deg), "
                    f"gain_margin={_short(self.gain_margin)}, phase_margin={_short(self.phase_margin)}, "
                    f"S_peak={self.S_peak:.4g}, T_peak={self.T_peak:.4g}, reason={self.reason!r})")
        ok = np.asarray(self.reason) == "ok"
        alpha = np.asarray(self.alpha)[ok]
        spread = (f"alpha min {alpha.min():.4g} median {np.median(alpha):.4g} max {alpha.max():.4g}"
                  if alpha.size else "no stable loop")
        return (f"LoopMargins(at={self.at!r}, skew={self.skew:g}, {len(ok)} loops, {int(ok.sum())} stable: "
                f"{spread})")


def _shaped(value: np.ndarray, siso: bool, single: bool) -> Any:
    """An entry of :func:`_analyse` without the loop axis for one loop and without the stack axis for one design."""
    if value.ndim == 2 and siso:
        value = value[:, 0]
    if not single:
        return value
    return value[0].item() if value.ndim == 1 else value[0]


def _short(x) -> str:
    return f"{x:.4g}" if np.ndim(x) == 0 else np.array2string(np.asarray(x), precision=4)


# ---------------------------------------------------------------- the loop transfer
def _from_lti(L) -> tuple[tuple[np.ndarray, ...], float | None]:
    """``((A, B, C, D) stacks of one, dt)`` of a python-control system."""
    import control

    sys = control.ss(L)
    m_in, m_out = sys.ninputs, sys.noutputs
    if m_in != m_out:
        raise ValueError(f"L must be square (as many inputs as outputs: the loop is closed by -I), "
                         f"got {m_out} outputs and {m_in} inputs")
    dt = sys.dt
    if dt is True:
        dt = 1.0
    dt = None if dt is None or dt == 0 else float(dt)
    A, B, C, D = (np.asarray(M, dtype=float).reshape(shape) for M, shape in
                  ((sys.A, (sys.nstates, sys.nstates)), (sys.B, (sys.nstates, m_in)),
                   (sys.C, (m_out, sys.nstates)), (sys.D, (m_out, m_in))))
    return (A[None], B[None], C[None], D[None]), dt


def _from_controller(ctrl, at: str) -> tuple[tuple[np.ndarray, ...], float | None, bool]:
    """``((A, B, C, D) stacks, dt, single)`` of the loop transfers of a controller, a batch or ``(plant, K)``.

    :func:`robustctl.systems.interconnect.loop_transfer`: at the input
    ``L = -K(z) P(z)``, at the output ``L = -P(z) K(z)``; a state feedback
    ``u = K x`` reads the state (``C = I``, ``D = 0``).
    """
    if isinstance(ctrl, (Controller, ControllerBatch)):
        batch = ctrl.as_batch() if isinstance(ctrl, Controller) else ctrl
        plant, (Ac, Bc, Cc, Dc) = batch.plant, (batch.Ac, batch.Bc, batch.Cc, batch.Dc)
        single = isinstance(ctrl, Controller)
    else:
        try:
            plant, K = _loop(ctrl, batch=True)
        except TypeError:
            raise TypeError("ctrl must be a robustctl.Controller, a ControllerBatch, a (Plant, K) pair or a "
                            f"python-control system (the loop transfer L), got {type(ctrl).__name__}") from None
        single = K.ndim == 2
        Dc = K[None] if single else K
        B, m, n = Dc.shape
        plant = replace(plant, C=None, D=None) if plant.has_outputs else plant   # u = K x reads the state
        Ac, Bc, Cc = np.zeros((B, 0, 0)), np.zeros((B, 0, n)), np.zeros((B, m, 0))
    C, D = plant.output_matrices()
    return loop_transfer(plant.F, plant.G, C, D, Ac, Bc, Cc, Dc, at), plant.dt, single


# ---------------------------------------------------------------- the analysis
def _analyse(A, B, C, D, *, discrete: bool, skew: float, what: str = "all") -> dict[str, np.ndarray]:
    """Every entry of :class:`LoopMargins` for stacks ``(A, B, C, D)`` of loop transfers.

    ``what="disk"``: the disk margins only (the peaks and classical margins stay NaN).

    Arrays (K,) and (K, m) (the loop axis kept); frequencies in rad per
    sample (``theta``) if ``discrete``.
    """
    K, n, m = A.shape[0], A.shape[-1], D.shape[-1]
    finite = np.isfinite(A).all(axis=(1, 2)) & np.isfinite(B).all(axis=(1, 2)) \
        & np.isfinite(C).all(axis=(1, 2)) & np.isfinite(D).all(axis=(1, 2))
    if not finite.all():
        A, B, C, D = (np.where(finite[:, None, None], M, 0.0) for M in (A, B, C, D))
    As, Bs, Cs, Ds, posed = kern.sensitivity(A, B, C, D)
    if n:
        lam = _hinfnorm.eigvals(As)
        stable = stability_of_eigenvalues(lam, discrete=discrete)[1]
    else:
        lam, stable = np.zeros((K, 0), dtype=complex), np.ones(K, dtype=bool)
    reason = np.where(stable, "ok", "unstable").astype("<U10")
    reason[~posed] = "ill-posed"
    reason[~finite] = "not finite"
    valid = finite & posed
    ok = valid & stable

    out = {key: np.full(K, np.nan) for key in ("alpha", "alpha_freq", "S_peak", "S_peak_freq", "T_peak",
                                               "T_peak_freq")}
    out |= {key: np.full((K, m), np.nan) for key in ("alpha_loops", "alpha_loops_freq", "gain_margin",
                                                    "gain_margin_freq", "phase_margin", "phase_margin_freq")}
    unstable = valid & ~stable
    for key in ("alpha", "alpha_loops"):
        out[key][unstable] = 0.0
    for key in ("S_peak", "T_peak"):
        out[key][unstable] = np.inf
    shift = 0.5 * (skew - 1.0)
    idx = np.flatnonzero(ok)
    if idx.size:
        a, b, c, d, poles = As[idx], Bs[idx], Cs[idx], Ds[idx], lam[idx]
        if what == "all" or m > 1:        # the multi-loop sweep starts from the S peak's frequency too
            g, w, _ = _hinfnorm.hinf_norm(a, b, c, discrete=discrete, poles=poles, D=d)
            out["S_peak"][idx], out["S_peak_freq"][idx] = g, w
        if what == "all":
            g, w, _ = _hinfnorm.hinf_norm(a, b, -c, discrete=discrete, poles=poles, D=np.eye(m) - d)
            out["T_peak"][idx], out["T_peak_freq"][idx] = g, w
        rows = _loops(a, b, c, d)
        dl = rows[3] + shift
        g, w, _ = _hinfnorm.hinf_norm(rows[0], rows[1], rows[2], discrete=discrete,
                                     poles=np.repeat(poles, m, axis=0), D=dl)
        with np.errstate(divide="ignore"):
            out["alpha_loops"][idx] = (1.0 / g).reshape(-1, m)
        out["alpha_loops_freq"][idx] = w.reshape(-1, m)
        if m == 1:
            out["alpha"][idx], out["alpha_freq"][idx] = out["alpha_loops"][idx, 0], out["alpha_loops_freq"][idx, 0]
        else:
            extra = np.concatenate([out["alpha_loops_freq"][idx], out["S_peak_freq"][idx, None]], axis=1)
            mu, w = kern.mu_peak(a, b, c, d + shift * np.eye(m), discrete=discrete, lam=poles, extra=extra)
            with np.errstate(divide="ignore"):
                out["alpha"][idx] = 1.0 / mu
            out["alpha_freq"][idx] = w
    idx = np.flatnonzero(valid) if what == "all" else np.zeros(0, dtype=int)
    if idx.size:
        rows = _loops(As[idx], Bs[idx], Cs[idx], Ds[idx])
        gm, wg, pm, wp = kern.classical(*rows, discrete=discrete)
        for key, v in (("gain_margin", gm), ("gain_margin_freq", wg), ("phase_margin", pm),
                       ("phase_margin_freq", wp)):
            out[key][idx] = v.reshape(-1, m)
    out["stable"], out["reason"] = stable & valid, reason
    return out


def _loops(A, B, C, D):
    """The SISO rows ``S_ii`` (K m, ...) of sensitivity stacks: ``(A, B[:, :, i], C[:, i], D[:, i, i])``."""
    K, n, m = A.shape[0], A.shape[-1], D.shape[-1]
    return (np.repeat(A, m, axis=0), np.moveaxis(B, 2, 1).reshape(K * m, n)[:, :, None],
            C.reshape(K * m, 1, n), np.diagonal(D, axis1=1, axis2=2).reshape(K * m, 1, 1))


_FREQS = ("alpha_freq", "alpha_loops_freq", "gain_margin_freq", "phase_margin_freq", "S_peak_freq", "T_peak_freq")


def loop_margins(ctrl, at: str | None = None, skew: float = 0.0, *, what: str = "all") -> LoopMargins:
    r"""Disk, gain and phase margins and sensitivity peaks of a feedback loop, or of a stack of loops.

    Parameters
    ----------
    ctrl : Controller, ControllerBatch, (Plant, K) pair, or python-control system
        The loop: a :class:`~robustctl.Controller` with its plant (state
        feedback ``u = K x`` or dynamic output feedback ``u = K(z) y``), a
        :class:`~robustctl.ControllerBatch` (a stack), a pair ``(plant, K)``
        of state feedbacks with one gain ``K`` (m, n) or a stack (B, m, n)
        (as :func:`~robustctl.robust_stability` takes it), or a loop
        transfer ``L`` (python-control ``StateSpace`` or ``TransferFunction``,
        square, in python-control's negative-feedback convention: the loop
        is closed by ``u = -y``; continuous if ``L.dt`` is 0 or None).
    at : {"input", "output"}, optional
        Where a controller's loop is broken (default ``"input"``): at the
        plant input (m loops) or at its measured output (p loops; the state
        for a state feedback: n loops). Not for a loop transfer ``L``, which
        is analysed as it is.
    skew : float, default 0
        The skew :math:`\sigma` of the disk margin: 0 balanced (gain
        increase and decrease alike), 1 based on ``S`` (the distance of the
        Nyquist plot to -1), -1 based on ``T``.
    what : {"all", "disk"}
        ``"disk"`` computes the disk margins alone (``alpha``, ``alpha_loops``
        and their frequencies; the other fields are NaN): what a tuning goal
        on the disk margin needs, in about half the time.

    Returns
    -------
    LoopMargins
        ``alpha`` (with ``gain_range`` and ``phase_range``), ``alpha_loops``,
        ``gain_margin``, ``phase_margin``, ``S_peak``, ``T_peak``, their
        frequencies, ``stable`` and ``reason``; numbers for one loop, arrays
        (B,) for a stack (the attributes' docstrings give the shapes).

    Raises
    ------
    TypeError
        ``ctrl`` is none of the above, or ``at`` is given with a loop transfer.
    ValueError
        Wrong shapes (``K`` not (m, n) or (B, m, n); ``L`` not square),
        ``at`` not ``"input"`` or ``"output"``, ``skew`` not a finite number.

    See Also
    --------
    robust_stability : robust-stability radius (``margin``) against a model of the uncertainty.
    disk_ranges : gain and phase ranges of a disk margin.

    Notes
    -----
    **Sign convention.** Our controllers use :math:`u = K x` and
    :math:`u = K(z) y` (no minus sign). Broken at the plant input, the
    signal that returns to the break is :math:`K(z) P(z) v` (:math:`P: u \to y`);
    in the negative-feedback convention of python-control (and of every
    margin formula) the loop transfer is therefore

    .. math::
        L(z) = -K(z) P(z) \quad \text{(input)}, \qquad
        L(z) = -P(z) K(z) \quad \text{(output)},

    for a state feedback :math:`L(z) = -K (zI - F)^{-1} G` at the input (and
    :math:`-(zI - F)^{-1} G K` at the state). A python-control gain
    ``K_pc`` (``u = -K_pc x``) gives the same loop with
    ``L = K_pc (zI - F)^{-1} G``. Then :math:`S = (I + L)^{-1}` and
    :math:`T = L (I + L)^{-1} = I - S`.

    **Disk margin** [1]_. The loop stays stable when each loop's gain is
    multiplied by any :math:`f_i` with
    :math:`f_i = \frac{1 + \frac{1 - \sigma}{2} \delta_i}{1 - \frac{1 + \sigma}{2} \delta_i}`,
    :math:`|\delta_i| < \alpha`, iff

    .. math::
        \alpha \le \frac{1}{\sup_\omega \mu_\Delta\left(S(j\omega) + \frac{\sigma - 1}{2} I\right)}

    with :math:`\Delta` diagonal and complex. For one loop
    :math:`\mu = |\cdot|` and :math:`\alpha = 1 / \|S + \frac{\sigma - 1}{2}\|_\infty`,
    computed exactly (not on a grid) by the level-set H-infinity norm
    (imaginary-axis eigenvalues of a Hamiltonian; Bruinsma & Steinbuch
    1990) that :func:`~robustctl.robust_stability` uses; the loop-at-a-time
    margins use :math:`S_{ii}`, the sensitivity of loop ``i`` with the
    others closed. For several loops :math:`\mu` is replaced by its
    upper bound :math:`\min_D \bar\sigma(D M D^{-1})` over positive
    diagonal :math:`D` (exact for two loops, where it has a closed form, and
    equal to :math:`\mu` for up to three loops [2]_; a convex minimisation
    otherwise), on a frequency sweep refined by golden-section search at
    its peak: ``alpha`` is then a lower bound of the disk margin.

    **Classical margins** without a grid. With :math:`l = 1 / S_{ii} - 1`
    the loop seen by loop ``i``, :math:`l(j\omega)` is real where
    :math:`\operatorname{Im} S_{ii}(j\omega) = 0` and :math:`|l| = 1` where
    :math:`\operatorname{Re} S_{ii}(j\omega) = \frac{1}{2}`; these frequencies
    are the imaginary-axis zeros of :math:`S_{ii}(s) \mp S_{ii}(-s) - c`,
    i.e. eigenvalues of a pencil of twice the loop's order (discrete loops
    through the bilinear transform), polished by Newton's method.

    **Peaks.** :math:`\|S\|_\infty` and :math:`\|T\|_\infty` by the same
    level sets; for one loop :math:`1 / \|S\|_\infty` is the distance of
    the Nyquist plot to -1 (python-control's stability margin ``sm``).

    References
    ----------
    .. [1] P. Seiler, A. Packard, P. Gahinet, "An introduction to disk
       margins", IEEE Control Systems Magazine 40(5), 78-95, 2020.
    .. [2] J. C. Doyle, "Analysis of feedback systems with structured
       uncertainties", IEE Proceedings D 129(6), 242-250, 1982.
    .. [3] N. A. Bruinsma, M. Steinbuch, "A fast algorithm to compute the
       H-infinity-norm of a transfer function matrix", Systems & Control
       Letters 14(4), 287-293, 1990.

    Examples
    --------
    The LQR of a sampled double integrator, broken at its input; the same
    loop built by hand with python-control (``L = -K (zI - F)^-1 G``) has the
    same phase margin:

    >>> import control
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> ctrl = rc.lqr(plant)
    >>> m = rc.loop_margins(ctrl)
    >>> round(m.alpha, 3), round(m.phase_margin, 2)
    (1.243, 67.07)
    >>> L = control.ss(plant.F, plant.G, -ctrl.K, 0, 0.1)
    >>> gm, pm = control.stability_margins(L)[:2]
    >>> bool(abs(pm - m.phase_margin) < 1e-8)
    True
    """
    import control

    if isinstance(ctrl, (control.StateSpace, control.TransferFunction)):
        if at is not None:
            raise TypeError("at applies to a controller; a loop transfer L is analysed as it is (leave at unset)")
        (A, B, C, D), dt = _from_lti(ctrl)
        single, where = True, "loop"
    else:
        where = "input" if at is None else check_choice(at, "at", ("input", "output"))
        (A, B, C, D), dt, single = _from_controller(ctrl, where)
    s = check_real(skew, "skew")
    out = _analyse(A, B, C, D, discrete=dt is not None, skew=s, what=check_choice(what, "what", ("all", "disk")))
    if dt is not None:
        for key in _FREQS:
            out[key] = out[key] / dt
    m = D.shape[-1]
    fields = {key: _shaped(value, m == 1, single) for key, value in out.items()}
    return LoopMargins(at=where, skew=s, dt=dt, alpha_exact=m == 1, **fields)
