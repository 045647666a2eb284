"""The MSE table against the paper's (``paper_repro/mse_table.py``): agreement measures and the table files.

Imported by ``mse_table.py`` as a sibling module (run from the repository:
``python paper_repro/mse_table.py``). The layouts are :mod:`moo.tables`'.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from paper_values import CONTROLLERS, OBJECTIVES, OVERLOADS, PAPER_MSE

from moo.tables import latex_tabular, markdown_table, write_csv

TEX_NAMES = {"RLQR_MOP": r"RLQR$^{MOP}$", "RLQR_A": r"RLQR$^{A}$", "Hinf": r"$\mathcal{H}_\infty$",
             "LQR": "LQR", "Hinf_polytopic": r"$\mathcal{H}_\infty$ polytopic",
             "Hinf_unbounded": r"$\mathcal{H}_\infty$ without input bound",
             "Hinf_robust": r"robust $\mathcal{H}_\infty$", "Hinf_game": r"$\mathcal{H}_\infty$ game (code)",
             "RLQR_A_code_EG": r"RLQR$^{A}$ (code's $E_G$)", "RLQR_A_printed_EG": r"RLQR$^{A}$ (printed $E_G$)",
             "RLQR_A_computed": r"RLQR$^{A}$ (computed)", "RLQR_A_printed": r"RLQR$^{A}$ (printed)"}


@dataclass(frozen=True)
class Agreement:
    """How a table (the paper's four controllers) agrees with the paper's (module docstring)."""

    winners: int
    pairs_agree: int
    pairs: int
    ratio_median: float
    ratio_min: float
    ratio_max: float
    ratio_median_by_objective: dict

    @property
    def pairwise(self) -> float:
        return self.pairs_agree / self.pairs

    def line(self) -> str:
        by = ", ".join(f"{o} {v:.3g}" for o, v in self.ratio_median_by_objective.items())
        return (f"winners matched {self.winners}/16; pairwise order {self.pairs_agree}/{self.pairs} = "
                f"{self.pairwise:.3f} (chance 0.5); ours/paper ratio median {self.ratio_median:.3g}, "
                f"range {self.ratio_min:.3g} .. {self.ratio_max:.3g} (medians {by})")


def agreement(mse: dict) -> Agreement:
    """Winners, pairwise order over the 6 pairs x 16 cells, and the 64 ours/paper ratios."""
    cs = compared_controllers(mse)
    if len(cs) < 2:
        raise ValueError(f"agreement needs at least two of the paper's controllers, got {cs}")
    winners, agree, pairs, by = 0, 0, 0, {}
    for o in OBJECTIVES:
        ratios = []
        for i in range(len(OVERLOADS)):
            ours = {c: mse[o][c][i] for c in cs}
            paper = {c: PAPER_MSE[o][c][i] for c in cs}
            winners += _winner(ours) == _winner(paper)
            for a in range(len(cs)):
                for b in range(a + 1, len(cs)):
                    pairs += 1
                    agree += (ours[cs[a]] < ours[cs[b]]) == (paper[cs[a]] < paper[cs[b]])
            ratios += [ours[c] / paper[c] for c in cs]
        by[o] = ratios
    every = np.concatenate(list(by.values()))
    return Agreement(winners, agree, pairs, float(np.median(every)), float(every.min()), float(every.max()),
                     {o: float(np.median(v)) for o, v in by.items()})


def _winner(values: dict[str, float]) -> str:
    return min(values, key=values.get)


def compared_controllers(mse: dict) -> list[str]:
    """The paper's controllers present in ``mse`` (winners are taken among these, in both tables)."""
    return [c for c in CONTROLLERS if c in mse[OBJECTIVES[0]]]


def winner_agreement(mse: dict) -> int:
    """Cells (of 16) whose best controller among the paper's four is the same as in the paper."""
    return agreement(mse).winners


def format_table(mse: dict, names: list[str], measure: str = "tracking") -> str:
    """The paper's layout, ours beside the paper's, and the winner of each cell in both."""
    lines = [f"MSE ({measure} errors) - ours beside the paper's published values"]
    head = f"{'obj':<4}{'controller':<17}" + "".join(f"{f'{ov}% ours':>12}{'paper':>11}" for ov in OVERLOADS)
    lines += [head, "-" * len(head)]
    agree = 0
    for obj in OBJECTIVES:
        for name in names:
            row = f"{obj:<4}{name:<17}"
            for i in range(len(OVERLOADS)):
                paper = PAPER_MSE[obj].get(name, (None,) * 4)[i]
                row += f"{mse[obj][name][i]:>12.4e}" + (f"{paper:>11.3e}" if paper is not None else f"{'':>11}")
            lines.append(row)
        cs = compared_controllers(mse)
        if not cs:
            continue
        ours = [_winner({c: mse[obj][c][i] for c in cs}) for i in range(4)]
        paper = [_winner({c: PAPER_MSE[obj][c][i] for c in cs}) for i in range(4)]
        agree += sum(a == b for a, b in zip(ours, paper, strict=True))
        lines.append(f"{'':<4}{'best (ours/paper)':<17}"
                     + "".join(f"{f'{a}/{b}':>23}" for a, b in zip(ours, paper, strict=True)))
        lines.append("")
    lines.append(f"Best controller agrees with the paper in {agree} of 16 cells "
                 f"(winners among {', '.join(compared_controllers(mse))}).")
    if len(compared_controllers(mse)) == len(CONTROLLERS):
        lines.append("Agreement: " + agreement(mse).line() + ".")
    return "\n".join(lines)


def write_tables(out: Path, stem: str, mse: dict, names: list[str], *, latex: bool = True) -> None:
    """``<stem>.csv`` (``objective,controller,overload,mse``), ``<stem>.md`` and, with ``latex``, ``<stem>.tex``."""
    write_csv(["objective", "controller", "overload", "mse"],
              ([obj, name, ov, f"{mse[obj][name][i]:.10e}"]
               for obj in OBJECTIVES for name in names for i, ov in enumerate(OVERLOADS)),
              out / f"{stem}.csv", lineterminator="\r\n")
    cs = compared_controllers(mse) or names
    best = {obj: [_winner({c: mse[obj][c][i] for c in cs}) for i in range(4)] for obj in OBJECTIVES}
    rows = []
    for obj in OBJECTIVES:
        pbest = [_winner({c: PAPER_MSE[obj][c][i] for c in cs if c in PAPER_MSE[obj]} or {"-": 0.0})
                 for i in range(4)]
        for name in names:
            ours = [_bold(f"{mse[obj][name][i]:.3e}", best[obj][i] == name) for i in range(4)]
            pap = ([_bold(f"{v:.3e}", pbest[i] == name) for i, v in enumerate(PAPER_MSE[obj][name])]
                   if name in PAPER_MSE[obj] else ["-"] * 4)
            rows.append([obj, name, *ours, *pap])
    header = ["Objective", "Controller", *(f"{ov} % (ours)" for ov in OVERLOADS),
              *(f"{ov} % (paper)" for ov in OVERLOADS)]
    (out / f"{stem}.md").write_text(markdown_table(header, rows, align="ll" + "r" * 8) + "\n\n"
                                    "Bold: smallest MSE among RLQR_MOP, RLQR_A, Hinf and LQR in that column. "
                                    "f1 [m^2], f2 [(rad/s)^2], f3 [(m/s)^2], f4 [rad^2].\n")
    if latex:
        groups = [[[rf"\multirow{{{len(names)}}}{{*}}{{$f_{obj[1]}$}}" if j == 0 else "", TEX_NAMES.get(name, name),
                    *(_sci_tex(mse[obj][name][i], bold=best[obj][i] == name) for i in range(4))]
                   for j, name in enumerate(names)] for obj in OBJECTIVES]
        head = [r"Objective & Controller & \multicolumn{4}{c}{Overload} \\",
                r"\cline{3-6} & & 0\% & 100\% & 200\% & 300\% \\"]
        (out / f"{stem}.tex").write_text(latex_tabular("c c c c c c", head, groups) + "\n")


def _bold(text: str, bold: bool) -> str:
    return f"**{text}**" if bold else text


def _sci_tex(x: float, bold: bool = False) -> str:
    m, e = f"{x:.3e}".split("e")
    body = f"{m}\\times10^{{{int(e)}}}"
    return f"$\\mathbf{{{body}}}$" if bold else f"${body}$"


def write_agreement(out: Path, rows: list[tuple[str, Agreement]], measure: str) -> None:
    """``agreement.md``: one row per set-up."""
    table = markdown_table(
        ["set-up", "winners (of 16)", "pairwise order (chance 0.5)", "ratio median", "ratio range",
         "ratio median f1 / f2 / f3 / f4"],
        ([name, a.winners, f"{a.pairs_agree}/{a.pairs} = {a.pairwise:.3f}", f"{a.ratio_median:.3g}",
          f"{a.ratio_min:.3g} .. {a.ratio_max:.3g}",
          " / ".join(f"{v:.3g}" for v in a.ratio_median_by_objective.values())] for name, a in rows),
        align="lrrrll")
    (out / "agreement.md").write_text(f"Agreement with the paper's MSE table ({measure} errors, the paper's four "
                                      f"controllers)\n\n{table}\n")


def write_comparison(out: Path, rows: list[tuple[str, str, Agreement]]) -> None:
    """``setup_comparison.md`` and ``.csv``: each set-up with one choice of the other at a time."""
    table = markdown_table(
        ["set-up", "switched to the other set-up's", "winners (of 16)", "pairwise order", "ratio median",
         "ratio range"],
        ([base, label, a.winners, f"{a.pairwise:.3f}", f"{a.ratio_median:.3g}",
          f"{a.ratio_min:.3g} .. {a.ratio_max:.3g}"] for base, label, a in rows), align="llrrrl")
    (out / "setup_comparison.md").write_text(
        table + "\n\nPairwise order: fraction of the 96 pairs (6 pairs of RLQR_MOP, RLQR_A, Hinf, LQR in each of "
        "the 16 cells) ordered as in the paper; chance 0.5. Ratio: ours/paper over the 64 values.\n")
    write_csv(["setup", "switched", "winners", "pairs_agree", "pairs", "ratio_median", "ratio_min", "ratio_max"],
              ([base, label, a.winners, a.pairs_agree, a.pairs, f"{a.ratio_median:.6g}", f"{a.ratio_min:.6g}",
                f"{a.ratio_max:.6g}"] for base, label, a in rows), out / "setup_comparison.csv", lineterminator="\r\n")
