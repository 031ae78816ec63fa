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
from functools import cached_property

import numpy as np

from ...kinematics import column
from ..base import Reactions
from . import inverse
from .forms import ONE, Expr, Vec
from .formulation import Formulation
from .terms import Terms
from .wrenches import wrenches as _wrenches

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
            angle, n = (None, n + 4) if f.angle is None else (n + 4, n + 5)
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
    #: the rows of its columns in ``_wrenches``' copy per solid, and its columns (``_taken``)
    at: list | None = None
    take: slice | np.ndarray | None = None


def _incidence_inverse(D: np.ndarray) -> np.ndarray:
    """D⁺, the least-norm inverse of a pin's incidence; one revolute between one moving
    solid and the ground, D = [[±1]], is its own inverse (what ``numpy.linalg.pinv`` gives,
    without its SVD). Made once per structure (``_Shape``)."""
    return D.copy() if D.shape == (1, 1) else np.linalg.pinv(D)


#: the ``_Shape`` of the structures met last (at most ``KEPT_SHAPES``: one per study)
_SHAPES: dict = {}
KEPT_SHAPES = 32


class Plan:
    """What the natural reactions need of a formulation, made once (``plan``): its numbers
    (the element rows' terms, the rates' matrix, the ground points) and the ``_Shape`` of
    its structure (index arrays, pins, ``copied``), shared by the plans of one structure."""

    def __init__(self, form: Formulation):
        mech = form.mech
        self.form, self.mech = form, mech
        self.frame_eq = eq = _FrameEquations(form)
        self.terms = Terms(eq.nz, [r[1:] for r in eq._rows])
        first = form.m - len(eq._rows)                 # the element rows' first row
        index = {el: k for k, el in enumerate(mech.constraints)}
        owners = tuple(index[el] for el in eq.owners)
        points, groups = _points(form, mech.constraints, set(owners))
        A = inverse.bodies(form).A
        key = (len(form.frames), tuple(form.grounds), tuple(f.angle for f in form.frames),
               form.nz, first, owners, tuple(form.rigid_owners), points,
               tuple((el.solids, el.receiver, el.pins, el.grounds, el.holds)
                     for el in mech.constraints), A.shape, A.tobytes())
        shape = _SHAPES.get(key)
        if shape is None:
            if len(_SHAPES) >= KEPT_SHAPES:
                _SHAPES.pop(next(iter(_SHAPES)))
            shape = _SHAPES[key] = _Shape(form, eq, owners, points, A)
        self.__dict__.update(shape.__dict__)            # shared: never to be changed
        self.first = first
        self.ok = (shape.ok and form.nz > 0 and not eq.unshared   # nz = 0: every solid held
                   and form.labels[first:] == [r[0] for r in eq._rows])
        self.pins = [pin if pin.columns is not None else _Pin(
            None, np.array([vec.x.linear().get(ONE, 0.0), vec.y.linear().get(ONE, 0.0)]),
            pin.solids, pin.revolutes, pin.inverse) for pin, vec in zip(shape.pins, groups)]
        self.ordered_pins = [self.pins[k] for k in shape.order]

    @cached_property
    def offsets(self) -> np.ndarray:
        """k of y = K z + k (``natural_rates``): the pose forms' constants, 0 for the angles."""
        return np.concatenate([self.form.pose_forms()[:, -1], np.zeros(len(self.angle_cols))])

    @cached_property
    def rates(self):
        """The left inverse of [K; the angle rows] (``natural_rates``: z from y), CSR."""
        K = self.form.pose_forms()
        Q, R = np.linalg.qr(np.vstack([K[:, :-1], self.angles]))   # full column rank
        return inverse.csr(np.linalg.solve(R, Q.T))


def _points(form, constraints, owned) -> tuple[tuple, list]:
    """The shared basic points of the revolutes without rows (the pins), first met first:
    (each pin's point's number, each point's z columns or None at a ground point) and the
    points (``Vec``)."""
    numbers: dict[int, int] = {}
    groups, pins, columns = [], [], []
    for k, el in enumerate(constraints):
        if not el.pins or k in owned:
            continue
        vec = form.basic[(el.ref1.solid, tuple(el.ref1.local))]
        if id(vec) not in numbers:
            numbers[id(vec)] = len(groups)
            groups.append(vec)
            columns.append(None if vec.x.is_constant else tuple(
                next(iter(e.linear().keys() - {ONE})) for e in (vec.x, vec.y)))
        pins.append((k, numbers[id(vec)]))
    return (tuple(pins), tuple(columns)), groups


class _Shape:
    """The parts of a plan that depend only on its structure (the key of ``_SHAPES``: the
    solids held and their angle columns, the element rows' owners, the rigid rows' owners,
    the pins' points, the constraint elements' solids and kinds, the solids' A), read-only;
    the pins at ground points without their point (``Plan.pins``)."""

    def __init__(self, form: Formulation, eq: _FrameEquations, owners, points, A):
        mech = form.mech
        self.rigid = np.array(form.rigid_owners, dtype=int)
        self.ok = len(self.rigid) == form.m - len(eq._rows)
        self.moving = [i for i in range(len(form.frames)) if i not in form.grounds]
        self.angle_cols = {i: form.frames[i].angle for i in self.moving
                           if form.frames[i].angle is not None}
        self.rows_of = {k: np.array([r for r, o in enumerate(owners) if o == k])
                        for k in dict.fromkeys(owners)}
        self.solids_of = [el.solids for el in mech.constraints]
        self.receivers = [el.receiver for el in mech.constraints]
        # ``_chunk``: ζ̂'s columns of every moving solid's p, v (from ζ's) and angle (from z's)
        self.hat_frames = (np.array([k + d for k in eq.start.values() for d in range(4)],
                                    dtype=int),
                           np.array([4 * i + d for i in eq.start for d in range(4)], dtype=int))
        self.hat_angles = (np.array([eq.frames[i].angle for i in self.angle_cols], dtype=int),
                           np.array(list(self.angle_cols.values()), dtype=int))
        # ``_wrenches``: each moving solid's columns of ζ̂ (p, v and its angle if it has one)
        self.frame_columns = {
            i: np.array([k, k + 1, k + 2, k + 3] + (
                [] if eq.frames[i].angle is None else [eq.frames[i].angle]))
            for i, k in eq.start.items()}
        self._pins(form, mech, points)
        #: the fixed links, and the solid each holds
        self.held = [(k, el.holds) for k, el in enumerate(mech.constraints) if el.grounds]
        self.ok &= len({g for _, g in self.held}) == len(self.held) and not any(
            not el.grounds and all(s in form.grounds for s in el.solids)
            for el in mech.constraints)                     # (no rows between grounds)
        self._copied(A)
        self.angles = np.zeros((len(self.angle_cols), form.nz))
        for r, c in enumerate(self.angle_cols.values()):
            self.angles[r, c] = 1.0
        self.angle_solids = np.array(list(self.angle_cols), dtype=int)
        # ``natural_rates``: the rows of y that are columns of q (x, y of every solid, the
        # angle coordinates), those columns, and every solid's fi column
        ns = len(form.frames)
        self.y_rows = np.array([4 * i + k for i in range(ns) for k in (0, 1)] +
                               [4 * ns + r for r in range(len(self.angle_solids))], dtype=int)
        self.y_columns = np.array([column(i, k) for i in range(ns) for k in (0, 1)] +
                                  [column(i, 2) for i in self.angle_solids], dtype=int)
        self.fi_columns = np.array([column(i, 2) for i in range(ns)], dtype=int)
        # ``_wrenches``: the columns of each constraint element's receiver's x and y
        self.receiver_columns = np.array([[column(el.receiver, k) for el in mech.constraints]
                                          for k in (0, 1)], dtype=int).reshape(2, -1)
        _frozen(list(self.__dict__.values()))

    def _pins(self, form, mech, points) -> None:
        (pins, columns), members = points, [[] for _ in points[1]]
        for k, number in pins:
            members[number].append(k)
        self.pins, grounded = [], {}
        for cols, revolutes in zip(columns, members):
            els = [mech.constraints[k] for k in revolutes]
            solids = sorted({s for el in els for s in el.solids if s not in form.grounds})
            D = np.zeros((len(solids), len(els)))      # the force on each solid, per revolute
            for k, el in enumerate(els):
                for r, s in enumerate(solids):
                    if s in el.solids:
                        D[r, k] = 1.0 if s == el.receiver else -1.0
            if cols is None:
                for s in solids:
                    grounded[s] = grounded.get(s, 0) + 1
            self.pins.append(_Pin(None if cols is None else np.array(cols), None, solids,
                                  revolutes, _incidence_inverse(D)))
        self.ok &= all(k == 1 for k in grounded.values())
        # a column point's coordinates are exactly one z column each
        self.ok &= all(p.columns is None or len(p.columns) == 2 for p in self.pins)

    def _copied(self, A) -> None:
        """The columns of each solid's copy of its basic points that the reactions read (its
        column pins'), stacked solid after solid (``_wrenches``' copy, rows ``copy_rows``
        {solid: slice}), with A_s's nonzero entries there: ``copied`` {solid: (columns,
        [[(k, A_s[k, c])] per column c])}, and as rounds of one operation each: A_sᵀ W_s
        (``copy_terms``: the k-th nonzero of every column in round k, as ``_combined``) and
        the rigid-body rows' Φ_zᵀ μ (``copy_rigid``: the j-th rigid row of every solid in
        round j); the pins, column points first (``order``), each with the copy's rows
        of its columns for each of its solids (``_Pin.at``)."""
        wanted: dict[int, list] = {}
        for pin in self.pins:
            for i in pin.solids if pin.columns is not None else ():
                wanted.setdefault(i, [])
                wanted[i] += [c for c in pin.columns if c not in wanted[i]]
        self.copied = {i: (np.array(cols), [[(k, A[i][k, c]) for k in range(4)
                                              if A[i][k, c]] for c in cols])
                       for i, cols in wanted.items()}
        self.copy_rows, size = {}, 0
        for i, cols in wanted.items():
            self.copy_rows[i], size = slice(size, size + len(cols)), size + len(cols)
        self.copy_size = size
        terms, rigid = [], []                  # per round: (rows, sources, numbers)
        for i, (cols, per_column) in self.copied.items():
            first = self.copy_rows[i].start
            for a, pairs in enumerate(per_column):
                for number, (k, c) in enumerate(pairs):
                    if number == len(terms):
                        terms.append(([], [], []))
                    for part, value in zip(terms[number], (first + a, 4 * i + k, c)):
                        part.append(value)
            own = [r for r, o in enumerate(self.rigid) if o == i]
            for j, r in enumerate(own):
                if j == len(rigid):
                    rigid.append(([], [], []))
                for a, c in enumerate(cols):
                    for part, value in zip(rigid[j], (first + a, r, c)):
                        part.append(value)
        self.copy_terms = [(_taken(a), _taken(b), np.array(c)[:, None]) for a, b, c in terms]
        self.copy_rigid = [(_taken(a), np.array(b), np.array(c)) for a, b, c in rigid]
        for pin in self.pins:
            if pin.columns is not None:
                pin.at = [_taken([self.copy_rows[i].start + wanted[i].index(c)
                                  for c in pin.columns]) for i in pin.solids]
                pin.take = _taken(pin.columns)
        self.order = sorted(range(len(self.pins)), key=lambda k: self.pins[k].columns is None)


def _taken(index) -> slice | np.ndarray:
    """Indices as a slice where they are consecutive (a view of the same entries, cheaper
    than taking them one by one), else as an array."""
    index = np.asarray(index, dtype=int)
    if len(index) and np.array_equal(index, np.arange(index[0], index[0] + len(index))):
        return slice(int(index[0]), int(index[0]) + len(index))
    return index


def _frozen(value) -> None:
    """The arrays in ``value`` (through dicts, lists, tuples and pins) made read-only."""
    if isinstance(value, np.ndarray):
        value.setflags(write=False)
    elif isinstance(value, (dict, list, tuple, _Pin)):
        for v in (value.values() if isinstance(value, dict) else value.__dict__.values()
                  if isinstance(value, _Pin) else value):
            _frozen(v)


def plan(form: Formulation) -> Plan:
    """The formulation's ``Plan`` (made once)."""
    kept = form.__dict__.setdefault("_kept", {})
    if "reactions_plan" not in kept:
        kept["reactions_plan"] = Plan(form)
    return kept["reactions_plan"]


def natural_rates(pl: Plan, q, qd, qdd):
    """(z, ż, z̈) of the motion q, q̇, q̈: the least-squares solutions of K z = y − k,
    K ż = ẏ, K z̈ = ÿ, y = (x, y, cos fi, sin fi) of every solid and the angle coordinates
    (exact: linear in z, ``Formulation.pose_forms``); y, ẏ, ÿ side by side, a row per
    quantity with the steps along it (a kind's rows of all solids at once), one product."""
    ns, n = len(pl.form.frames), len(q)
    y = np.empty((4 * ns + len(pl.angle_solids), 3, n))
    for k, v in enumerate((q, qd, qdd)):
        y[pl.y_rows, k] = v[:, pl.y_columns].T                # x, y and the angle coordinates
    f, w, a = (v[:, pl.fi_columns].T for v in (q, qd, qdd))   # (ns, n) each
    c, s = np.cos(f), np.sin(f)
    y[2:4 * ns:4, 0], y[3:4 * ns:4, 0], minus_s, cw = c, s, -s, c * w
    y[2:4 * ns:4, 1], y[3:4 * ns:4, 1] = minus_s * w, cw
    y[2:4 * ns:4, 2], y[3:4 * ns:4, 2] = minus_s * a - cw * w, c * a - s * w * w
    y[:, 0] -= pl.offsets[:, None]
    out = (pl.rates @ y.reshape(len(y), 3 * n)).reshape(pl.rates.shape[0], 3, n)
    return tuple(np.ascontiguousarray(out[:, k]).T for k in range(3))   # as ``inverse.times``


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


def in_frames(pl: Plan, terms: Terms, z, zeta, q):
    """(Φ_ζ̂ (n, rows, ζ̂), the receivers' origins x, y (nc, n) each): the element rows'
    Jacobian ``terms`` (the plan's, or one column per step with each step's constants) at
    ζ̂ = (p, v, fi) of every moving solid, from z and ζ (n, ns, 4), and where each element's
    wrench is taken about (``wrenches``)."""
    n = len(z)
    hat = np.empty((n, terms.nz))                              # ζ̂: (p, v, fi) per solid
    hat[:, pl.hat_frames[0]] = zeta.reshape(n, -1)[:, pl.hat_frames[1]]
    hat[:, pl.hat_angles[0]] = z[:, pl.hat_angles[1]]
    return (terms.dense(terms.jacobian(hat)),
            (q[:, pl.receiver_columns[0]].T, q[:, pl.receiver_columns[1]].T))


def _chunk(pl: Plan, t, q, qd, qdd, extra: int):
    """(wrenches, kinetic energy, self-stress wrenches) of a chunk of steps."""
    form = pl.form
    z, zd, zdd = natural_rates(pl, q, qd, qdd)
    bd = inverse.bodies(form)
    W = inverse.constraint_forces(form, t, z, zd, zdd, q)
    J = form.terms.dense(form.terms.jacobian(z))
    mu = inverse.multipliers(form, z, W, extra > 0, jacobian=J)
    zeta = inverse.body_coordinates(bd, z)                     # (n, ns, 4): p, v
    Jh, origins = in_frames(pl, pl.terms, z, zeta, q)
    wrench = _wrenches(pl, z, zeta, J, Jh, W, mu, origins)
    modes = None
    if extra:                                                  # the null space of Φ_zᵀ
        null = np.linalg.svd(J)[0][:, :, form.m - extra:]
        modes = np.stack([_wrenches(pl, z, zeta, J, Jh, np.zeros_like(W), null[:, :, k],
                                    origins) for k in range(extra)], axis=1)
    return wrench, inverse.kinetic_energy(form, zd), modes
