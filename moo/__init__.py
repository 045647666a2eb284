"""moo: multiobjective evolutionary tuning of robust controllers.

MOEAs on top of pymoo (a registry of the paper's ten algorithms), the MO-LSP
local search that wraps any of them, quality indicators, the paper's two
control-design problems, single runs (``python -m moo run``), resumable
experiment grids (``python -m moo experiment``) and the paper's statistics
(``python -m moo stats``: ANOVA and Tukey HSD, MOEA vs its MO-LSP version).
"""

__version__ = "0.1.0"
