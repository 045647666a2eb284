"""The paper's MOEA indicator tables (Morais et al. 2022, Tables result_1 and result_2) as data.

``PAPER_MOEA[problem][(algorithm, molsp)]`` is a tuple of five :class:`Cell`
in the column order IGD, SP, HV, PD, Spread (``INDICATORS``), for
``problem`` ``"generic"`` (Table "result_1", Section 4.4, 3 objectives) and
``"applied"`` (Table "result_2", Section 4.5, the truck, 4 objectives);
``algorithm`` is a registry name of :data:`moo.algorithms.ALGORITHMS`,
``molsp`` True for the "MOEA/MO-LSP" row. Every figure is the mean and the
standard deviation over 50 runs of 10000 evaluations, as printed (PlatEMO,
the paper's units and HV reference points [25, 25, 25] and
[5000, 10000, 5000, 5000]).

A :class:`Cell` also records the typography: ``bold`` (the paper's better
value of the pair) and ``marks``, the superscripts: ``"a"`` "the model is
significantly better (95 %)" (ANOVA + Tukey HSD), ``"*"`` "best overall result".

Reading notes (checked by tests/test_moea_tables.py):

* The bold marks agree with the means for IGD (lower), HV and PD (higher) and
  Spread (lower), but for SP the paper bolds the *larger* value in all 20
  pairs: it treats larger spacing as better, contrary to Schott's definition
  (lower is more uniform). Compare the *sign* of the MO-LSP effect
  (``mean_molsp - mean_plain``), not the bold marks, when our direction
  convention (lower SP better) matters.
* Applied, SPEA/R/MO-LSP IGD is printed 9.8804E+4, yet bold and marked "a"
  against 1.0382E+4: the exponent is a typo for 9.8804E+3. ``PAPER_MOEA`` keeps
  the printed value; :data:`CORRECTIONS` holds the corrected one and
  :func:`paper_cell` applies it.
* Applied, BiGE HV is printed with one more digit (1.22385E+15); kept.
* Several "best overall" marks contradict the printed means: applied IGD
  "*" on BiGE/MO-LSP (1.0149E+4) while EFR-RR/MO-LSP has 9.4054E+3; applied SP
  "*" on MaOEA-DDFC/MO-LSP (9.5584E+1), neither the largest (EFR-RR/MO-LSP,
  4.1226E+2) nor the smallest; applied Spread "*" on EFR-RR (1.0312), while
  NSGA-II/MO-LSP has 0.99212. They are transcribed as printed and not used in
  comparisons.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["INDICATORS", "PAPER_LABELS", "Cell", "PAPER_MOEA", "CORRECTIONS", "paper_cell"]

INDICATORS = ("igd", "sp", "hv", "pd", "spread")

#: The paper's row names of the registry's algorithms.
PAPER_LABELS = {"nsga2": "NSGA-II", "nsga3": "NSGA-III", "theta-dea": "theta-DEA", "mombi2": "MOMBI-II",
                "moea-igd-ns": "MOEA/IGD-NS", "efr-rr": "EFR-RR", "maoea-ddfc": "MaOEA-DDFC",
                "spea-r": "SPEA/R", "spea2-sde": "SPEA2+SDE", "bige": "BiGE"}


class Cell(NamedTuple):
    """One printed cell: mean, standard deviation, bold (better of the pair) and superscripts."""

    mean: float
    std: float
    bold: bool
    marks: str


def _table(rows: dict) -> dict[tuple[str, bool], tuple[Cell, ...]]:
    return {key: tuple(Cell(*c) for c in cells) for key, cells in rows.items()}


PAPER_MOEA: dict[str, dict[tuple[str, bool], tuple[Cell, ...]]] = {
    "generic": _table({
        ("nsga2", True): (
            (2.6514E+1, 2.67E-1, True, "a,*"), (1.1815E-1, 3.73E-2, True, "a"), (1.3644E+4, 1.23E+1, True, "a,*"),
            (2.2943E+5, 2.23E+4, True, "a,*"), (9.6881E-1, 4.57E-3, True, "")),
        ("nsga2", False): (
            (2.6867E+1, 2.18E-1, False, ""), (8.2553E-2, 1.52E-2, False, ""), (1.3628E+4, 9.22E+0, False, ""),
            (2.0761E+5, 2.45E+4, False, ""), (9.6998E-1, 3.08E-3, False, "")),
        ("nsga3", True): (
            (2.6670E+1, 3.54E-1, True, "a"), (1.3804E-1, 5.73E-2, True, "a"), (1.3625E+4, 1.59E+1, True, "a"),
            (1.8573E+5, 2.39E+4, True, "a"), (9.7854E-1, 6.11E-3, True, "a")),
        ("nsga3", False): (
            (2.7007E+1, 4.26E-1, False, ""), (1.0641E-1, 4.41E-2, False, ""), (1.3605E+4, 2.15E+1, False, ""),
            (1.5608E+5, 2.14E+4, False, ""), (9.8263E-1, 5.05E-3, False, "")),
        ("theta-dea", True): (
            (2.6690E+1, 3.10E-1, True, "a"), (1.3586E-1, 5.72E-2, True, "a"), (1.3572E+4, 2.73E+1, False, ""),
            (1.6647E+5, 1.61E+4, True, "a"), (9.7989E-1, 4.91E-3, True, "")),
        ("theta-dea", False): (
            (2.7022E+1, 4.63E-1, False, ""), (9.6822E-2, 2.91E-2, False, ""), (1.3576E+4, 2.35E+1, True, ""),
            (1.5562E+5, 2.45E+4, False, ""), (9.7995E-1, 4.57E-3, False, "")),
        ("mombi2", True): (
            (2.6986E+1, 4.39E-1, True, "a"), (1.5640E-1, 6.57E-2, True, "a"), (1.3522E+4, 4.99E+2, False, ""),
            (1.3280E+5, 2.83E+4, True, "a"), (9.9271E-1, 7.03E-3, False, "")),
        ("mombi2", False): (
            (2.7469E+1, 7.39E-1, False, ""), (1.0330E-1, 5.52E-2, False, ""), (1.3595E+4, 3.77E+1, True, ""),
            (1.1381E+5, 3.36E+4, False, ""), (9.9222E-1, 3.91E-3, True, "")),
        ("moea-igd-ns", True): (
            (2.6583E+1, 2.50E-1, True, "a"), (1.2679E-1, 4.78E-2, True, "a"), (1.3625E+4, 1.71E+1, True, "a"),
            (2.0069E+5, 1.56E+4, True, "a"), (9.6113E-1, 3.72E-3, False, "")),
        ("moea-igd-ns", False): (
            (2.6847E+1, 2.77E-1, False, ""), (9.4555E-2, 3.72E-2, False, ""), (1.3612E+4, 1.25E+1, False, ""),
            (1.8549E+5, 1.53E+4, False, ""), (9.6076E-1, 3.87E-3, True, "*")),
        ("efr-rr", True): (
            (2.6598E+1, 2.88E-1, True, ""), (1.9211E-1, 6.80E-2, True, "a,*"), (1.3638E+4, 1.33E+1, True, "a"),
            (1.7061E+5, 1.64E+4, True, "a"), (9.8057E-1, 7.49E-3, False, "")),
        ("efr-rr", False): (
            (2.6626E+1, 3.09E-1, False, ""), (1.6012E-1, 5.94E-2, False, ""), (1.3630E+4, 1.05E+1, False, ""),
            (1.6122E+5, 1.35E+4, False, ""), (9.8021E-1, 4.26E-3, True, "")),
        ("maoea-ddfc", True): (
            (2.6580E+1, 3.01E-1, True, "a"), (1.5213E-1, 4.69E-2, True, "a"), (1.3635E+4, 1.41E+1, True, "a"),
            (1.8333E+5, 2.28E+4, True, "a"), (9.8473E-1, 6.76E-3, True, "")),
        ("maoea-ddfc", False): (
            (2.6955E+1, 3.70E-1, False, ""), (1.1452E-1, 3.14E-2, False, ""), (1.3620E+4, 1.51E+1, False, ""),
            (1.6074E+5, 1.89E+4, False, ""), (9.8554E-1, 4.16E-3, False, "")),
        ("spea-r", True): (
            (2.6616E+1, 3.54E-1, False, ""), (1.4497E-1, 4.85E-2, True, ""), (1.3621E+4, 1.66E+1, False, ""),
            (1.8292E+5, 1.64E+4, True, ""), (9.8104E-1, 4.92E-3, True, "")),
        ("spea-r", False): (
            (2.6596E+1, 3.37E-1, True, ""), (1.3316E-1, 4.00E-2, False, ""), (1.3625E+4, 1.38E+1, True, ""),
            (1.8284E+5, 2.09E+4, False, ""), (9.8226E-1, 4.36E-3, False, "")),
        ("spea2-sde", True): (
            (2.6819E+1, 2.78E-1, True, "a"), (1.3680E-1, 3.92E-2, True, "a"), (1.3625E+4, 1.17E+1, True, "a"),
            (1.7099E+5, 1.48E+4, True, "a"), (9.8566E-1, 3.34E-3, True, "")),
        ("spea2-sde", False): (
            (2.7149E+1, 4.74E-1, False, ""), (1.0764E-1, 4.89E-2, False, ""), (1.3615E+4, 2.46E+1, False, ""),
            (1.5231E+5, 2.21E+4, False, ""), (9.8583E-1, 3.63E-3, False, "")),
        ("bige", True): (
            (2.6530E+1, 3.14E-1, True, "a"), (1.4666E-1, 5.16E-2, True, "a"), (1.3623E+4, 1.64E+1, True, "a"),
            (1.8345E+5, 1.73E+4, True, "a"), (9.8084E-1, 4.55E-3, True, "")),
        ("bige", False): (
            (2.6966E+1, 3.96E-1, False, ""), (1.0567E-1, 2.80E-2, False, ""), (1.3611E+4, 2.04E+1, False, ""),
            (1.6268E+5, 2.23E+4, False, ""), (9.8207E-1, 3.83E-3, False, "")),
    }),
    "applied": _table({
        ("nsga2", True): (
            (9.9567E+3, 3.75E+2, True, "a"), (9.1979E+1, 1.38E+2, True, ""), (1.2347E+15, 5.49E+12, True, "a,*"),
            (5.6215E+8, 2.28E+8, True, "a"), (9.9212E-1, 1.72E-2, True, "")),
        ("nsga2", False): (
            (1.0153E+4, 3.65E+2, False, ""), (7.7183E+1, 1.37E+2, False, ""), (1.2281E+15, 3.18E+12, False, ""),
            (4.0812E+8, 1.54E+8, False, ""), (9.9859E-1, 1.82E-2, False, "")),
        ("nsga3", True): (
            (1.0278E+4, 2.25E+2, True, "a"), (4.5133E+1, 3.72E+1, True, ""), (1.2272E+15, 5.08E+12, True, "a"),
            (2.9024E+8, 7.91E+7, True, "a"), (9.9951E-1, 7.41E-3, True, "")),
        ("nsga3", False): (
            (1.0396E+4, 2.51E+2, False, ""), (4.0309E+1, 6.73E+1, False, ""), (1.2168E+15, 1.10E+13, False, ""),
            (1.9930E+8, 7.99E+7, False, ""), (1.0012E+0, 8.90E-3, False, "")),
        ("theta-dea", True): (
            (1.0335E+4, 2.89E+2, True, ""), (5.9223E+1, 1.53E+2, True, ""), (1.2172E+15, 1.66E+13, True, ""),
            (2.0107E+8, 7.09E+7, True, "a"), (1.0050E+0, 2.18E-2, False, "")),
        ("theta-dea", False): (
            (1.0430E+4, 2.23E+2, False, ""), (3.6280E+1, 8.01E+1, False, ""), (1.2129E+15, 1.37E+13, False, ""),
            (1.4122E+8, 4.14E+7, False, ""), (1.0027E+0, 1.08E-2, True, "")),
        ("mombi2", True): (
            (1.0301E+4, 1.92E+2, True, "a"), (3.0226E+1, 5.07E+1, True, ""), (1.2325E+15, 3.49E+12, True, "a"),
            (2.5432E+8, 7.47E+7, True, "a"), (1.0036E+0, 6.75E-3, False, "")),
        ("mombi2", False): (
            (1.0414E+4, 1.53E+2, False, ""), (2.5857E+1, 4.34E+1, False, ""), (1.2266E+15, 3.44E+12, False, ""),
            (1.8467E+8, 5.30E+7, False, ""), (1.0025E+0, 4.25E-3, True, "")),
        ("moea-igd-ns", True): (
            (1.0312E+4, 2.26E+2, True, "a"), (8.9270E+1, 1.38E+2, True, "a"), (1.2307E+15, 5.98E+12, True, "a"),
            (3.2759E+8, 7.18E+7, True, "a"), (9.9845E-1, 1.78E-2, False, "")),
        ("moea-igd-ns", False): (
            (1.0407E+4, 2.28E+2, False, ""), (3.8264E+1, 6.99E+1, False, ""), (1.2194E+15, 1.02E+13, False, ""),
            (2.3176E+8, 7.23E+7, False, ""), (9.9352E-1, 1.02E-2, True, "")),
        ("efr-rr", True): (
            (9.4054E+3, 2.47E+2, True, "a"), (4.1226E+2, 3.53E+2, True, "a"), (1.2326E+15, 4.15E+12, True, "a"),
            (7.6329E+8, 2.26E+8, True, "a,*"), (1.0576E+0, 4.14E-2, False, "")),
        ("efr-rr", False): (
            (9.9348E+3, 4.71E+2, False, ""), (2.5012E+2, 3.51E+2, False, ""), (1.2247E+15, 7.60E+12, False, ""),
            (4.0443E+8, 2.41E+8, False, ""), (1.0312E+0, 4.73E-2, True, "a,*")),
        ("maoea-ddfc", True): (
            (1.0158E+4, 2.71E+2, True, "a"), (9.5584E+1, 9.46E+1, True, "a,*"), (1.2325E+15, 3.90E+12, True, "a"),
            (3.9193E+8, 6.45E+7, True, "a"), (1.0037E+0, 1.40E-2, False, "")),
        ("maoea-ddfc", False): (
            (1.0372E+4, 2.33E+2, False, ""), (3.9554E+1, 5.29E+1, False, ""), (1.2195E+15, 7.20E+12, False, ""),
            (2.5277E+8, 7.80E+7, False, ""), (9.9677E-1, 6.44E-3, True, "a")),
        ("spea-r", True): (
            (9.8804E+4, 4.70E+2, True, "a"), (1.6476E+2, 2.59E+2, True, "a"), (1.2285E+15, 4.94E+12, True, "a"),
            (5.8282E+8, 4.06E+8, True, "a"), (1.0176E+0, 2.87E-2, False, "")),
        ("spea-r", False): (
            (1.0382E+4, 1.95E+2, False, ""), (4.5938E+1, 8.07E+1, False, ""), (1.2173E+15, 1.06E+13, False, ""),
            (2.1226E+8, 7.46E+7, False, ""), (1.0049E+0, 1.31E-2, True, "a")),
        ("spea2-sde", True): (
            (1.0445E+4, 6.60E+1, True, "a"), (2.5946E+1, 1.38E+1, True, ""), (1.2303E+15, 4.62E+12, True, "a"),
            (2.0872E+8, 5.14E+7, True, "a"), (9.9855E-1, 3.46E-3, False, "")),
        ("spea2-sde", False): (
            (1.0528E+4, 5.12E+1, False, ""), (1.8283E+1, 2.76E+1, False, ""), (1.2231E+15, 5.03E+12, False, ""),
            (1.5596E+8, 2.15E+7, False, ""), (9.9670E-1, 4.78E-3, True, "")),
        ("bige", True): (
            (1.0149E+4, 2.83E+2, True, "a,*"), (7.3337E+1, 9.46E+1, True, "a"), (1.2327E+15, 4.39E+12, True, "a"),
            (3.4968E+8, 1.05E+8, True, "a"), (1.0066E+0, 1.34E-2, False, "")),
        ("bige", False): (
            (1.0405E+4, 1.66E+2, False, ""), (3.3735E+1, 5.53E+1, False, ""), (1.22385E+15, 5.65E+12, False, ""),
            (2.2544E+8, 6.24E+7, False, ""), (1.0014E+0, 6.98E-3, True, "a")),
    }),
}

#: Printed values read as typos: (problem, algorithm, molsp, indicator) -> corrected mean.
CORRECTIONS: dict[tuple[str, str, bool, str], float] = {
    ("applied", "spea-r", True, "igd"): 9.8804e3,
}


def paper_cell(problem: str, algorithm: str, molsp: bool, indicator: str) -> Cell:
    """The paper's cell, with :data:`CORRECTIONS` applied to its mean."""
    cell = PAPER_MOEA[problem][(algorithm, molsp)][INDICATORS.index(indicator)]
    fixed = CORRECTIONS.get((problem, algorithm, molsp, indicator))
    return cell if fixed is None else cell._replace(mean=fixed)
