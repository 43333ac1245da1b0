"""MOM's orthogonal subset, extracted as map-metrics' ``extract_orthogonal_subsets`` does:

1. normals of the cloud by Open3D (hybrid search: ``radius`` metres, at most ``max_nn``);
2. planar points: more than 3 neighbours closer than ``radius`` and, of their neighbourhood's
   covariance eigenvalues, 100 * lambda_0 < lambda_1;
3. their normals clustered by Ward linkage, cut at distance 0.1 (scikit-learn's
   ``AgglomerativeClustering(distance_threshold=0.1)``; here the same Ward tree built by
   fastcluster from the normals themselves, in memory linear in N, where SciPy's ``ward``
   holds all N^2 / 2 distances twice, quadratic in memory). A Ward tree still costs
   N^2 in time: above ``max_ward`` planar points (default ``MAX_WARD_POINTS``; a whole map:
   map-metrics extracts from one scan) the tree is built on that many of them, evenly spaced
   in the cloud's order, and every planar point then joins the cluster whose mean normal is
   nearest (largest dot product); below it the result is map-metrics' own;
4. clusters of more than ``min_cluster`` points, their mean normals normalised;
5. of the triples of clusters whose mean normals are pairwise nearly orthogonal
   (|cos| < ``eps``), the one holding the most points (map-metrics: the largest maximal clique,
   and in 3D no four directions are pairwise that orthogonal, so its cliques are triples).
"""

from __future__ import annotations

import fastcluster
import numpy as np
from scipy.cluster.hierarchy import fcluster

from pcmapq.core.errors import EvaluationError
from pcmapq.metrics.defaults import MAX_WARD_POINTS
from pcmapq.metrics.noref import MAX_NN, flat, neighbourhood_sums

#: map-metrics' constants: Ward cut distance, near-orthogonality |cos|, smallest cluster.
WARD_CUT = 0.1
ORTHOGONAL_COS = 0.1
MIN_CLUSTER = 5


def planar_points(cloud: np.ndarray, radius: float) -> np.ndarray:
    """Mask of the points whose neighbourhood (more than 3 points closer than ``radius``
    metres) is flat: 100 * smallest eigenvalue < middle eigenvalue."""
    keep = np.zeros(len(cloud), dtype=bool)
    for idx, sums in neighbourhood_sums(cloud, radius):
        keep[idx] = flat(sums)
    return keep


def _normals(cloud: np.ndarray, radius: float, max_nn: int) -> np.ndarray:
    import open3d as o3d  # heavy: loaded when a subset is extracted

    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(cloud, dtype=np.float64)))
    pc.estimate_normals(search_param=o3d.geometry.KDTreeSearchParamHybrid(radius=radius,
                                                                          max_nn=max_nn))
    return np.asarray(pc.normals)


def _best_triple(means: np.ndarray, sizes: np.ndarray, eps: float) -> tuple[int, int, int]:
    """Indices of the pairwise-orthogonal triple of unit normals with the largest total size
    (the first, in lexicographic order, among equals). One cluster i at a time: the pairs
    j < k of clusters after it orthogonal to it and to each other (memory in the clusters
    squared, not cubed)."""
    adj = np.abs(means @ means.T) < eps
    best, best_total = None, -1
    for i in range(len(means)):
        after = np.flatnonzero(adj[i, i + 1:]) + i + 1
        j, k = np.nonzero(np.triu(adj[np.ix_(after, after)], 1))
        if len(j) == 0:
            continue
        total = sizes[i] + sizes[after[j]] + sizes[after[k]]
        m = int(np.argmax(total))
        if total[m] > best_total:
            best, best_total = (i, int(after[j[m]]), int(after[k[m]])), total[m]
    if best is None:
        raise EvaluationError("no three mutually orthogonal planes found for MOM "
                              "(give an orthogonal subset instead)")
    return best


def extract_orthogonal_subset(cloud: np.ndarray, radius: float, max_nn: int = MAX_NN,
                              min_cluster: int = MIN_CLUSTER,
                              eps: float = ORTHOGONAL_COS,
                              planar: np.ndarray | None = None,
                              max_ward: int = MAX_WARD_POINTS) -> list[np.ndarray]:
    """Three arrays of points (metres, the cloud's frame) on mutually orthogonal planes of
    ``cloud`` (map-metrics extracts them from the first scan). EvaluationError when none.
    ``planar``: :func:`planar_points` of the cloud at ``radius``, when already found;
    ``max_ward``: the most planar normals the Ward tree is built on (see the module
    docstring)."""
    cloud = np.asarray(cloud, dtype=np.float64)
    normals = _normals(cloud, radius, max_nn)
    keep = planar_points(cloud, radius) if planar is None else planar
    points, normals = cloud[keep], normals[keep]
    if len(points) < 3 * (min_cluster + 1):
        raise EvaluationError(f"only {len(points)} planar points for MOM's orthogonal subset")
    labels, ids, sizes = _clusters(normals, min_cluster, max_ward)
    if len(ids) < 3:
        raise EvaluationError("fewer than three planes for MOM's orthogonal subset")
    means = np.stack([normals[labels == c].mean(axis=0) for c in ids])
    means /= np.linalg.norm(means, axis=1, keepdims=True)
    return [points[labels == ids[c]] for c in _best_triple(means, sizes, eps)]


def _clusters(normals: np.ndarray, min_cluster: int,
              max_ward: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ward cluster label of every normal, and the labels and sizes of the clusters of more
    than ``min_cluster`` normals (above ``max_ward`` normals: see the module docstring;
    ``min_cluster`` then counts the sample's normals)."""
    step = -(-len(normals) // max_ward)
    sample = normals[::step]
    tree = fastcluster.linkage_vector(sample, method="ward")
    clusters = int(np.count_nonzero(tree[:, 2] >= WARD_CUT)) + 1
    labels = fcluster(tree, clusters, criterion="maxclust")
    ids, sizes = np.unique(labels, return_counts=True)
    big = sizes > min_cluster
    ids = ids[big]
    if step > 1 and len(ids):
        means = np.stack([sample[labels == c].mean(axis=0) for c in ids])
        labels = ids[np.argmax(normals @ means.T, axis=1)]
        ids, sizes = np.unique(labels, return_counts=True)
        return labels, ids, sizes
    return labels, ids, sizes[big]
