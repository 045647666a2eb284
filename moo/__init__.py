"""moo: multiobjective evolutionary tuning of robust controllers.

MOEAs on top of pymoo (a registry of the paper's ten algorithms), the MO-LSP
local search that wraps any of them, quality indicators, the paper's two
control-design problems and an experiment runner (``python -m moo run``).
"""

__version__ = "0.1.0"
