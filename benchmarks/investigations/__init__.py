"""Investigations that back a claim of the documentation's Validation pages.

Each module is named after the page it backs (``benchmarks_*``: validation/benchmarks, ``dtlz4_*``:
validation/dtlz4, ``many_objectives_*``: validation/many_objectives, ``operators_*``: validation/operators) and
runs from the repository root as ``python -m benchmarks.investigations.NAME``.
"""
