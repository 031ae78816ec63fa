"""A chunk's variants after the one pass (``variants.solve``): their x, y, fi with rates,
and, when their runs ask, their reactions, every variant at once.

The pass gives every variant's z, ż, z̈ (n, nz, V). Each variant's own run would turn them
into x, y, fi (``Natural._converted``) and, in a kinetostatic analysis, compute its
reactions (``reactions.constraint_wrenches``): one variant after the other, a hundred small
numpy operations each. Here both are done for all variants together, the variants side by
side as columns (column k·V + v: variant v at step k) and each variant's constants taken
per column:

- x, y, fi: each variant's pose K_v [z; 1] (x, y, cos, sin of every solid), summed term
  after term over z's entries as the single run's sparse product sums them (the same bits),
  then the single run's own steps (``Natural._chunk_q``, ``Natural._pose_rates``), the
  angles unwrapped along each variant's steps: each variant's x, y, fi, q̇, q̈ are the bits
  its own conversion gives;
- the reactions: the natural inverse dynamics of ``reactions`` on every row at once, from
  the pass's z, ż, z̈ (the single run derives them back from x, y, fi by least squares: the
  two agree to round-off): W_b = M_b ζ̈_b − Q_b with each row's masses and loads,
  Φ_zᵀ μ = −Σ A_bᵀ W_b with one LU per row (its own pivots), the elements' wrenches
  (``wrenches.wrenches``) with each row's ground points. ``Group.reactions`` makes them
  the first time a run asks (a kinematic study never does); a quasi-static run asks for
  those of its configurations at rest (ż = z̈ = 0: no inertia, no damper force).

Every operation is elementwise over the rows, or a sum in a fixed order: no variant's numbers
depend on which others share its chunk. A variant whose reactions cannot be had here (its
plan does not handle it, another structure, a singular Φ_z, a load that cannot be computed)
gets None: its run computes its own, and says why where it fails.
"""
from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from ...errors import Pam2ExuError
from ..base import Reactions
from . import inverse
from .reactions import in_frames, plan
from .variants import Stacked, structure, turns
from .wrenches import wrenches

#: variant × step rows per block of the reactions (bounded memory: ~2 kB a row for a small
#: mechanism)
BLOCK_ROWS = 1 << 13
#: the most bytes the x, y, fi and rates of a pass's variants may take (``fits``): beyond,
#: each run converts its own, one at a time, as without the pass
MOST_BYTES = 1 << 28


def fits(variants: int, steps: int, nq: int) -> bool:
    """Whether the x, y, fi, q̇, q̈ of ``variants`` runs of ``steps`` steps (nq each) fit in
    MOST_BYTES."""
    return 3 * 8 * variants * steps * nq <= MOST_BYTES


def columns(a: np.ndarray) -> np.ndarray:
    """(k, n·V) of a (n, k, V): one column per variant and step, step-major."""
    n, k, V = a.shape
    return a.transpose(1, 0, 2).reshape(k, n * V)


def pose_sums(K: np.ndarray, x: np.ndarray) -> np.ndarray:
    """K_v x (rows, n, V) for every variant, K (rows, k, V) and x (k, n, V): each row's terms
    added one after the other from 0 in k's order (what a sparse product of K_v gives: a
    zero term adds nothing)."""
    out = np.zeros((K.shape[0],) + x.shape[1:])
    for k in range(K.shape[1]):
        out += K[:, k, None, :] * x[k][None]
    return out


def poses(kinds, K: np.ndarray, guesses: np.ndarray, z, zd, zdd):
    """(q, q̇, q̈) each (V, n, nq) of every variant, as its own ``Natural._converted``, and
    the free solids' angles at the first step before their whole turns (nfree, V): K
    (4 ns, nz + 1, V) the variants' pose forms, ``kinds`` their one ``Natural._angle_kinds``,
    ``guesses`` (nq, V) where each started (its angles' whole turns), z, ż, z̈ (n, nz, V)."""
    from . import Natural                       # its conversion steps, run on all columns
    n, nz, V = z.shape
    nq = guesses.shape[0]
    ext = np.empty((nz + 1, n, V))
    ext[:nz], ext[nz] = z.transpose(1, 0, 2), 1.0
    pose = pose_sums(K, ext).reshape(len(K), n * V)
    qT, qdT, qddT = (np.empty((nq, n * V)) for _ in range(3))
    raw = Natural._chunk_q(kinds, columns(z), pose, qT)
    rates = []
    for a in (zd, zdd):
        ext[:nz], ext[nz] = a.transpose(1, 0, 2), 0.0
        rates.append(pose_sums(K, ext).reshape(len(K), n * V))
    Natural._pose_rates(kinds, pose, *rates, columns(zd), columns(zdd), qdT, qddT)
    raw = raw.reshape(-1, n, V)
    first = raw[:, 0].copy()
    if kinds.free.size:
        if n > 1:
            raw = np.unwrap(raw, axis=1)
        raw += 2 * np.pi * turns(guesses[kinds.free_fi], first)[:, None]
        qT.reshape(nq, n, V)[kinds.free_fi] = raw
    return (*(np.ascontiguousarray(a.reshape(nq, n, V).transpose(2, 1, 0))
              for a in (qT, qdT, qddT)), first)


class Group:
    """The variants of one pass that were solved to the end, with their x, y, fi: their
    reactions made for all at once when a run first asks (``reactions``).

    forms : list of Formulation      times : (n,)
    z, zd, zdd : (n, nz, V)          q : (V, n, nq)
    """

    def __init__(self, forms, times, z, zd, zdd, q):
        self.forms, self.times = forms, times
        self.z, self.zd, self.zdd, self.q = z, zd, zdd, q
        #: every variant's reactions, of the motion (False) and at rest (True), once made
        self._made: dict[bool, list] = {}

    def reactions(self, v: int, at_rest: bool = False) -> Reactions | None:
        """Variant v's ``Reactions`` (None: its run computes its own) of its motion, or with
        ``at_rest`` of its configurations at rest (ż = z̈ = 0: the quasi-static equilibrium)."""
        if at_rest not in self._made:        # inside the run of the variant that asks first:
            with np.errstate(all="ignore"):  # no floating-point warning of another's rows
                self._made[at_rest] = self._make(at_rest)   # (a row not finite: its None)
        return self._made[at_rest][v]

    def _make(self, at_rest: bool) -> list:
        """Every variant's reactions: those of the first handled variant's structure at
        once, the others None."""
        plans = [plan(f) for f in self.forms]
        out: list = [None] * len(plans)
        handled = [v for v, pl in enumerate(plans) if pl.ok and self.forms[v].m ==
                   self.forms[v].nz]
        if not handled:
            return out
        first = plans[handled[0]]
        shape = structure(first.terms)
        # one reaction structure: the plans share their ``_Shape`` (its arrays, the same
        # objects) and their frame equations stack
        members = [v for v in handled if plans[v].hat_frames is first.hat_frames
                   and structure(plans[v].terms) == shape]
        found = _reactions(self, members, [plans[v] for v in members], at_rest)
        for v, given in zip(members, found):
            out[v] = given
        return out


def _reactions(group: Group, members: list[int], plans: list, at_rest: bool) -> list:
    """The ``Reactions`` of the variants ``members`` (one plan structure), None where one
    fails (module doc); ``at_rest``: of their configurations with ż = z̈ = 0."""
    forms = [group.forms[v] for v in members]
    first, V = plans[0], len(members)
    n = len(group.times)
    bodies = [inverse.bodies(f) for f in forms]
    bd = bodies[0]                                        # A: one structure, shared
    c = np.stack([b.c for b in bodies])                   # (V, ns, 4)
    mass = np.stack([b.mass for b in bodies])             # (V, ns, 4, 4)
    main = Stacked([f.terms for f in forms])
    frame = Stacked([pl.terms for pl in plans])
    grounds = {k: np.stack([pl.pins[k].constant for pl in plans], axis=1)
               for k, pin in enumerate(first.pins) if pin.columns is None}   # (2, V)
    z, zd, zdd = (a[:, :, members] for a in (group.z, group.zd, group.zdd))
    if at_rest:
        zd = zdd = np.zeros_like(z)
    q = group.q[members]
    nc = len(first.mech.constraints)
    wrench_out = np.empty((V, n, nc, 3))
    kinetic_out = np.empty((V, n))
    good = np.ones(V, dtype=bool)
    applied = np.zeros((n, V) + c.shape[1:])              # Q_b: each variant's loads
    for j, form in enumerate(forms):
        try:
            applied[:, j] = inverse.applied(form, group.times, z[:, :, j], q[j], zd[:, :, j])
        except Pam2ExuError:                              # its run says why
            good[j] = False
    per = max(1, BLOCK_ROWS // V)
    for a in range(0, n, per):
        s = slice(a, min(n, a + per))
        steps = s.stop - s.start
        cols = np.tile(np.arange(V), steps)               # the variant of each row
        rows = [columns(x[s]).T for x in (z, zd, zdd)]    # (R, nz): rows step-major
        qR = np.ascontiguousarray(q[:, s].transpose(1, 0, 2)).reshape(steps * V, -1)
        wrench, kinetic, ok = _block(first, bd, c, mass, main.terms(cols),
                                     frame.terms(cols), grounds, cols, *rows, qR,
                                     applied[s].reshape(steps * V, *c.shape[1:]))
        good &= ok.reshape(steps, V).all(axis=0)
        wrench_out[:, s] = wrench.reshape(steps, V, nc, 3).transpose(1, 0, 2, 3)
        kinetic_out[:, s] = kinetic.reshape(steps, V).T
    good &= np.isfinite(wrench_out).all(axis=(1, 2, 3)) & np.isfinite(kinetic_out).all(axis=1)
    return [Reactions(wrench_out[j], kinetic_out[j]) if good[j] else None for j in range(V)]


def _block(pl, bd, c, mass, terms, frame_terms, grounds, cols, z, zd, zdd, q, applied):
    """(wrenches (R, nc, 3), kinetic energy (R,), ok (R,)) of R = steps × V rows (step-major),
    each with its variant's constants: c (V, ns, 4), mass (V, ns, 4, 4), the equations
    ``terms`` and ``frame_terms`` (one column per row), the ground pins' points ``grounds``
    {pin: (2, V)}, Q_b ``applied`` (R, ns, 4) (``reactions._chunk`` on every row)."""
    R, (V, ns) = len(z), c.shape[:2]
    accel = inverse.body_coordinates(bd, zdd, constant=False)    # ζ̈ (R, ns, 4)
    W = _mass_times(mass, accel) - applied
    rhs = -inverse.on_coordinates(bd, W)                           # (R, nz)
    J = terms.dense(terms.jacobian(z))                             # Φ_z (R, m, nz)
    mu = inverse.transposed_solve(J, rhs)                          # (R, m)
    ok = np.isfinite(mu).all(axis=1)
    zeta = (inverse.body_coordinates(bd, z, constant=False).reshape(-1, V, ns, 4)
            + c).reshape(R, ns, 4)                                 # (R, ns, 4): p, v
    Jh, origins = in_frames(pl, frame_terms, z, zeta, q)
    rows = copy.copy(pl)                                # each row's ground points
    rows.pins = [pin if pin.columns is not None else replace(pin, constant=grounds[k][:, cols])
                 for k, pin in enumerate(pl.pins)]
    rows.ordered_pins = [rows.pins[k] for k in pl.order]
    wrench = wrenches(rows, z, zeta, J, Jh, W, mu, origins)
    speed = inverse.body_coordinates(bd, zd, constant=False)      # ζ̇
    kinetic = 0.5 * np.sum((speed * _mass_times(mass, speed)).reshape(R, 4 * ns), axis=1)
    return wrench, kinetic, ok


def _mass_times(mass: np.ndarray, x: np.ndarray) -> np.ndarray:
    """M_b x_b (R, ns, 4) per row and solid, mass (V, ns, 4, 4) of the rows' variants (R =
    steps × V, step-major): each entry's four terms added in order from 0 (as the single
    run's sparse product of the block-diagonal mass)."""
    V = len(mass)
    x = x.reshape(-1, V, *x.shape[1:])
    out = np.zeros_like(x)
    for k in range(4):
        out += mass[..., k] * x[..., k, None]
    return out.reshape(-1, *x.shape[2:])


__all__ = ["Group", "columns", "fits", "pose_sums", "poses"]
