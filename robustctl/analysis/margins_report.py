"""Certified robust-stability margins of several controllers against named uncertainty models, and their loop margins.

:func:`margins_report` runs :func:`robustctl.robust_stability` for
every (controller, model) pair and :func:`robustctl.loop_margins` for every
controller (its nominal loop broken at the plant input), and returns a
:class:`MarginsReport`, two small tables with text, Markdown and CSV writers.
The two kinds of margin differ: the robust-stability margin is a radius of a
model of the uncertainty; the loop margins (disk, gain and phase margins,
sensitivity peaks) are properties of the nominal loop's frequency response. A model is a norm-bounded
uncertainty ``[dF dG] = H Delta [EF EG]`` (margin: the largest ``r`` with
stability certified for every ``||Delta|| <= r``, the small-gain value
``1 / ||E (zI - A)^-1 H||_inf``) or a polytope, given by its vertices besides
the nominal plant (margin: the largest scaling of the polytope about the
nominal plant with a common quadratic Lyapunov function); ``margin >= 1``
certifies the whole model. A law with input memory
(:class:`robustctl.InputMemoryFeedback`) is checked as the static gain
``[K K_input]`` on the plant, vertices and uncertainty augmented by the
previous input (:func:`robustctl.systems.input_memory.with_input_memory`).

References
----------
S. Boyd, L. El Ghaoui, E. Feron, V. Balakrishnan, *Linear Matrix
Inequalities in System and Control Theory*, SIAM 1994, Sec. 5.1 (quadratic
stability of polytopic and norm-bounded systems).
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike

from ..errors import RobustCtlError
from ..systems.controller import Controller
from ..systems.input_memory import InputMemoryFeedback
from ..systems.plant import Plant, check_plant
from ..systems.uncertainty import NormBounded
from .loop_margins import LoopMargins, loop_margins

if TYPE_CHECKING:                      # robustctl.analysis re-exports this module: import it lazily
    from .results import RobustStability

__all__ = ["MarginsReport", "margins_report"]

_TITLE = ("Certified robust-stability margins (robustctl.robust_stability): the largest r with stability "
          "certified for r x the uncertainty; >= 1 certifies it all")
_LOOP_TITLE = ("Loop margins at the plant input (robustctl.loop_margins, skew 0): disk margin with the gains and "
               "phases it allows at once; classical gain and phase margins; peaks of S and T")
_LOOP_COLUMNS = ("disk margin", "disk gains", "disk phase [deg]", "gain margin", "phase margin [deg]", "S peak",
                 "T peak")


@dataclass(frozen=True, eq=False, repr=False)
class MarginsReport:
    """Result of :func:`margins_report`: one certificate per controller and model, and each controller's loop margins.

    Parameters
    ----------
    controllers : tuple of str
        Row names, in the order given.
    models : tuple of str
        Column names, in the order given.
    results : Mapping
        ``results[controller][model]``: the :class:`~robustctl.RobustStability`,
        or a string ``"n/a (reason)"`` where the analysis raised.
    loops : Mapping, optional
        ``loops[controller]``: the :class:`~robustctl.LoopMargins` of its
        nominal loop at the plant input, or ``"n/a (reason)"``.

    Attributes
    ----------
    margin : (controllers, models) ndarray
        The robust-stability margins (NaN where not available).
    certified : (controllers, models) bool ndarray
        ``margin >= 1`` certified.

    See Also
    --------
    margins_report : makes it.

    Examples
    --------
    One gain ``u = -0.6 x`` of a scalar plant ``x+ = 1.1 x + u`` with an
    uncertainty ``dF = 0.5 Delta``: the closed loop is ``a = 0.5`` and the
    margin the small-gain value ``1 / max |0.5 / (z - a)| = (1 - a) / 0.5 = 1``
    (at ``z = 1``); its loop ``L = 0.6 / (z - 1.1)`` crosses the negative
    real axis at ``z = -1`` with ``L = -0.6 / 2.1``, a gain margin of 3.5:

    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.1]], [[1.0]], 0.1)
    >>> report = rc.margins_report(plant, {"K": [[-0.6]]}, {"dF": rc.NormBounded([[0.5]], [[1.0]], [[0.0]])})
    >>> round(float(report.margin[0, 0]), 6), round(report.loops["K"].gain_margin, 6)
    (1.0, 3.5)
    """

    controllers: tuple[str, ...]
    models: tuple[str, ...]
    results: Mapping[str, Mapping[str, RobustStability | str]]
    loops: Mapping[str, LoopMargins | str] = field(default_factory=lambda: MappingProxyType({}))

    @property
    def margin(self) -> np.ndarray:
        """Margins, (controllers, models); NaN where not available."""
        return np.array([[np.nan if isinstance(m, str) else m.margin
                          for m in (self.results[c][k] for k in self.models)] for c in self.controllers],
                        dtype=float).reshape(len(self.controllers), len(self.models))

    @property
    def certified(self) -> np.ndarray:
        """``margin >= 1`` certified, (controllers, models) of bool; False where not available."""
        return np.array([[not isinstance(m, str) and bool(m.certified)
                          for m in (self.results[c][k] for k in self.models)] for c in self.controllers],
                        dtype=bool).reshape(len(self.controllers), len(self.models))

    def cell(self, controller: str, model: str) -> str:
        """One entry as text: the margin to 3 digits, ``(certified)`` if >= 1, or the ``n/a`` reason."""
        m = self.results[controller][model]
        return m if isinstance(m, str) else f"{m.margin:.3g}{' (certified)' if m.certified else ''}"

    def loop_cells(self, controller: str) -> tuple[str, ...]:
        """The loop-margin entries of one controller as text (the columns of :meth:`loops_to_markdown`; worst loop).

        The disk margin is the simultaneous one; the gain margin of several
        loops is the one closest to 1 (in ``|log|``), the phase margin the
        smallest in absolute value.
        """
        lm = self.loops.get(controller, "n/a (not computed)")
        if isinstance(lm, str):
            return (lm, *("" for _ in _LOOP_COLUMNS[1:]))
        g = lm.gain_range
        gm, pm = _worst_loop(lm)
        return (f"{lm.alpha:.3g}", f"{g[0]:.3g} to {g[1]:.3g}", f"+-{lm.phase_range:.3g}", f"{gm:.3g}", f"{pm:.3g}",
                f"{lm.S_peak:.3g}", f"{lm.T_peak:.3g}")

    def to_text(self) -> str:
        """Fixed-width tables with title lines (for a terminal or a log): the margins, then the loop margins."""
        wn = max(18, *(len(c) + 1 for c in self.controllers))
        wm = max(26, *(len(k) + 2 for k in self.models))
        head = f"{'controller':<{wn}}" + "".join(f"{k:>{wm}}" for k in self.models)
        lines = [_TITLE, head, "-" * len(head)]
        lines += [f"{c:<{wn}}" + "".join(f"{self.cell(c, k):>{wm}}" for k in self.models) for c in self.controllers]
        if self.loops:
            head = f"{'controller':<{wn}}" + "".join(f"{k:>20}" for k in _LOOP_COLUMNS)
            lines += ["", _LOOP_TITLE, head, "-" * len(head)]
            lines += [f"{c:<{wn}}" + "".join(f"{v:>20}" for v in self.loop_cells(c)) for c in self.controllers]
        return "\n".join(lines)

    def to_markdown(self) -> str:
        """A Markdown table: one row per controller, one column per model (ends with a newline)."""
        lines = ["| controller | " + " | ".join(self.models) + " |", "|---|" + "---:|" * len(self.models)]
        lines += [f"| {c} | " + " | ".join(self.cell(c, k) for k in self.models) + " |" for c in self.controllers]
        return "\n".join(lines) + "\n"

    def loops_to_markdown(self) -> str:
        """The loop margins as a Markdown table: one row per controller (ends with a newline)."""
        lines = ["| controller | " + " | ".join(_LOOP_COLUMNS) + " |", "|---|" + "---:|" * len(_LOOP_COLUMNS)]
        lines += [f"| {c} | " + " | ".join(self.loop_cells(c)) + " |" for c in self.controllers]
        return "\n".join(lines) + "\n"

    def to_csv(self, path: str | os.PathLike | None = None) -> str:
        r"""CSV ``controller,uncertainty,margin,certified``, one row per pair; written to ``path`` if given.

        Margins to 6 significant digits; both fields empty where not
        available. Lines end with ``\r\n`` (RFC 4180, Python's csv default).
        """
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["controller", "uncertainty", "margin", "certified"])
        for c in self.controllers:
            for k in self.models:
                m = self.results[c][k]
                w.writerow([c, k, "" if isinstance(m, str) else f"{m.margin:.6g}",
                            "" if isinstance(m, str) else bool(m.certified)])
        return _written(buf.getvalue(), path)

    def loops_to_csv(self, path: str | os.PathLike | None = None) -> str:
        r"""CSV of the loop margins, one row per controller; written to ``path`` if given.

        Columns ``controller,disk_margin,disk_gain_min,disk_gain_max,disk_phase_deg,gain_margin,phase_margin_deg,
        S_peak,T_peak`` (the entries of :meth:`loop_cells`, to 6 significant digits); empty where not available.
        """
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["controller", "disk_margin", "disk_gain_min", "disk_gain_max", "disk_phase_deg", "gain_margin",
                    "phase_margin_deg", "S_peak", "T_peak"])
        for c in self.controllers:
            lm = self.loops.get(c)
            if not isinstance(lm, LoopMargins):
                w.writerow([c, *("" for _ in range(8))])
                continue
            gm, pm = _worst_loop(lm)
            w.writerow([c, *(f"{v:.6g}" for v in (lm.alpha, *lm.gain_range, lm.phase_range, gm, pm, lm.S_peak,
                                                  lm.T_peak))])
        return _written(buf.getvalue(), path)

    def __repr__(self) -> str:
        return (f"MarginsReport(controllers={len(self.controllers)}, models={list(self.models)},\n"
                f"margin=\n{np.array2string(self.margin, precision=4)})")


def _worst_loop(lm: LoopMargins) -> tuple[float, float]:
    """The gain margin closest to 1 (in ``|log|``) and the phase margin smallest in absolute value over the loops."""
    gm, pm = np.atleast_1d(lm.gain_margin), np.atleast_1d(lm.phase_margin)
    with np.errstate(divide="ignore"):
        g = gm[np.argmin(np.where(np.isnan(gm), np.inf, np.abs(np.log(gm))))]
    return float(g), float(pm[np.argmin(np.where(np.isnan(pm), np.inf, np.abs(pm)))])


def _written(text: str, path: str | os.PathLike | None) -> str:
    if path is not None:
        with open(Path(path), "w", newline="") as fh:
            fh.write(text)
    return text


def _model(name: str, model) -> NormBounded | list[Plant]:
    if isinstance(model, NormBounded):
        return model
    if isinstance(model, (str, bytes)) or not isinstance(model, Sequence) or not model \
            or not all(isinstance(v, Plant) for v in model):
        raise TypeError(f"models[{name!r}] must be a NormBounded or a non-empty sequence of Plant "
                        f"(the polytope's vertices besides the plant), got {type(model).__name__}")
    return list(model)


def _law(name: str, law, plant: Plant) -> InputMemoryFeedback | Controller:
    """A law with input memory, or a dynamic controller of ``plant`` (analysed as its augmented loop)."""
    if isinstance(law, InputMemoryFeedback):
        return law
    if isinstance(law, Controller):
        if law.K is None:
            return Controller.dynamic(*law._matrices(), law.method, plant)
        return InputMemoryFeedback(law.K)
    try:
        return InputMemoryFeedback(law)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"controllers[{name!r}]: {exc}") from None


def margins_report(plant: Plant, controllers: Mapping[str, ArrayLike | Controller | InputMemoryFeedback],
                   models: Mapping[str, NormBounded | Sequence[Plant]]) -> MarginsReport:
    """Certified robust-stability margins of each controller against each named uncertainty model, and loop margins.

    For every pair, :func:`robustctl.robust_stability` of the loop
    ``(plant, K)`` (module docstring): ``uncertainty=model`` for a
    :class:`~robustctl.NormBounded`, ``vertices=model`` for a sequence of
    plants. For every controller, :func:`robustctl.loop_margins` of its
    nominal loop broken at the plant input (a law with input memory: on the
    plant augmented by the previous input, where ``u`` is still the loop's
    input). An analysis that raises (:class:`~robustctl.RobustCtlError`
    or ``ValueError``, e.g. an infeasible certificate) is reported as
    ``"n/a (reason)"`` instead of stopping the report.

    Parameters
    ----------
    plant : Plant
        The nominal plant the controllers were designed for.
    controllers : Mapping of str to (m, n) array_like, Controller or InputMemoryFeedback
        Named gains ``u = K x``, laws with input memory or dynamic output
        feedbacks (analysed with ``plant``), in row order.
    models : Mapping of str to NormBounded or sequence of Plant
        Named uncertainty models, in column order; a sequence of plants is
        a polytope's vertices besides ``plant``.

    Returns
    -------
    MarginsReport
        ``margin`` and ``certified`` arrays (controllers, models), ``loops``
        (the :class:`~robustctl.LoopMargins` of each controller) and the
        writers ``to_text()`` (both tables), ``to_markdown()``,
        ``to_csv(path)``, ``loops_to_markdown()``, ``loops_to_csv(path)``.

    Examples
    --------
    Two LQR gains of the paper's truck against a payload polytope and a
    norm-bounded steering uncertainty; the norm-bounded margin is the
    small-gain value, checked on a frequency grid:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> unc = rc.NormBounded(plant.G, [[0.1, 0.0, 0.0, 0.0]], [[0.1]])
    >>> report = rc.margins_report(plant, {"LQR": rc.lqr(plant).K, "slow": 0.3 * rc.lqr(plant).K},
    ...                            {"payload 0-300 %": [truck_plant(300.0)], "steering": unc})
    >>> report.margin.shape, bool(report.certified[0, 0])
    ((2, 2), True)
    >>> A, E = plant.F + plant.G @ rc.lqr(plant).K, unc.EF + unc.EG @ rc.lqr(plant).K
    >>> peak = max(abs(E @ np.linalg.solve(z * np.eye(4) - A, unc.H)).item()
    ...            for z in np.exp(1j * np.linspace(0.0, np.pi, 20001)))
    >>> bool(abs(report.margin[0, 1] * peak - 1.0) < 1e-4)
    True
    >>> print(report.to_markdown().splitlines()[0])
    | controller | payload 0-300 % | steering |

    The loop margins of the LQR, its loop built by hand for python-control
    (``u = K x``: ``L = -K (zI - F)^-1 G``):

    >>> import control
    >>> L = control.ss(plant.F, plant.G, -rc.lqr(plant).K, 0, plant.dt)
    >>> bool(abs(control.stability_margins(L)[1] - report.loops["LQR"].phase_margin) < 1e-6)
    True
    >>> print(report.loops_to_markdown().splitlines()[2])
    | LQR | 1.07 | 0.301 to 3.32 | +-56.5 | 3.89 | 56.6 | 1.35 | 1.27 |
    """
    from .robust_stability import robust_stability

    check_plant(plant)
    if not isinstance(controllers, Mapping) or not controllers:
        raise TypeError("controllers must be a non-empty mapping of name -> gain")
    if not isinstance(models, Mapping) or not models:
        raise TypeError("models must be a non-empty mapping of name -> NormBounded or list of Plant")
    laws = {str(c): _law(str(c), law, plant) for c, law in controllers.items()}
    checked = {str(k): _model(str(k), m) for k, m in models.items()}
    results: dict[str, Mapping[str, RobustStability | str]] = {}
    loops: dict[str, LoopMargins | str] = {}
    for name, law in laws.items():
        try:
            loops[name] = loop_margins(law if isinstance(law, Controller) else (law.augmented_plant(plant), law.gain))
        except (RobustCtlError, ValueError) as exc:
            loops[name] = f"n/a ({str(exc).splitlines()[0][:60]})"
        row: dict[str, RobustStability | str] = {}
        for key, model in checked.items():
            try:
                if isinstance(law, Controller):
                    res = (robust_stability(law, model) if isinstance(model, NormBounded)
                           else robust_stability(law, vertices=model))
                elif isinstance(model, NormBounded):
                    res = robust_stability((law.augmented_plant(plant), law.gain),
                                           law.augmented_uncertainty(model, plant))
                else:
                    res = robust_stability((law.augmented_plant(plant), law.gain),
                                           vertices=[law.augmented_plant(v) for v in model])
                row[key] = cast("RobustStability", res)        # one gain (m, n): never a batch
            except (RobustCtlError, ValueError) as exc:
                row[key] = f"n/a ({str(exc).splitlines()[0][:60]})"
        results[name] = MappingProxyType(row)
    return MarginsReport(tuple(laws), tuple(checked), MappingProxyType(results), MappingProxyType(loops))
