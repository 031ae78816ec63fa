"""Where the names go: a greedy placement of labels that do not overlap.

Each label has an anchor (a joint, a solid's middle), the reach of the symbol drawn there
(the label stays outside it) and the size of its text. In turn, in the order given, each
label tries a few places around its anchor (its preferred side first, then the eight
compass directions, each at a few distances) and takes the one of least cost: overlap with
the labels already placed and with fixed boxes (the frame's x and y) costs most, then
leaving the axes, then covering the lines of the drawing (points sampled along them), then
straying from the preferred side and from the anchor. Everything here is in display
coordinates (pixels); ``Pen.place_labels`` converts.
"""
from __future__ import annotations

import numpy as np

#: directions tried after the preferred one: E, N, W, S, then the diagonals
DIRECTIONS = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0],
                       [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]])
DIRECTIONS[4:] /= np.sqrt(2.0)
#: distances beyond the symbol's reach, in multiples of the gap
RINGS = (0.0, 1.5, 4.0, 7.0)
#: weights of the cost: overlap [px²] with labels and fixed boxes, area outside the axes
#: [px²], line points covered, rank of the direction, ring
W_OVERLAP, W_OUTSIDE, W_COVER, W_RANK, W_RING = 1e4, 1e3, 10.0, 1.0, 8.0
#: sampling step along the lines [px], margin around a box when counting covered points [px]
STEP, PAD = 3.0, 2.0


def box_at(centre, size) -> np.ndarray:
    """(x0, y0, x1, y1) = centre ∓ size/2."""
    c, h = np.asarray(centre, dtype=float), np.asarray(size, dtype=float) / 2
    return np.array([c[0] - h[0], c[1] - h[1], c[0] + h[0], c[1] + h[1]])


def overlap(box, boxes) -> float:
    """Σ area(box ∩ b) over the boxes (m, 4) [px²]."""
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    w = np.minimum(box[2], boxes[:, 2]) - np.maximum(box[0], boxes[:, 0])
    h = np.minimum(box[3], boxes[:, 3]) - np.maximum(box[1], boxes[:, 1])
    return float(np.sum(np.clip(w, 0.0, None) * np.clip(h, 0.0, None)))


def outside(box, frame) -> float:
    """Area of the box outside the frame (x0, y0, x1, y1) [px²]."""
    area = (box[2] - box[0]) * (box[3] - box[1])
    return float(area - overlap(box, frame))


def covered(box, points, pad: float = PAD) -> int:
    """Number of points (k, 2) inside the box grown by ``pad``."""
    if not len(points):
        return 0
    inside = ((points[:, 0] >= box[0] - pad) & (points[:, 0] <= box[2] + pad)
              & (points[:, 1] >= box[1] - pad) & (points[:, 1] <= box[3] + pad))
    return int(np.count_nonzero(inside))


def sample(polyline, step: float = STEP) -> np.ndarray:
    """Points every ``step`` or closer along a polyline (k, 2), NaN rows breaking it."""
    xy = np.asarray(polyline, dtype=float).reshape(-1, 2)
    out = [xy[np.isfinite(xy).all(axis=1)]]
    for a, b in zip(xy[:-1], xy[1:]):
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            continue
        n = int(np.hypot(*(b - a)) // step)
        if n > 1:
            s = np.linspace(0.0, 1.0, n + 1)[1:-1, None]
            out.append(a + s * (b - a))
    return np.vstack(out)


def candidates(anchor, reach: float, size, prefer, gap: float) -> list[tuple[np.ndarray, int, int]]:
    """(centre, rank, ring) of each place tried: the box's side or corner nearest the anchor
    at reach + ring · gap from it, along the preferred direction (rank 0) then the eight of
    ``DIRECTIONS``. ``prefer`` zero: the anchor itself first (a name inside its plate);
    None: no preferred side."""
    anchor, half = np.asarray(anchor, dtype=float), np.asarray(size, dtype=float) / 2
    out, dirs, first = [], DIRECTIONS, 0
    if prefer is not None:
        prefer = np.asarray(prefer, dtype=float)
        if np.any(prefer):
            dirs = np.vstack([prefer / np.hypot(*prefer), DIRECTIONS])
        else:
            out.append((anchor.copy(), 0, 0))
            first = 1
    for ring, k in enumerate(RINGS):
        for rank, u in enumerate(dirs, start=first):
            # the box touches the circle of radius reach + k·gap along u: its centre is
            # further out by the half size projected on u (a side or a corner)
            d = reach + k * gap
            out.append((anchor + d * u + half * np.sign(np.round(u, 6)), rank, ring))
    return out


def place(anchors, reaches, sizes, prefers, lines=(), fixed=(), frame=None,
          gap: float = 4.0) -> np.ndarray:
    """Centres (n, 2) [px] of n labels placed greedily in order (module doc).

    Parameters
    ----------
    anchors : (n, 2) array
        Where each label belongs [px].
    reaches : (n,) array
        Radius around each anchor the label keeps clear of [px].
    sizes : (n, 2) array
        Width and height of each label [px].
    prefers : sequence of (2,) arrays or None
        Preferred direction of each label from its anchor (zero: on the anchor; None: no
        preference).
    lines : (k, 2) array
        Points of the drawing's lines [px] (``sample``).
    fixed : (m, 4) array
        Boxes already there (texts that do not move) [px].
    frame : (4,) array, optional
        The axes' box [px]; labels leaving it pay ``W_OUTSIDE`` per px².
    gap : float
        Distance step between the rings of places [px].
    """
    lines = np.asarray(lines, dtype=float).reshape(-1, 2)
    boxes = [np.asarray(b, dtype=float) for b in np.asarray(fixed, dtype=float).reshape(-1, 4)]
    centres = np.zeros((len(anchors), 2))
    for i, (anchor, reach, size, prefer) in enumerate(zip(anchors, reaches, sizes, prefers)):
        best, best_cost = None, np.inf
        for centre, rank, ring in candidates(anchor, reach, size, prefer, gap):
            box = box_at(centre, size)
            cost = W_RANK * rank + W_RING * ring
            if boxes:
                cost += W_OVERLAP * overlap(box, np.array(boxes))
            if frame is not None:
                cost += W_OUTSIDE * outside(box, frame)
            if cost < best_cost:               # the count of covered points is the slow part
                cost += W_COVER * covered(box, lines)
                if cost < best_cost:
                    best, best_cost = centre, cost
        centres[i] = best
        boxes.append(box_at(best, size))
    return centres
