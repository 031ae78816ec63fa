"""The native force pass: applied and inertia forces, multipliers, reactions, power balance.

With q = (x, y, fi) per solid, the equations of motion of the constrained solids read

    Q_inertia = Q_applied + Cqᵀ λ          Q_inertia = M(q) qdd + (centrifugal terms)

so the constraint forces Cqᵀ λ follow from one linear solve per step once q, qd, qdd are
known (inverse dynamics; quasi-statics is the same with Q_inertia = 0). These λ are the
backend's static multipliers (f + Cqᵀ λ = 0, ``Backend.solve_positions(forces=True)``),
so both can be compared directly.

An element's reaction is the part of Cqᵀ λ that its own rows give to its receiving solid
(a wrench about that solid's origin), moved to the element's reporting point and turned
into its reporting basis (``Element.wrench``, ``Element.report_frame``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..elements.base import Load
from ..errors import TranslationError
from ..complex_step import as_array, scalar
from ..kinematics import (State, column, generalized_force, move_wrench, moved_to_basis, pose,
                          to_basis)
from . import native

#: a reaction component that is zero by construction must be below this × the element's force scale
ZERO_COMPONENT_TOLERANCE = 1e-9
#: steps per chunk of the dense force pass: its arrays then stay in the cache (several times
#: faster than chunks of 50,000 steps; the results do not depend on it)
CHUNK_STEPS = 4096


# ---- applied forces ----------------------------------------------------------------------

def gravity(mech, st: State, forces: bool = True) -> Load:
    """Weight (0, −m g) at each solid's G; V = Σ m g y_G (``forces=False``: V alone, the
    generalized forces left empty)."""
    force, potential = {}, np.zeros(st.n, st.q.dtype)     # complex in the complex step
    for i, s in enumerate(mech.solids):
        m = scalar(s.mass)
        if m.real > 0 and mech.gravity:
            if forces:
                G = st.point(i, [scalar(c) for c in s.cog])
                weight = np.broadcast_to([0.0, -m * mech.gravity], (st.n, 2))
                force.update(generalized_force(G, weight))
                y = G.value[:, 1]
            else:
                y = height(st, i, as_array([scalar(c) for c in s.cog]))
            potential += m * mech.gravity * y
    return Load(force, {}, potential)


def height(st: State, solid: int, local) -> np.ndarray:
    """y_G (n,) = (sin fi sx + cos fi sy) + y of the point s of a solid: ``State.point``'s
    y, the same products and sums, without its x and its Quantity."""
    c, s = st.trig(solid)
    return (s * local[0] + c * local[1]) + st.q[:, column(solid, 1)]


@dataclass
class Applied:
    """The applied forces of a mechanism at its states (rows).

    force:       Q_applied (n, nq): gravity, torsors, springs (and dampers); None when
                 not asked (``applied_forces(forces=False)``)
    outputs:     the force elements' outputs, by column name (``spring1.Força``)
    potential:   V (n,), gravity and springs
    dissipation: power removed by the dampers (n,)
    external:    generalized force of the loads without a potential (torsors), (n, nq)
    """

    force: np.ndarray
    outputs: dict[str, np.ndarray]
    potential: np.ndarray
    dissipation: np.ndarray
    external: np.ndarray


def applied_forces(mech, st: State, damping: bool, forces: bool = True) -> Applied:
    """Sum the loads of gravity and of every force element (dampers only if ``damping``;
    ``forces=False``: without Q_applied, only the outputs, energies and torsors' forces)."""
    n, dtype = st.n, st.q.dtype                              # complex in the complex step
    out = Applied(np.zeros((n, mech.nq), dtype) if forces else None, {}, np.zeros(n, dtype),
                  np.zeros(n, dtype), np.zeros((n, mech.nq), dtype))
    loads = [(None, gravity(mech, st, forces))] + [(el, el.loads(st, damping))
                                                   for el in mech.elements]
    for el, load in loads:
        if load is None:
            continue
        target = out.force if load.potential is not None else out.external
        for solid, q in load.force.items() if target is not None else ():
            target[:, pose(solid)] += q
        if load.potential is not None:
            out.potential += load.potential
        if load.dissipation is not None:
            out.dissipation += load.dissipation
        out.outputs.update({f"{el.name}.{k}": v for k, v in load.outputs.items()})
    if forces:
        out.force += out.external
    return out


def inertia_forces(mech, st: State, qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(Q_inertia (n, nq), kinetic energy (n,)): m a_G at G and J_G α, for every solid.

    a_G = R̈ + α Ω(A c) − ω² A c,  Q = Jᵀ(m a_G) + (0, 0, J_G α),  T = ½ m v_G² + ½ J_G ω².
    """
    dtype = np.result_type(st.q, qdd)                        # complex in the complex step
    Q, T = np.zeros((st.n, mech.nq), dtype), np.zeros(st.n, dtype)
    for i, s in enumerate(mech.solids):
        m, J = scalar(s.mass), scalar(s.inertia)
        if m == 0 and J == 0:
            continue
        cols = pose(i)
        G = st.point(i, [scalar(c) for c in s.cog])
        block = G.jac[i]
        a_G = np.einsum("ndk,nk->nd", block, qdd[:, cols]) + G.conv
        Q[:, cols] += np.einsum("nd,ndk->nk", m * a_G, block)
        fi = column(i, 2)
        Q[:, fi] += J * qdd[:, fi]
        w = st.qd[:, fi]
        T += 0.5 * m * np.sum(G.rate**2, axis=1) + 0.5 * J * w * w
    return Q, T


# ---- reactions ---------------------------------------------------------------------------

def element_wrench(el, st: State, lam: np.ndarray, jacobian=None) -> np.ndarray:
    """The wrench (n, 3) an element's multipliers λ (n, k) apply to its receiving solid.

    Force and moment about the solid's origin come from Cqᵀ λ restricted to the element's
    rows and the solid's columns; they are then moved to the reporting point and turned
    into the reporting basis (x, y, moment).
    """
    s = el.receiver
    if jacobian is None:
        jacobian = el.constraint(st)[0].jac
    block = jacobian.get(s)
    if block is None:
        return np.zeros((st.n, 3))
    return reported_wrench(el, st, np.einsum("nkj,nk->nj", block, lam))


def reported_wrench(el, st: State, wrench: np.ndarray) -> np.ndarray:
    """A wrench (n, 3) on the element's receiving solid, about the solid's origin, moved to
    the element's reporting point and turned into its reporting basis."""
    point, direction = el.report_frame(st)
    return to_basis(move_wrench(wrench, st.q[:, pose(el.receiver)][:, :2], point), direction)


def reported(el) -> list[int]:
    """Indices of the wrench components an element reports."""
    return [k for k, name in enumerate(el.wrench) if name is not None]


def reactions(mech, st: State, lam: np.ndarray, parts=None) -> dict[str, np.ndarray]:
    """Every constraint element's reported reaction components, by column name.

    The components that are zero by construction (the tangential force of a prismatic
    or pin_slot, the moment at a revolute…) are checked to be zero. ``parts``: the
    elements' constraint quantities when already built (``native.Equations.parts``).
    """
    if parts is None:
        parts = [el.constraint(st)[0] for el in mech.constraints]
    if not mech.constraints:
        return {}
    return checked_reactions(mech, np.stack([element_wrench(el, st, lam[:, rows], v.jac)
                                             for el, rows, v in zip(mech.constraints,
                                                                    mech.rows, parts)], axis=1))


def checked_reactions(mech, wrenches: np.ndarray, views: bool = False
                      ) -> dict[str, np.ndarray]:
    """The reported components of every constraint element's wrench in its reporting frame
    (``wrenches`` (n, constraints, 3), in ``mech.constraints`` order), by column name
    (``views``: views of ``wrenches``, for a caller that copies them, not columns of their
    own); the components that are zero by construction are checked to be zero."""
    out, length = {}, mech.scale()
    if not mech.constraints:
        return out
    largest = np.max(np.abs(wrenches), axis=0, initial=0.0)         # (constraints, 3)
    scales = (np.maximum(largest[:, 0], largest[:, 1]) + largest[:, 2] / length).tolist()
    columns = np.moveaxis(wrenches, 0, -1)                          # (constraints, 3, n)
    if not views:
        columns = np.ascontiguousarray(columns)
    for e, (el, top, scale) in enumerate(zip(mech.constraints, largest.tolist(), scales)):
        for k, name in enumerate(el.wrench):
            if name is not None:
                out[f"{el.name}.{name}"] = columns[e, k]
                continue
            size = top[k] / (length if k == 2 else 1.0)
            if size > ZERO_COMPONENT_TOLERANCE * scale + 1e-300:
                what = ("moment" if k == 2 else
                        "force along x" if k == 0 else "force along y")
                raise TranslationError(
                    f"internal error: the reaction of element '{el.name}' ({el.type}) has a "
                    f"{what} of relative size {size / scale:.2g} in its reporting frame, where "
                    "it must be zero. Please report it with the model file.")
    return out


def _report_matrix(mech, st: State, parts) -> np.ndarray:
    """B (n, m, m): the reported reaction components of each element per unit multiplier.

    Block-diagonal, one square block per element (each reports as many components as it
    has equations).
    """
    B = np.zeros((st.n, mech.n_equations, mech.n_equations), st.q.dtype)
    for el, rows, v in zip(mech.constraints, mech.rows, parts):
        jac = v.jac
        keep = reported(el)
        for j in range(el.equations):
            unit = np.zeros((st.n, el.equations))
            unit[:, j] = 1.0
            B[:, rows, rows.start + j] = element_wrench(el, st, unit, jac)[:, keep]
    return B


def multipliers(mech, st: State, rhs: np.ndarray, redundant: bool,
                rcond: float = 1e-10, eq: native.Equations | None = None) -> np.ndarray:
    """λ (n, m) with Cqᵀ λ = rhs at every step (``eq``: the equations at ``st`` when
    already evaluated).

    Redundant constraints: of all solutions, the one whose reported reaction components
    R = B λ have the least sum of squares: R = (Cqᵀ B⁻¹)⁺ rhs, λ = B⁻¹ R.
    """
    if not redundant and mech.n_equations >= native.SPARSE_FROM:
        lam = _sparse_multipliers(mech, st, rhs)
        if lam is not None:
            return lam
    if eq is None or eq.jacobian is None:
        eq = native.equations(mech, st)
    if not redundant:
        return _solve_transposed(mech, eq.jacobian, rhs)
    A = np.swapaxes(eq.jacobian, 1, 2)                                  # Cqᵀ, (n, nq, m)
    B = _report_matrix(mech, st, eq.parts)
    AB = np.swapaxes(np.linalg.solve(np.swapaxes(B, 1, 2), np.swapaxes(A, 1, 2)), 1, 2)
    R = np.einsum("nmq,nq->nm", least_norm_inverse(AB, rcond), rhs)
    return np.linalg.solve(B, R[..., None])[..., 0]


def least_norm_inverse(A: np.ndarray, rcond: float) -> np.ndarray:
    """A⁺ per step (A (n, r, c)): ``numpy.linalg.pinv``; in the complex step, where A has
    full row rank, A⁺ = Aᵀ(A Aᵀ)⁻¹ with plain transposes (analytic: pinv conjugates)."""
    if not np.iscomplexobj(A):
        return np.linalg.pinv(A, rcond=rcond)
    At = np.swapaxes(A, 1, 2)
    return np.swapaxes(np.linalg.solve(A @ At, np.swapaxes(At, 1, 2)), 1, 2)


def _solve_transposed(mech, J: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """λ with Jᵀ λ = rhs per step, J = Cq (n, m, nq) square, the fixed links solved apart.

    A fixed link's rows of Cq are the identity on its solid's columns H and zero elsewhere,
    so Cqᵀ is block-triangular: Cq[r, M]ᵀ λ_r = rhs_M on the other rows r and the moving
    columns M (one smaller solve), then λ_fixed = rhs_H − Cq[r, H]ᵀ λ_r.
    """
    rows, cols = native.moving(mech)
    fixed = [(rr.start + k, column(el.holds, k))
             for el, rr in zip(mech.constraints, mech.rows) if el.grounds for k in range(3)]
    held = [h for _, h in fixed]
    if len(rows) != len(cols) or len(set(held)) != len(held):
        return np.linalg.solve(np.swapaxes(J, 1, 2), rhs[..., None])[..., 0]
    lam = np.empty(rhs.shape[:1] + J.shape[1:2], np.result_type(J, rhs))
    A = np.swapaxes(J[:, rows[:, None], cols], 1, 2)
    lam[:, rows] = np.linalg.solve(A, rhs[:, cols, None])[..., 0] if len(rows) else 0.0
    if fixed:
        g, h = (np.array(x) for x in zip(*fixed))
        lam[:, g] = rhs[:, h] - np.einsum("nrh,nr->nh", J[:, rows[:, None], h], lam[:, rows])
    return lam


@dataclass
class Energies:
    """Per step: kinetic + potential energy [J], damper dissipation [W], torsor power [W]."""

    energy: np.ndarray
    dissipation: np.ndarray
    external: np.ndarray


def over_time(mech, t, q, redundant: bool, qd=None, qdd=None):
    """Every reaction, spring and actuator force at every step: (outputs, Energies or None).

    Cqᵀ λ = Q_inertia − Q_applied per step (kinetostatic, with qd and qdd: inertia and
    damper terms, and the energies of the power balance); with qdd None, Cqᵀ λ = −Q_applied
    without damper terms (quasi-static equilibrium, no energies).
    """
    n = len(t)
    dynamic = qdd is not None
    out: dict[str, np.ndarray] = {}
    dtype = np.result_type(q, qd, qdd)                       # complex in the complex step
    energies = Energies(*(np.zeros(n, dtype) for _ in range(3))) if dynamic else None
    sparse = mech.n_equations >= native.SPARSE_FROM
    for s in native.chunks(mech, n, sparse, most=None if sparse else CHUNK_STEPS):
        st = State(t[s], q[s], qd[s] if dynamic else None)
        applied = applied_forces(mech, st, damping=dynamic)
        rhs = -applied.force
        if dynamic:
            inertia, kinetic = inertia_forces(mech, st, qdd[s])
            rhs += inertia
            energies.energy[s] = kinetic + applied.potential
            energies.dissipation[s] = applied.dissipation
            energies.external[s] = np.sum(applied.external * qd[s], axis=1)
        # Cq once per chunk, for the multipliers and the reactions (large mechanisms
        # assemble their own sparse Cq)
        eq = native.equations(mech, st, jacobian=redundant
                              or mech.n_equations < native.SPARSE_FROM)
        lam = multipliers(mech, st, rhs, redundant, eq=eq)
        for name, v in {**reactions(mech, st, lam, eq.parts), **applied.outputs}.items():
            out.setdefault(name, np.empty(n, dtype))[s] = v
    return out, energies


def over_time_given(mech, t, q, qd, given):
    """``over_time`` of a kinetostatic run whose constraint wrenches a backend gave
    (``Backend.reactions``: each element's wrench on its receiver about the receiver's
    origin, and the kinetic energy): the reactions reported and checked, the force
    elements' outputs and the energies of the power balance from the applied forces."""
    n = len(t)
    out: dict[str, np.ndarray] = {}
    energies = Energies(*(np.zeros(n) for _ in range(3)))
    for s in native.chunks(mech, n, most=CHUNK_STEPS):
        st = State(t[s], q[s], qd[s])
        applied = applied_forces(mech, st, damping=True, forces=False)
        energies.energy[s] = given.kinetic[s] + applied.potential
        energies.dissipation[s] = applied.dissipation
        energies.external[s] = np.sum(applied.external * qd[s], axis=1)
        wrenches = reported_wrenches(mech, st, given.wrenches[s])
        if given.modes is not None:
            wrenches = _least_reported(mech, st, wrenches, given.modes[s])
        whole = s.start == 0 and s.stop == n          # one chunk: its arrays are the columns
        found = checked_reactions(mech, wrenches, views=not whole)    # (else copied below)
        for name, v in {**found, **applied.outputs}.items():
            if whole and isinstance(v, np.ndarray) and v.shape == (n,) and v.dtype == float:
                out[name] = v
            else:
                out.setdefault(name, np.empty(n))[s] = v
    return out, energies


def reported_wrenches(mech, st: State, wrenches: np.ndarray) -> np.ndarray:
    """``reported_wrench`` of every constraint element at once: ``wrenches`` (n,
    constraints, 3) on their receivers about the receivers' origins, in ``mech.constraints``
    order, moved to the reporting points and turned into the reporting bases."""
    if not mech.constraints:
        return np.array(wrenches, dtype=float)
    at, shape = st.values_only(), (st.n, len(mech.constraints), 2)
    frames = [el.report_frame(at) for el in mech.constraints]   # (n, 2) each: side by side
    point = np.concatenate([f[0] for f in frames], axis=1).reshape(shape)
    direction = np.concatenate([f[1] for f in frames], axis=1).reshape(shape)
    origin = st.q[:, [[column(el.receiver, 0), column(el.receiver, 1)]
                      for el in mech.constraints]]
    return moved_to_basis(wrenches, origin, point, direction)


def _least_reported(mech, st: State, wrenches: np.ndarray, modes: np.ndarray) -> np.ndarray:
    """The reported wrenches (n, constraints, 3) plus the self-stresses' combination
    (``modes`` (n, r, constraints, 3), about the receivers' origins) that makes the reported
    components least in sum of squares: the native pass's least norm (``multipliers``)."""
    shown = [reported(el) for el in mech.constraints]
    moved = [reported_wrenches(mech, st, modes[:, j]) for j in range(modes.shape[1])]
    R0 = np.concatenate([wrenches[:, k, keep] for k, keep in enumerate(shown)], axis=1)
    S = np.stack([np.concatenate([mode[:, k, keep] for k, keep in enumerate(shown)], axis=1)
                  for mode in moved], axis=1)                              # (n, r, K)
    c = -np.einsum("njk,nk->nj", least_norm_inverse(np.swapaxes(S, 1, 2), 1e-10), R0)
    return np.stack([wrenches[:, k] + np.einsum("nj,njd->nd", c,
                                                np.stack([mode[:, k] for mode in moved], axis=1))
                     for k in range(len(shown))], axis=1)


def _sparse_multipliers(mech, st: State, rhs: np.ndarray):
    """λ with Cqᵀ λ = rhs for all states by one sparse LU (large mechanisms); None if singular."""
    from scipy.sparse.linalg import splu
    try:
        lu = splu(native.sparse_jacobian(mech, st).T.tocsc())
    except RuntimeError:
        return None
    return lu.solve(np.ascontiguousarray(rhs).ravel()).reshape(st.n, mech.n_equations)


def equilibrium_residual(mech, st: State, lam: np.ndarray, rhs: np.ndarray,
                         jacobian: np.ndarray | None = None) -> np.ndarray:
    """Cqᵀ λ − rhs (n, nq)."""
    if jacobian is None:
        jacobian = native.equations(mech, st).jacobian
    return np.einsum("nmq,nm->nq", jacobian, lam) - rhs


# ---- power balance -----------------------------------------------------------------------

@dataclass
class PowerBalance:
    """Σ actuator power = dE/dt + damper dissipation − torsor power, with dE/dt from
    fourth-order central differences of E = T + V on the time grid.

    error:     max |residual| over the checked steps [W]
    tolerance: the difference's own error, estimated from the same difference over twice
               the step (Richardson: error ≈ (D(2h) − D(h))/15), plus round-off [W]
    checked:   number of steps checked (not those whose stencil crosses a law breakpoint,
               where the motion is not smooth)
    """

    error: float
    tolerance: float
    checked: int

    @property
    def ok(self) -> bool:
        return self.error <= self.tolerance


def derivative(f: np.ndarray, k: slice, h: int, dt: float) -> np.ndarray:
    """f'(t_k) ≈ (−f[k+2h] + 8 f[k+h] − 8 f[k−h] + f[k−2h]) / (12 h dt), error O((h dt)⁴),
    at the steps k of a slice (step 1)."""
    def at(j):
        return f[k.start + j:k.stop + j]
    return (-at(2 * h) + 8 * at(h) - 8 * at(-h) + at(-2 * h)) / (12 * h * dt)


def power_balance(mech, t: np.ndarray, actuator_power: np.ndarray, energy: np.ndarray,
                  dissipation: np.ndarray, external_power: np.ndarray) -> PowerBalance | None:
    """Check the power balance at the steps k = 4 … n−5 (None with fewer than 9 rows)."""
    n = len(t)
    if n < 9:
        return None
    dt = float(t[1] - t[0])
    k = slice(4, n - 4)
    d1, d2 = derivative(energy, k, 1, dt), derivative(energy, k, 2, dt)
    residual = actuator_power[k] - (d1 + dissipation[k] - external_power[k])
    breakpoints = [b for el in mech.drivers for b in el.time_law().breakpoints()]
    if breakpoints:
        keep = np.ones(n - 8, dtype=bool)
        for b in breakpoints:
            keep &= ~((t[:n - 8] < b) & (b <= t[8:]))
        if not keep.any():
            return PowerBalance(0.0, 0.0, 0)
        residual, d1, d2 = residual[keep], d1[keep], d2[keep]
    checked = len(residual)
    error, change, power, rate, dissipated, external, stored = _largest(
        [residual, d2 - d1, actuator_power, d1, dissipation, external_power, energy])
    truncation = change / 15.0
    size = max(power, rate, dissipated, external)
    roundoff = 1e3 * np.finfo(float).eps * stored / dt
    tolerance = 10.0 * truncation + 1e-9 * size + roundoff
    return PowerBalance(float(error), float(tolerance), checked)


def _largest(arrays: list) -> list[float]:
    """max |a| of each of the (non-empty) arrays, in one pass over them joined."""
    ends = np.cumsum([0] + [len(a) for a in arrays[:-1]])
    return np.maximum.reduceat(np.abs(np.concatenate(arrays)), ends).tolist()


def actuator_power(mech, st: State, outputs: dict[str, np.ndarray]) -> np.ndarray:
    """Σ (actuator force or torque) × Df(t): Mz·Df of angular, Força·Df of linear actuators."""
    power = np.zeros(st.n, st.q.dtype)
    for el in mech.drivers:
        name = next(n for n in el.wrench if n is not None)
        power += outputs[f"{el.name}.{name}"] * el.time_law()(st.t)[1]
    return power


__all__ = ["Applied", "PowerBalance", "applied_forces", "actuator_power",
           "checked_reactions", "element_wrench", "equilibrium_residual", "gravity",
           "inertia_forces", "multipliers", "over_time_given", "power_balance", "reactions",
           "reported_wrench", "reported_wrenches"]
