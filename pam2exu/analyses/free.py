"""The motions the constraints leave free at a configuration, and the solids they move:
what the equilibrium analysis's stability check and the dynamic analysis's inertia check
work on (``rank.mobility`` counts them for the rank test of every analysis)."""
from __future__ import annotations

import numpy as np

from .rank import _rank


def free_motions(mech, t: float, q: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Z (nq, k): an orthonormal basis of ker Cq at (q, t), the motions the constraints
    allow, in ``_rank``'s coordinates (x, y and the angles times the length scale)."""
    found = _rank(mech, t, q, rtol)
    if found is None:
        return np.eye(mech.nq)
    _, _, Vt, rank = found
    return Vt[rank:].T


def moving_solids(mech, motions: np.ndarray, rtol: float = 1e-6) -> list[str]:
    """The solids that motions (nq, k) in ``free_motions``' coordinates move, largest
    first: those whose share is above ``rtol`` of the largest one's."""
    size = np.linalg.norm(np.reshape(motions, (len(mech.solids), 3, -1)), axis=(1, 2))
    return [mech.solids[i].name for i in np.argsort(-size, kind="stable")
            if size[i] > rtol * np.max(size)]
