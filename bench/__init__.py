"""Benchmarks (``bench/bench_*.py``) and the validation on real data (:mod:`bench.validation`)."""
