"""The reactions of the kinetostatic analysis from natural-coordinate inverse dynamics
(``Natural.reactions``).

From the motion (``inverse``): each solid's constraint forces W_b = M_b ζ̈_b − Q_b on its
base point and base vector, and the multipliers μ of M z̈ + Φ_zᵀ μ = Q. Then every
constraint element's wrench on its receiving solid:

- an element with equations (prismatic, pin_slot, transmission, the actuators): its rows
  written in each solid's own frame, ζ̂ = (p_s, v_s, fi_s) (``_FrameEquations``), give the
  force it applies to solid s, −(∂Φ_el/∂ζ̂_s)ᵀ μ_el: a force F on p, a moment from v and fi,
  about the origin O: (F, p × F + G_v·Ω v + G_fi);
- a revolute whose two points are one basic point P (no equation): per-body equilibrium at
  P. The forces on solid s's own copy of P's coordinates are A_sᵀ W_s plus those of s's rigid
  rows and of the element rows through s's frame; what is left is the force of the
  revolutes at P on s. At a ground point (a constant, no coordinate) it is what s's wrench
  balance leaves (W_s's wrench minus every other element's on s). With several solids at
  one point, the revolutes' forces follow from the solids' by the point's incidence
  (least norm for a closed cycle of revolutes);
- a fixed link: the held solid's balance, W of its loads minus every element's wrench on it
  (an element's wrench on a ground solid is minus the sum on its moving solids).

Redundant constraints: μ of least norm, and the wrenches of the self-stresses (μ in the
null space of Φ_zᵀ without load), of which the analysis adds the combination that makes
the reported components least in norm, as its reference-point pass does.

Not handled (``None``: the analysis's reference-point pass runs): every solid held (no
coordinate), a revolute whose points could not share a basic point (two equations on basic
points, not on frames), a solid pinned to the ground at two points, an element between
ground solids only, two fixed links on one solid.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import sparse

from ...kinematics import ANGLES, column, cross, perp, pose
from ..base import Reactions
from . import inverse
from .forms import ONE, Expr, Vec
from .formulation import Formulation
from .terms import Terms

#: steps per chunk at most (arrays that stay in the cache; the results do not depend on it)
CHUNK_STEPS = 4096
#: bytes of one chunk's largest Jacobian at most (large mechanisms: fewer steps per chunk)
CHUNK_BYTES = 1 << 24


class _FrameEquations(Formulation):
    """The element equations of a formulation with each moving solid's base point, base
    vector and angle as variables of its own (ζ̂), in the formulation's row order."""

    def __init__(self, form: Formulation):           # no Formulation.__init__: reuse form's
        self.mech, self.grounds, self.form = form.mech, form.grounds, form
        self.start: dict[int, int] = {}              # solid -> its first variable
        frames, n = [], 0
        for i, f in enumerate(form.frames):
            if i in form.grounds:
                frames.append(f)
                continue
            self.start[i] = n
            p, v = (Vec(Expr.coordinate(n + k), Expr.coordinate(n + k + 1)) for k in (0, 2))
            n += 4
            angle = None
            if f.angle is not None:
                angle, n = n, n + 1
            frames.append(replace(f, p=p, v=v, angle=angle))
        self.frames, self.nz = frames, n
        self._rows, self.owners, self.unshared = [], [], False
        for el in form.mech.elements:
            el.natural(self)

    def coincide(self, ref1, ref2, element=None) -> None:
        """A revolute: none of its own equations where its points share a basic point."""
        a, b = (self.form.basic[(r.solid, tuple(r.local))] for r in (ref1, ref2))
        if a != b:
            self.unshared = True

    def equation(self, element, expressions, target=0.0, power: int = 1) -> None:
        before = len(self._rows)
        super().equation(element, expressions, target, power)
        self.owners += [element] * (len(self._rows) - before)


def _rigid_owners(form: Formulation) -> list[int]:
    """The solid of each rigid-body row (the formulation's first rows), in order."""
    owners = []
    for i in range(len(form.frames)):
        if i in form.grounds:
            continue
        alone = object.__new__(Formulation)        # the formulation's own rows, one solid
        alone.mech, alone.frames, alone.own = form.mech, form.frames, form.own
        alone.grounds = {j: None for j in range(len(form.frames)) if j != i}
        alone._rows = []
        alone._rigid_equations()
        owners += [i] * len(alone._rows)
    return owners


@dataclass
class _Pin:
    """The revolutes at one shared basic point: its columns (None: a ground point), the
    moving solids there, and the incidence's least-norm inverse (revolute forces from the
    solids' forces)."""

    columns: np.ndarray | None
    constant: np.ndarray | None
    solids: list
    revolutes: list               # indices into mech.constraints
    inverse: np.ndarray           # (revolutes, solids)


class Plan:
    """What the natural reactions need of a formulation, made once (``plan``)."""

    def __init__(self, form: Formulation):
        mech = form.mech
        self.form, self.mech = form, mech
        self.frame_eq = eq = _FrameEquations(form)
        self.terms = Terms(eq.nz, [r[1:] for r in eq._rows])
        self.first = form.m - len(eq._rows)            # the element rows' first row
        self.ok = (form.nz > 0 and not eq.unshared       # nz = 0: every solid held
                   and form.labels[self.first:] == [r[0] for r in eq._rows])
        self.rigid = np.array(_rigid_owners(form), dtype=int)
        self.ok &= len(self.rigid) == self.first
        self.moving = [i for i in range(len(form.frames)) if i not in form.grounds]
        self.angle_cols = {i: form.frames[i].angle for i in self.moving
                           if form.frames[i].angle is not None}
        index = {el: k for k, el in enumerate(mech.constraints)}
        self.rows_of: dict[int, np.ndarray] = {}
        for r, el in enumerate(eq.owners):
            self.rows_of.setdefault(index[el], []).append(r)
        self.rows_of = {k: np.array(v) for k, v in self.rows_of.items()}
        self._pins(form, mech, index)
        self._fixed(form, mech)
        K = form.pose_forms()
        angles = np.zeros((len(self.angle_cols), form.nz))
        for r, c in enumerate(self.angle_cols.values()):
            angles[r, c] = 1.0
        self.angle_solids = np.array(list(self.angle_cols), dtype=int)
        self.offsets = np.r_[K[:, -1], np.zeros(len(self.angle_cols))]
        Q, R = np.linalg.qr(np.vstack([K[:, :-1], angles]))       # full column rank
        self.rates = sparse.csr_matrix(np.linalg.solve(R, Q.T))     # its left inverse

    def _pins(self, form, mech, index) -> None:
        groups: dict[int, list] = {}
        for el in mech.constraints:
            if not el.pins or index[el] in self.rows_of:
                continue
            vec = form.basic[(el.ref1.solid, tuple(el.ref1.local))]
            groups.setdefault(id(vec), [vec, []])[1].append(el)
        self.pins, grounded = [], {}
        for vec, els in groups.values():
            solids = sorted({s for el in els for s in el.solids if s not in form.grounds})
            cols = None
            if not vec.x.is_constant:
                cols = np.array([next(iter(e.linear().keys() - {ONE})) for e in (vec.x, vec.y)])
            D = np.zeros((len(solids), len(els)))      # the force on each solid, per revolute
            for k, el in enumerate(els):
                for r, s in enumerate(solids):
                    if s in el.solids:
                        D[r, k] = 1.0 if s == el.receiver else -1.0
            constant = None
            if cols is None:
                constant = np.array([vec.x.linear().get(ONE, 0.0), vec.y.linear().get(ONE, 0.0)])
                for s in solids:
                    grounded[s] = grounded.get(s, 0) + 1
            self.pins.append(_Pin(cols, constant, solids, [index[el] for el in els],
                                  np.linalg.pinv(D)))
        self.ok &= all(k == 1 for k in grounded.values())
        # a column point's coordinates are exactly one z column each
        self.ok &= all(p.columns is None or len(p.columns) == 2 for p in self.pins)

    def _fixed(self, form, mech) -> None:
        held = [el.holds for el in mech.constraints if el.grounds]
        self.ok &= len(set(held)) == len(held)
        for el in mech.constraints:
            if not el.grounds and all(s in form.grounds for s in el.solids):
                self.ok = False                        # between ground solids: no rows


def plan(form: Formulation) -> Plan:
    """The formulation's ``Plan`` (made once)."""
    kept = form.__dict__.setdefault("_kept", {})
    if "reactions_plan" not in kept:
        kept["reactions_plan"] = Plan(form)
    return kept["reactions_plan"]


def natural_rates(pl: Plan, q, qd, qdd):
    """(z, ż, z̈) of the motion q, q̇, q̈: the least-squares solutions of K z = y − k,
    K ż = ẏ, K z̈ = ÿ, y = (x, y, cos fi, sin fi) of every solid and the angle coordinates
    (exact: they are linear in z, ``Formulation.pose_forms``)."""
    ns = len(pl.form.frames)
    i, angles = np.arange(ns), pl.angle_solids
    fi, w, a = q[:, ANGLES], qd[:, ANGLES], qdd[:, ANGLES]
    c, s = np.cos(fi), np.sin(fi)
    y = np.empty((3, len(q), 4 * ns + len(angles)))
    for out, v in zip(y, (q, qd, qdd)):
        out[:, 0:4 * ns:4], out[:, 1:4 * ns:4] = v[:, column(i, 0)], v[:, column(i, 1)]
        out[:, 4 * ns:] = v[:, column(angles, 2)]
    y[0, :, 2:4 * ns:4], y[0, :, 3:4 * ns:4] = c, s
    y[1, :, 2:4 * ns:4], y[1, :, 3:4 * ns:4] = -s * w, c * w
    y[2, :, 2:4 * ns:4], y[2, :, 3:4 * ns:4] = -s * a - c * w * w, c * a - s * w * w
    y[0] -= pl.offsets
    return tuple(inverse.times(v, pl.rates) for v in y)


def _about_origin(p, v, force_p, force_v, moment=0.0):
    """(n, 3): forces (force_p, force_v) on a frame's (p, v) (and a moment on its angle) as
    a force and a moment about the global origin: (F, p × F + G_v·Ω v + M)."""
    out = np.empty(p.shape[:1] + (3,))
    out[:, :2] = force_p
    out[:, 2] = cross(p, force_p) + np.sum(force_v * perp(v), axis=1) + moment
    return out


def constraint_wrenches(form: Formulation, t, q, qd, qdd,
                        redundant: bool = False) -> Reactions | None:
    """Every constraint element's wrench on its receiver and the kinetic energy (``Reactions``),
    in chunks of steps; None where the model is not handled (module doc). ``redundant``:
    μ of least norm, and the wrenches of the self-stresses (μ in the null space of Φ_zᵀ,
    no load: ``Reactions.modes``) for the analysis's least norm over the reported
    components."""
    pl = plan(form)
    extra = form.m - form.nz if redundant else 0
    if not pl.ok or (redundant and extra <= 0):
        return None
    n, nc = len(t), len(pl.mech.constraints)
    out = Reactions(np.empty((n, nc, 3)), np.empty(n),
                    np.empty((n, extra, nc, 3)) if redundant else None)
    size = max(1, min(CHUNK_STEPS, CHUNK_BYTES // (8 * max(1, form.m * form.nz,
                                                          pl.terms.m * pl.terms.nz))))
    for a in range(0, n, size):
        s = slice(a, min(n, a + size))
        out.wrenches[s], out.kinetic[s], modes = _chunk(pl, t[s], q[s], qd[s], qdd[s], extra)
        if redundant:
            out.modes[s] = modes
    return out


def _chunk(pl: Plan, t, q, qd, qdd, extra: int):
    """(wrenches, kinetic energy, self-stress wrenches) of a chunk of steps."""
    form = pl.form
    z, zd, zdd = natural_rates(pl, q, qd, qdd)
    bd = inverse.bodies(form)
    W = inverse.constraint_forces(form, t, z, zd, zdd, q)
    J = form.terms.dense(form.terms.jacobian(z))
    mu = inverse.multipliers(form, z, W, extra > 0, jacobian=J)
    zeta = inverse.body_coordinates(bd, z)                     # (n, ns, 4): p, v
    n = len(t)
    hat = np.empty((n, pl.terms.nz))
    for i, k in pl.frame_eq.start.items():
        hat[:, k:k + 4] = zeta[:, i]
    for i, c in pl.angle_cols.items():
        hat[:, pl.frame_eq.frames[i].angle] = z[:, c]
    Jh = pl.terms.dense(pl.terms.jacobian(hat))                 # (n, rows, ζ̂)
    origins = [q[:, pose(el.receiver)][:, :2] for el in pl.mech.constraints]
    wrench = _wrenches(pl, z, zeta, J, Jh, W, mu, origins)
    modes = None
    if extra:                                                  # the null space of Φ_zᵀ
        null = np.linalg.svd(J)[0][:, :, form.m - extra:]
        modes = np.stack([_wrenches(pl, z, zeta, J, Jh, np.zeros_like(W), null[:, :, k],
                                    origins) for k in range(extra)], axis=1)
    return wrench, inverse.kinetic_energy(form, zd), modes


def _wrenches(pl: Plan, z, zeta, J, Jh, W, mu, origins):
    """Each constraint element's wrench on its receiver, about the receiver's origin, from
    the solids' constraint forces W and the multipliers μ (linear in both: module doc)."""
    form, mech = pl.form, pl.mech
    bd = inverse.bodies(form)
    n, ns = len(z), len(form.frames)
    wrench = np.zeros((n, len(mech.constraints), 3))            # about O, on the receiver
    on = {}                                                    # (element, solid) -> about O
    copies = np.zeros((n, ns, form.nz))                         # A_sᵀ W_s per solid
    for i in pl.moving:
        copies[:, i] = np.einsum("nk,kz->nz", W[:, i], bd.A[i])
    for r, i in enumerate(pl.rigid):                           # s's rigid rows on its copy
        copies[:, i] += J[:, r] * mu[:, r, None]
    for k, rows in pl.rows_of.items():
        el = mech.constraints[k]
        g = np.einsum("nr,nrj->nj", mu[:, pl.first + rows], Jh[:, rows])
        total = np.zeros((n, 3))
        for i in el.solids:
            if i in form.grounds or (k, i) in on:
                continue
            j = pl.frame_eq.start[i]
            f = pl.frame_eq.frames[i]
            moment = -g[:, f.angle] if f.angle is not None else 0.0
            on[(k, i)] = w = _about_origin(zeta[:, i, :2], zeta[:, i, 2:], -g[:, j:j + 2],
                                           -g[:, j + 2:j + 4], moment)
            total += w
            copies[:, i] += np.einsum("nk,kz->nz", g[:, j:j + 4], bd.A[i])
            if f.angle is not None:
                copies[:, i, pl.angle_cols[i]] += g[:, f.angle]
        wrench[:, k] = -total if el.receiver in form.grounds else on[(k, el.receiver)]
        for i in el.solids:
            if i in form.grounds:
                on[(k, i)] = on.get((k, i), 0.0) - total
    balance = _about_origin(zeta[:, :, :2].reshape(-1, 2), zeta[:, :, 2:].reshape(-1, 2),
                            W[:, :, :2].reshape(-1, 2), W[:, :, 2:].reshape(-1, 2)
                            ).reshape(n, ns, 3)
    left = balance.copy()                                      # what the pins must give
    for (k, i), w in on.items():
        left[:, i] -= w
    pins = sorted(pl.pins, key=lambda p: p.columns is None)    # column points first
    for pin in pins:
        if pin.columns is not None:
            point = z[:, pin.columns]
            force = np.stack([copies[:, i][:, pin.columns] for i in pin.solids], axis=1)
            for r, i in enumerate(pin.solids):
                left[:, i, :2] -= force[:, r]
                left[:, i, 2] -= cross(point, force[:, r])
        else:
            point = np.broadcast_to(pin.constant, (n, 2))
            force = np.stack([left[:, i, :2] for i in pin.solids], axis=1)
        revolute = np.einsum("es,nsd->ned", pin.inverse, force)  # on each receiver
        for e, k in enumerate(pin.revolutes):
            el = mech.constraints[k]
            w = np.zeros((n, 3))
            w[:, :2], w[:, 2] = revolute[:, e], cross(point, revolute[:, e])
            wrench[:, k] = w
            for i in el.solids:
                if i in form.grounds:
                    sign = 1.0 if i == el.receiver else -1.0
                    on[(k, i)] = on.get((k, i), 0.0) + sign * w
    for k, el in enumerate(mech.constraints):
        if el.grounds:                                         # the held solid's balance
            g = el.holds
            w = balance[:, g].copy()
            for (kk, i), other in on.items():
                if i == g and kk != k:
                    w -= other
            wrench[:, k] = w
    for k, origin in enumerate(origins):                       # about the receiver's origin
        wrench[:, k, 2] -= cross(origin, wrench[:, k, :2])
    return wrench
