"""pcmapq's tests. Imported before tests/conftest.py and every test module, so before NumPy: it
holds NumPy's and SciPy's OpenBLAS to the command's thread count
(:data:`pcmapq.cli.BLAS_THREADS`) unless the environment sets one. The tests then run the
library as ``pcmapq`` runs it, and OpenBLAS's threads do not spin beside the other test
workers (``-n auto``) on their small systems, where they cost several times the CPU time."""

import os

from pcmapq.cli import BLAS_THREADS

os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)
