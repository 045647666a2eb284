"""The truck's uncertainty models for the robust-stability margins of ``mse_table.py`` and ``design_selection.py``.

Imported by both scripts as a sibling module (run from the repository).
The report itself is :func:`robustctl.analysis.margins_report`.
"""

from __future__ import annotations

import robustctl as rc
from robustctl.models import morais2022, truck

#: The models' names, the columns of the report.
MARGINS = ("polytope 0-300 %", "appendix (printed)", "appendix (computed)")
#: The legend under the Markdown table.
MARGINS_NOTE = ("Margin: the largest r for which stability is certified for r times the uncertainty (polytope: "
                "scaled about the nominal payload); >= 1 certifies it all. Appendix: H = 1, EF, EG of RLQR^A.")


def appendix_uncertainty(source: str = "printed") -> rc.NormBounded:
    """The appendix's norm-bounded model on the plain truck (alpha = u1 + u2: one of the equal EG entries)."""
    u = morais2022.algebraic_uncertainty(source)
    return rc.NormBounded(u.H, u.EF, u.EG[:, :1])


def margin_models() -> dict[str, rc.NormBounded | list[rc.Plant]]:
    """Polytope: the truck at 100, 200, 300 % besides the nominal 0 % (``margin >= 1``: the whole range
    certified, also for time-varying payloads). Norm-bounded: the appendix's ``H = 1``, ``EF``, ``EG``,
    printed and computed."""
    return {MARGINS[0]: [truck.truck_plant(k) for k in (100.0, 200.0, 300.0)],
            MARGINS[1]: appendix_uncertainty("printed"), MARGINS[2]: appendix_uncertainty("computed")}


def truck_margins(laws: dict[str, rc.InputMemoryFeedback]) -> rc.MarginsReport:
    """Certified margins of steering laws designed on the nominal (0 %) truck against :func:`margin_models`."""
    return rc.margins_report(truck.truck_plant(0.0), laws, margin_models())
