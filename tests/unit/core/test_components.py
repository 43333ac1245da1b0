"""Connected components of edges given in batches: SciPy's labels, whatever the batches."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse
from scipy.sparse.csgraph import connected_components

from pcmapq.core.components import Components


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("batch", [1, 97, 10_000])
def test_labels_are_scipys_whatever_the_batches(seed, batch):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3000))
    m = int(rng.integers(0, 2 * n))
    i, j = rng.integers(0, n, m), rng.integers(0, n, m)
    _, expected = connected_components(sparse.coo_array((np.ones(m), (i, j)), shape=(n, n)),
                                       directed=False)
    joined = Components(n)
    for start in range(0, m, batch):
        joined.join(i[start:start + batch], j[start:start + batch].astype(np.int32))
    got = joined.labels()
    assert got.dtype == expected.dtype and np.array_equal(got, expected)


def test_a_graph_without_edges_has_a_component_a_node():
    assert np.array_equal(Components(4).labels(), [0, 1, 2, 3])
