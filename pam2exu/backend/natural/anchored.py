"""The assembly with free degrees of freedom in natural coordinates: the configuration
nearest the model's guess that satisfies the constraints (an equality-constrained least
squares, solved by Newton's method on its optimality conditions)."""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from .solver import NaturalSettings


def anchored(terms, t0: float, z: np.ndarray, K: np.ndarray, target: np.ndarray,
             weight: np.ndarray, settings: NaturalSettings, w: np.ndarray) -> np.ndarray:
    """z minimising ½ Σ weight (K [z; 1] − target)² subject to Φ(z, t0) = 0: Newton on the
    optimality conditions, H Δz + Φ_zᵀ μ = −∇E, Φ_z Δz = −Φ (H: the Lagrangian's Hessian).

    The free degrees of freedom settle nearest the guess (an assembly with free solids).
    Raises SolverError when it does not converge.
    """
    nz, m = terms.nz, terms.m
    A = K[:, :nz]
    mu = np.zeros(m)
    t = np.array([t0])
    for _ in range(4 * settings.max_iterations):
        phi = terms.residual(t, z[None])[0]
        J = terms.dense(terms.jacobian(z[None]))[0]
        gap = K @ np.r_[z, 1.0] - target
        H = A.T @ (weight[:, None] * A) + terms.hessian(z, mu)
        kkt = np.block([[H, J.T], [J, np.zeros((m, m))]])
        rhs = -np.r_[A.T @ (weight * gap), phi]
        sol = np.linalg.lstsq(kkt, rhs, rcond=1e-13)[0]
        dz, mu = sol[:nz], sol[nz:]
        z = z + dz
        if np.max(np.abs(dz) * w, initial=0.0) <= settings.tolerance:
            return z
    raise SolverError("the natural-coordinate assembly with free degrees of freedom did not "
                      "converge")
