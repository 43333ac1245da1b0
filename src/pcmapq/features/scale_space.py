"""SIFT's difference-of-Gaussians (DoG) scale space of an image and its extrema, in pixels.

The Gaussian pyramid is built as ``cv2.SIFT`` builds it without doubling the image (``layers``
DoG layers searched per octave, base blur ``sigma`` pixels), with one layer more per octave so
that consecutive octaves share a searched DoG layer. Extrema are every sample that is an
extremum of its 26 neighbours, refined by one quadratic step clipped to half a sample in space
and scale (see :mod:`pcmapq.features.sift` for why ``cv2.SIFT``'s own detection is not used).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import cv2
import numpy as np

#: Samples this close to the image border are not searched for extrema (as in cv2.SIFT).
BORDER = 5


@dataclass(frozen=True)
class Extrema:
    """DoG extrema, one entry per extremum.

    octave: (N,) int, octave index (0: the input's resolution).
    layer: (N,) int, DoG layer within the octave, 1 to ``layers + 1``.
    pt: (N, 2) refined position (u, v), pixels of the input image.
    xi: (N,) refined scale offset, layers, in [-0.5, 0.5].
    size: (N,) diameter ``2 * scale``, pixels of the input image.
    contrast: (N,) refined DoG value, units of the image.
    edge_ratio: (N,) ``trace^2 / det`` of the spatial Hessian, inf when the curvatures differ
        in sign.
    """

    octave: np.ndarray
    layer: np.ndarray
    pt: np.ndarray
    xi: np.ndarray
    size: np.ndarray
    contrast: np.ndarray
    edge_ratio: np.ndarray

    def __len__(self) -> int:
        return len(self.octave)

    def where(self, keep: np.ndarray) -> Extrema:
        """The extrema selected by ``keep``, an (N,) bool mask or an index array."""
        return Extrema(**{f.name: getattr(self, f.name)[keep] for f in fields(self)})


def octave_count(shape: tuple[int, int], sigma: float, layers: int, largest: float) -> int:
    """How many octaves to build for extrema at most ``largest`` pixels across on an image of
    ``shape``: those whose smallest extremum (layer 1, refined half a layer down) is at most
    that, and at most ``round(log2(min(shape))) - 2`` (``cv2.SIFT``'s count). 0 or less: none."""
    first = 2.0 * sigma * 2.0 ** (0.5 / layers)
    wanted = int(np.floor(np.log2(largest / first))) + 1 if largest >= first else 0
    return min(wanted, int(round(np.log2(max(min(shape), 1)))) - 2)


def blur_steps(sigma: float, layers: int) -> list[float]:
    """The blurs, pixels of an octave, that take each layer of a SIFT octave to the next (the
    first takes the input, counted as blurred by 0.5 px, to ``sigma``): ``layers + 4``."""
    k = 2.0 ** (1.0 / layers)
    step = [np.sqrt(max(sigma * sigma - 0.25, 0.01))]
    return step + [sigma * k ** (i - 1) * np.sqrt(k * k - 1.0) for i in range(1, layers + 4)]


def blur_reach(sigma_px: float) -> int:
    """How many pixels away ``cv2.GaussianBlur`` of a float32 image with ``sigma_px`` and no
    kernel size looks: its kernel's half-width (OpenCV's rule, 4 sigma)."""
    return (int(round(sigma_px * 8 + 1)) | 1) // 2


#: Cells of one layer of a strip of an octave's stack: the stack of a large image is built and
#: searched a strip of rows at a time (with the rows its blurs reach above and below), so it
#: holds ``layers + 4`` such layers instead of the whole octave's.
STACK_CELLS = 1 << 22


def extrema(image: np.ndarray, sigma: float, layers: int, octaves: int,
            floor: float) -> Extrema:
    """Every sample of SIFT's DoG scale space of ``image`` (rows, cols) that is an extremum of
    its 26 neighbours with ``|DoG| >= floor``, in layers 1 to ``layers + 1`` of each of at most
    ``octaves`` octaves, refined by one quadratic step clipped to half a sample in space and
    scale (a sample is an extremum's nearest one when the fit says more: the fit overshoots,
    and stepping to the next sample is what loses keypoints). ``sigma``: the base blur, pixels.

    Each octave is a stack (layers + 4) of blurs ``sigma 2^(i / layers)`` pixels of the octave,
    starting from the previous octave's layer ``layers``, halved; ``cv2.SIFT`` has one layer
    fewer: the extra one makes consecutive octaves share a DoG layer where extrema are searched,
    so an extremum at an octave's scale limit is not lost between two octaves sampled
    differently. An octave is built in strips of rows, each with the rows its blurs reach on
    either side, and gives what the whole octave's stack gives, sample for sample. Stops early
    when an octave has no sample left to search."""
    steps = blur_steps(sigma, layers)
    current = np.asarray(image, dtype=np.float32)
    found: list[Extrema] = []
    for o in range(octaves):
        rows, cols = current.shape
        blurs = steps if o == 0 else steps[1:]  # later octaves start from a blurred layer
        halo = sum(blur_reach(s) for s in blurs) + 2  # and one row each side for the peaks
        strip = max(2 * halo, STACK_CELLS // max(cols, 1)) // 2 * 2
        halved = np.empty((rows // 2, cols // 2), np.float32)
        keys, parts = [], []
        for top in range(0, rows, strip):
            lo, hi = max(0, top - halo), min(rows, top + strip + halo)
            stack = _stack(current[lo:hi], blurs, layers)
            # the next octave's rows of this strip: its even rows of layer ``layers``
            even = np.arange(top, min(top + strip, rows // 2 * 2), 2)
            halved[even // 2] = stack[layers][even - lo, : cols // 2 * 2 : 2]
            part, key = _octave_extrema(_dog(stack), o, sigma, floor,
                                        (top - lo, min(top + strip, rows) - lo), lo, rows)
            parts.append(part)
            keys.append(key)
        lay, r, c = (np.concatenate(k) for k in zip(*keys, strict=True))
        found.append(_joined(parts).where(np.lexsort((c, r, lay))))
        if min(rows, cols) < 2 * BORDER + 3:
            break
        current = halved
    return _joined(found)


def _joined(parts: list[Extrema]) -> Extrema:
    """The extrema of ``parts``, one after the other."""
    return Extrema(**{f.name: np.concatenate([getattr(e, f.name) for e in parts])
                      for f in fields(Extrema)})


def _stack(base: np.ndarray, blurs: list[float], layers: int) -> np.ndarray:
    """(layers + 4, rows, cols) float32: ``base`` (rows, cols) blurred by each of ``blurs`` in
    turn, each blur written straight into its layer; with one blur fewer than the layers (an
    octave after the first, whose base is already blurred), ``base`` itself is layer 0."""
    stack = np.empty((layers + 4, *base.shape), np.float32)
    first = len(stack) - len(blurs)
    if first:
        stack[0] = base
    previous = base
    for i, s in enumerate(blurs, start=first):
        previous = cv2.GaussianBlur(previous, (0, 0), s, dst=stack[i])
    return stack


def _dog(stack: np.ndarray) -> np.ndarray:
    """The difference of consecutive layers of ``stack`` (n, rows, cols), written over its
    first n - 1 layers (each layer is read before it is overwritten): a view of n - 1 layers."""
    for i in range(len(stack) - 1):
        np.subtract(stack[i + 1], stack[i], out=stack[i])
    return stack[:-1]


#: Cells of a strip of :func:`_peaks`: a few strips of this size stay in the CPU's cache,
#: where whole-image passes of a large image do not.
STRIP_CELLS = 1 << 18


def _peaks(dog: np.ndarray, floor: float, searched: tuple[int, int], row: int,
           total: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(layer, row, column) of every sample of layers 1 to n - 2 of the DoG stack, in its rows
    ``searched`` (first, end) and at least :data:`BORDER` from the image's edges (the stack's
    row 0 is the image's row ``row`` of ``total``), that equals the maximum (at least
    ``floor``) or the minimum (at most ``-floor``) of its 3 x 3 x 3 neighbourhood: the 3 x 3
    dilation (erosion) of the largest (smallest) of three layers, by OpenCV, which ignores
    samples beyond the border, as repeating the border would. Computed in strips of rows (each
    with one row of the next strips around it); rows of the stack, in no set order
    (:func:`extrema` orders the octave's extrema once)."""
    square = np.ones((3, 3), np.uint8)
    layers, rows, cols = dog.shape
    strip = max(1, STRIP_CELLS // cols)
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for top in range(searched[0], searched[1], strip):
        lo, hi = max(0, top - 1), min(rows, top + strip + 1)
        first, last = top - lo, top - lo + min(strip, searched[1] - top)
        for i in range(1, layers - 1):
            below, here, above = dog[i - 1, lo:hi], dog[i, lo:hi], dog[i + 1, lo:hi]
            high = cv2.dilate(np.maximum(np.maximum(below, here), above), square)
            low = cv2.erode(np.minimum(np.minimum(below, here), above), square)
            peak = ((here >= floor) & (here == high)) | ((here <= -floor) & (here == low))
            r, c = np.nonzero(peak[first:last])
            r += top
            inner = ((r + row >= BORDER) & (r + row < total - BORDER) & (c >= BORDER)
                     & (c < cols - BORDER))
            found.append((np.full(inner.sum(), i), r[inner], c[inner]))
    lay, r, c = (np.concatenate(f) for f in zip(*found, strict=True))
    return lay, r, c


def _octave_extrema(dog: np.ndarray, octave: int, sigma: float, floor: float,
                    searched: tuple[int, int], row: int, total: int
                    ) -> tuple[Extrema, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """:func:`extrema` in the rows ``searched`` of a strip of one octave's DoG stack
    (layers + 3, rows, cols), whose row 0 is the octave's row ``row`` of ``total``; with
    each extremum's (layer, row, column) in the octave, to order them by."""
    layers = dog.shape[0] - 3
    lay, r, c = _peaks(dog, floor, searched, row, total)

    def at(dl: int, dr: int, dc: int) -> np.ndarray:
        return dog[lay + dl, r + dr, c + dc].astype(np.float64)

    v = at(0, 0, 0)
    grad = 0.5 * np.stack([at(0, 0, 1) - at(0, 0, -1), at(0, 1, 0) - at(0, -1, 0),
                           at(1, 0, 0) - at(-1, 0, 0)], axis=1)
    dxx = at(0, 0, 1) + at(0, 0, -1) - 2 * v
    dyy = at(0, 1, 0) + at(0, -1, 0) - 2 * v
    dss = at(1, 0, 0) + at(-1, 0, 0) - 2 * v
    dxy = 0.25 * (at(0, 1, 1) - at(0, 1, -1) - at(0, -1, 1) + at(0, -1, -1))
    dxs = 0.25 * (at(1, 0, 1) - at(1, 0, -1) - at(-1, 0, 1) + at(-1, 0, -1))
    dys = 0.25 * (at(1, 1, 0) - at(1, -1, 0) - at(-1, 1, 0) + at(-1, -1, 0))
    hess = np.stack([np.stack([dxx, dxy, dxs], 1), np.stack([dxy, dyy, dys], 1),
                     np.stack([dxs, dys, dss], 1)], 1)
    step = np.clip(-np.einsum("nij,nj->ni", np.linalg.pinv(hess), grad), -0.5, 0.5)
    det, trace = dxx * dyy - dxy * dxy, dxx + dyy
    scale = 2.0 ** octave  # input pixels per pixel of the octave
    return Extrema(
        octave=np.full(len(lay), octave),
        layer=lay,
        pt=np.column_stack([c + step[:, 0], r + row + step[:, 1]]) * scale,
        xi=step[:, 2],
        size=2.0 * sigma * 2.0 ** ((lay + step[:, 2]) / layers) * scale,
        contrast=v + 0.5 * np.sum(grad * step, axis=1),
        edge_ratio=np.where(det > 0, trace * trace / np.where(det > 0, det, 1.0), np.inf),
    ), (lay, r + row, c)
