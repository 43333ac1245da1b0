"""Connected components of a graph whose edges come in batches, never held together: a
disjoint-set forest (union by the smaller root, path halving, compiled by Numba) that each
batch of edges joins, so memory grows with the nodes, not the edges.

The labels are those of SciPy's ``connected_components(graph, directed=False)`` on the graph
of all the edges: components numbered 0, 1, ... in the order of their smallest node.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def _root(parent: np.ndarray, node: int) -> int:
    """The root of ``node``'s tree, the trees halved on the way."""
    while parent[node] != node:
        parent[node] = parent[parent[node]]
        node = parent[node]
    return node


@numba.njit(cache=True, nogil=True)
def _join(parent: np.ndarray, first: np.ndarray, second: np.ndarray) -> None:
    """Join the trees of each edge's two nodes, the smaller root on top."""
    for e in range(len(first)):
        a, b = _root(parent, first[e]), _root(parent, second[e])
        if a < b:
            parent[b] = a
        elif b < a:
            parent[a] = b


@numba.njit(cache=True, nogil=True)
def _labels(parent: np.ndarray) -> np.ndarray:
    """Each node's component, numbered in the order of the components' smallest nodes."""
    label = np.full(len(parent), -1, dtype=np.int32)
    count = 0
    for node in range(len(parent)):
        root = _root(parent, node)
        if label[root] < 0:
            label[root] = count
            count += 1
        label[node] = label[root]
    return label


class Components:
    """The connected components of an undirected graph on ``nodes`` nodes (0 .. nodes - 1),
    its edges given a batch at a time (:meth:`join`)."""

    def __init__(self, nodes: int) -> None:
        self._parent = np.arange(nodes, dtype=np.int64)

    def join(self, first: np.ndarray, second: np.ndarray) -> None:
        """Add the edges ``first[e]`` -- ``second[e]`` (two integer arrays of one length)."""
        _join(self._parent, np.asarray(first, dtype=np.int64),
              np.asarray(second, dtype=np.int64))

    def labels(self) -> np.ndarray:
        """(nodes,) int32: each node's component, as SciPy's ``connected_components`` numbers
        them (module docstring); a node no edge reaches is a component of its own."""
        return _labels(self._parent)
