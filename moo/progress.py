"""Progress bars (tqdm, on stderr, only on a terminal) and the one summary line that ends a run.

:class:`ProgressBar` is what :func:`moo.tuning.tune`, :func:`moo.run_experiment`
and ``python -m moo run | experiment | select`` show while they work: a tqdm
bar on stderr, drawn only when stderr is a terminal (never into a log file or
a pipe) and not asked to be quiet. :func:`front_summary` is the line a run ends
with: the front's size, its hypervolume and the reference point it is
measured from, the best value of each objective, and where the results went.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import numpy as np

__all__ = ["ProgressBar", "front_summary", "check_progress"]


def check_progress(progress, name: str = "progress"):
    """``progress`` as a bool, None or a callable; ``TypeError`` naming ``name`` otherwise."""
    if isinstance(progress, (bool, np.bool_)):
        return bool(progress)
    if progress is None or callable(progress):
        return progress
    raise TypeError(f"{name} must be a bool or a callable progress(done, total), got {type(progress).__name__}")


class ProgressBar:
    """A tqdm bar on stderr for ``progress(done, total)`` callbacks; silent when stderr is not a terminal.

    Parameters
    ----------
    label : str
        What the bar counts for (its description).
    unit : str
        The unit of ``done`` (``"evals"``, ``"runs"``, ``"simulations"``).
    total : int, optional
        Known total (default: the first call's ``total``).
    initial : int
        Units already done before the bar starts (e.g. the runs of a resumed grid).
    enabled : bool, optional
        Draw the bar; default only when stderr is a terminal.

    Examples
    --------
    A bar that is not drawn (stderr is not a terminal under the doctest runner)
    still counts:

    >>> from moo.progress import ProgressBar
    >>> bar = ProgressBar("nsga2", unit="evals")
    >>> bar(92, 400); bar(184, 400)
    >>> bar.done, bar.enabled
    (184, False)
    >>> bar.close()
    """

    def __init__(self, label: str, *, unit: str = "evals", total: int | None = None, initial: int = 0,
                 enabled: bool | None = None):
        self.label, self.unit, self.total, self.done = label, unit, total, int(initial)
        self.enabled = _stderr_is_terminal() if enabled is None else bool(enabled)
        self._bar = None

    def _open(self, total: int | None):
        if self._bar is None and self.enabled:
            from tqdm import tqdm

            self._bar = tqdm(total=total, initial=self.done, desc=self.label, unit=self.unit, file=sys.stderr,
                             dynamic_ncols=True, leave=False)
        return self._bar

    def __call__(self, done: int, total: int | None = None) -> None:
        """Move the bar to ``done`` of ``total``."""
        if total is not None:
            self.total = int(total)
        bar = self._open(self.total)
        if bar is not None:
            if self.total is not None and bar.total != self.total:
                bar.total = self.total
            bar.update(int(done) - self.done)
        self.done = int(done)

    def postfix(self, text: str) -> None:
        """A short note after the counts (failures, the current run)."""
        bar = self._open(self.total)
        if bar is not None:
            bar.set_postfix_str(text, refresh=True)

    def close(self) -> None:
        """Remove the bar (the summary line follows on a clean line)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> ProgressBar:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _stderr_is_terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def front_summary(F, names: Sequence[str], hv: float, hv_reference: str, where: str | None = None) -> str:
    """One line: front size, hypervolume (and its reference), best value per objective, where the results are.

    Parameters
    ----------
    F : (N, M) array_like
        The front's objectives.
    names : sequence of str
        The objectives' names (M).
    hv : float
        Its hypervolume.
    hv_reference : str
        Where the reference point comes from (e.g. ``"sampled designs"``).
    where : str, optional
        Where the results were written.

    Returns
    -------
    str

    Examples
    --------
    >>> from moo.progress import front_summary
    >>> front_summary([[1.0, 4.0], [2.0, 3.0]], ["mse", "peak |u|"], 2.5, "sampled designs", "run.json")
    'front: 2 designs, hypervolume 2.5 (reference: sampled designs); best mse 1, best peak |u| 3; written to run.json'
    """
    F = np.asarray(F, dtype=float).reshape(len(F), -1) if len(F) else np.zeros((0, len(names)))
    best = ", ".join(f"best {name} {value:.4g}" for name, value in zip(names, F.min(axis=0), strict=True)) \
        if len(F) else "no design"
    tail = f"; written to {where}" if where else ""
    return (f"front: {len(F)} design{'s' if len(F) != 1 else ''}, hypervolume {hv:.6g} "
            f"(reference: {hv_reference}); {best}{tail}")
