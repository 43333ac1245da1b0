"""What tests and benchmarks share, never imported by the pipeline: synthetic plans and maps
with known answers (:mod:`~pcmapq.testing.synth`)."""
