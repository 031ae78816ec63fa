"""Static equilibrium with free degrees of freedom (shared/spec/dynamics.md, ``equilibrium``).

The actuators hold their laws' values at t = 0; the free degrees of freedom settle where
gravity, the torsors and the springs (without their damper terms) balance. The backend's
static equilibrium (``Backend.static_equilibrium``: Exudyn's static solver with the masses
and force elements, or Newton on the natural coordinates' equilibrium) finds the
configuration from the assembled guess; the native pass gives the reactions and checks
them; the equilibrium must be stable: on the constraint manifold the reduced tangent stiffness

    K_r = Zᵀ (−∂Q/∂q − Σ_i λ_i ∂²C_i/∂q²) Z,   Z an orthonormal basis of ker C_q,

(the second variation of the potential energy, λ with C_qᵀλ = −Q) is positive definite.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..kinematics import State
from ..registry import backends_that
from . import force_pass, free
from .job import Job, check_mobility, collect, warn
from .positions import GUESS_STIFFNESS, assemble, check_residual
from .quasi_static import quasi_static

#: an eigenvalue of the reduced stiffness at most this fraction of the largest stiffness
#: term counts as zero (a neutral equilibrium)
NEUTRAL = 1e-8
#: the step of the central differences of Q, relative to the length scale (and in rad)
STEP = 1e-6
#: a descent step that moves less than this fraction of the length scale (and rad) is
#: followed by the static solver without the proximal springs
NEWTON_FROM = 1e-2
#: a descent step that moves at most this fraction of the length scale (and rad) did not
#: move: it started on an equilibrium (round-off of the backend's solve)
STILL = 1e-12
#: round-off allowed in comparing potential energies, relative
ENERGY_ROUNDOFF = 1e-12
#: the most proximal steps of the descent
DESCENT_STEPS = 200


class StabilityWarning(UserWarning):
    """The equilibrium found is unstable or neutral (``equilibrium``)."""


@dataclass
class Stability:
    """The reduced tangent stiffness at an equilibrium (scaled: angles × the length scale,
    so that every entry is in N/m)."""

    eigenvalues: np.ndarray     # ascending, of the symmetric part of K_r
    modes: np.ndarray           # (nq, k): the modes, in x, y and L·fi of every solid
    size: float                 # the largest |entry| of the full stiffness, for NEUTRAL

    @property
    def smallest(self) -> float:
        return float(self.eigenvalues[0]) if self.eigenvalues.size else np.inf

    @property
    def stable(self) -> bool:
        return self.smallest > NEUTRAL * self.size


def equilibrium(job: Job):
    """x, y, fi, f(t), ro, fi_rel, every reaction, spring and actuator force at t = 0, the
    free degrees of freedom in a stable static equilibrium (shared/spec/dynamics.md).

    A fully driven model gives the first row of ``quasi_static``. Otherwise, from the
    assembly nearest to the guess (``assemble``, with the guess springs of ``assembly``),
    the potential energy is descended by proximal steps (``descend``), each one the
    backend's ``static_equilibrium`` with springs tying the solids to the last step; then
    the same without the springs gives the equilibrium exactly. Not stable (``reduced_stiffness``):
    a ``StabilityWarning``. No equilibrium: a ModelError naming the free solids.
    """
    mech = job.mech
    mob = check_mobility(job, mech.initial_q(), need_driven=False)
    if mob.dof == 0:
        return quasi_static(job)
    if not job.backend.moves_free_solids:
        able = backends_that(lambda b: b.moves_free_solids)
        raise ModelError(
            f"the {job.backend.name} backend cannot solve a static equilibrium with free "
            f"degrees of freedom (the solids {', '.join(repr(n) for n in mob.free_solids)} "
            f"are free): run the equilibrium analysis on the {' or '.join(able)} backend "
            f"(backend = \"{able[0]}\", --backend {able[0]})")
    redundant = mob.redundant > 0
    start = assemble(job, redundant, GUESS_STIFFNESS)
    job.stage = f"descending the potential energy with {job.backend.solver_name}"
    q, lam, error = descend(job, start, redundant)
    if q is None:
        raise _no_equilibrium(job, mob, error)
    stability = reduced_stiffness(mech, float(job.times[0]), q, lam)
    job.info["stiffness_eigenvalue"] = stability.smallest
    if not stability.stable:
        kind = "unstable" if stability.smallest < -NEUTRAL * stability.size else "neutral"
        warn(job, f"the equilibrium found is {kind}: the smallest eigenvalue of the reduced "
                  f"tangent stiffness is {stability.smallest:.3g} N/m (angles scaled by the "
                  f"length scale {mech.scale():g} m); its mode moves the solids "
                  f"{_quoted(free.moving_solids(mech, stability.modes[:, :1]))}. "
                  "Start from a guess off it, on "
                  "the side of the stable configuration you expect", StabilityWarning)
    check_residual(mech, job.times, q[None], job)
    job.stage = "computing the reactions (static equilibrium)"
    out, _ = force_pass.over_time(mech, job.times, q[None], redundant=True)
    return collect(job, q[None], extra=out)


def descend(job: Job, start: np.ndarray, redundant: bool):
    """(q, λ, error): the equilibrium reached from ``start`` by descending the potential
    energy (q None, with the solver's last message, when there is none).

    Proximal steps q_(n+1) = argmin V(q) + ½ k |q − q_n|² on the constraints (angles scaled
    by the length scale), each one the backend's ``static_equilibrium`` with springs of
    stiffness k tying q to q_n (``anchor_stiffness``): for k above the largest
    negative curvature each step is a strictly convex problem whose solution lowers V, so
    the descent does not stop on an unstable equilibrium it does not start exactly on.
    k halves after each step solved and doubles after a failure. Once a step moves less
    than ``NEWTON_FROM`` of the length scale, the static equilibrium without the springs
    is tried: its equilibrium is taken when it lies as near (Newton did not jump to another
    branch), is stable and its V is not above the step's, else the descent goes on. A
    step that does not move (``STILL``) starts on an equilibrium: that one is taken, stable or
    not (``equilibrium`` warns).
    """
    mech, t = job.mech, float(job.times[0])
    scale = np.tile([mech.scale(), mech.scale(), 1.0], len(mech.solids))
    k = _initial_stiffness(mech, t, start)
    q, error = start, None
    for _ in range(DESCENT_STEPS):
        found = job.backend.static_equilibrium(mech, t, q, job.solver, redundant=redundant,
                                               anchor_stiffness=k)
        if not found.solved:
            k, error = 2.0 * k, found.error
            continue
        step = float(np.max(np.abs(found.q[0] - q) / scale))
        q, k = found.q[0], 0.5 * k
        if step <= NEWTON_FROM:
            exact = job.backend.static_equilibrium(mech, t, q, job.solver,
                                                   redundant=redundant)
            if exact.solved:
                qe, lam = exact.q[0], exact.multipliers[0]
                near = float(np.max(np.abs(qe - q) / scale)) <= NEWTON_FROM
                lower = potential(mech, t, qe) <= potential(mech, t, q) + ENERGY_ROUNDOFF * max(
                    1.0, abs(potential(mech, t, q)))
                if near and (step <= STILL or (lower and reduced_stiffness(mech, t, qe,
                                                                         lam).stable)):
                    return qe, lam, None
            error = exact.error
    return None, None, error or (f"the descent had not settled after {DESCENT_STEPS} "
                                 "steps: the loads keep moving the free solids")


def _initial_stiffness(mech, t: float, q: np.ndarray) -> float:
    """The first proximal stiffness [N/m]: the largest of the load stiffness at q and the
    applied forces over the length scale (so that the first step moves ~ the length scale)."""
    L = mech.scale()
    scale = np.tile([1.0, 1.0, L], len(mech.solids))
    K = _load_stiffness(mech, t, q) / np.outer(scale, scale)
    Q = force_pass.applied_forces(mech, State([t], q[None]), damping=False).force[0] / scale
    return max(float(np.max(np.abs(K), initial=0.0)), float(np.max(np.abs(Q))) / L, 1e-6)


def potential(mech, t: float, q: np.ndarray) -> float:
    """V(q): the potential energy of gravity and the springs [J]."""
    return float(force_pass.applied_forces(mech, State([t], q[None]), damping=False)
                 .potential[0])


def reduced_stiffness(mech, t: float, q: np.ndarray, lam: np.ndarray) -> Stability:
    """K_r = Zᵀ (−∂Q/∂q − Σ λ_i ∂²C_i/∂q²) Z on ker C_q, symmetric part, angles scaled by
    the length scale (∂Q/∂q by central differences, step ``STEP``; C_qq exact)."""
    scale = np.tile([1.0, 1.0, mech.scale()], len(mech.solids))
    K = -_load_stiffness(mech, t, q) - _constraint_curvature(mech, t, q, lam)
    K = K / np.outer(scale, scale)                       # in the scaled coordinates
    K = 0.5 * (K + K.T)
    Z = free.free_motions(mech, t, q)
    values, vectors = np.linalg.eigh(Z.T @ K @ Z)
    size = max(float(np.max(np.abs(K), initial=0.0)), np.finfo(float).tiny)
    return Stability(values, Z @ vectors, size)


def _load_stiffness(mech, t: float, q: np.ndarray) -> np.ndarray:
    """∂Q/∂q (nq, nq) of the applied forces without dampers, by central differences."""
    h = STEP * np.tile([mech.scale(), mech.scale(), 1.0], len(mech.solids))
    states = np.concatenate([q + np.diag(h), q - np.diag(h)])
    Q = force_pass.applied_forces(mech, State(np.full(len(states), t), states),
                                  damping=False).force
    n = len(q)
    return ((Q[:n] - Q[n:]) / (2 * h[:, None])).T


def _constraint_curvature(mech, t: float, q: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """Σ λ_i ∂²C_i/∂q² (nq, nq), exact (``Quantity.weighted_hessian``)."""
    st = State([t], q[None], hessians=True)
    W = np.zeros((1, mech.nq, mech.nq))
    for el, rows in zip(mech.constraints, mech.rows):
        v, _ = el.constraint(st)
        v.weighted_hessian(np.asarray(lam, dtype=float)[None, rows], W)
    return W[0]


def _quoted(names: list[str]) -> str:
    return ", ".join(f"'{n}'" for n in names)


def _no_equilibrium(job, mob, error) -> ModelError:
    names = ", ".join(f"'{n}'" for n in mob.free_solids)
    return ModelError(
        f"t=0: no static equilibrium found for the free solids {names}: the loads on them "
        "(gravity, torsors, springs) are not balanced in any configuration near the "
        "assembled guess. Add a spring or a support that can balance them, drive the free "
        "degree of freedom with an actuator, or start from a guess nearer the equilibrium. "
        f"{job.backend.solver_name} said: {error}")
