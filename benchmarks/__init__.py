"""Benchmarks (``bench_*``, each against a named peer) and the investigations behind the validation pages."""
