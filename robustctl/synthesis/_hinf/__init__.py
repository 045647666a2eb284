"""The stages of the H-infinity and H2 LMI syntheses (private; the maths is in ``robustctl.synthesis.hinf``).

``problem`` (validation), ``coordinates`` (scalings), ``lmis`` (the named LMI
blocks), ``level`` (the optimal level), ``gains`` (certified gains near the
optimum), ``riccati_path`` (the Riccati fast path) and ``tolerances``.
"""
