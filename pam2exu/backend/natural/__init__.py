"""The natural-coordinate backend: a second, independent formulation of the constraints
(Unda & García de Jalón, 1985), solved by pam2exu's own vectorised Newton method.

``Formulation`` turns a mechanism into basic points, unit vectors and angles with linear and
quadratic equations (each element declares its own: ``Element.natural``); ``Solver`` solves
them for all time steps at once; ``Natural`` is the ``Backend`` the analyses call
(``registry.BACKENDS['natural']``), returning x, y, fi of every solid and, on request, their
velocities and accelerations from the formulation's own linear solves.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from ...errors import SolverError
from ...kinematics import ANGLES, PER_SOLID, column
from ..base import Backend, Integrator, Positions
from .formulation import Coordinate, Formulation, Frame
from .inverse import csr
from .terms import extended
from .dynamics import motion
from .loads import multipliers
from .anchored import anchored
from .reactions import constraint_wrenches
from .solver import MAX_SUBSTEPS, NaturalSettings, Solver
from .variants import Answered, Stack, solve, stackable, structure, turns
from . import population
from .statics import Statics, pose_distance

__all__ = ["Natural", "NaturalSettings", "Formulation", "Frame", "Coordinate"]


class Natural(Backend):
    """``Backend`` on the natural-coordinate formulation (``registry.BACKENDS['natural']``)."""

    name = "natural"
    label = "the natural-coordinate backend"
    solver_name = "The natural-coordinate Newton solver"
    Settings = NaturalSettings
    #: it can return velocities and accelerations with the positions
    gives_rates = True
    #: the static equilibrium of free solids: ``static_equilibrium`` (``statics``)
    moves_free_solids = True
    #: their motion: ``motion`` (``dynamics``), to the tolerance by its own error control
    integrator = Integrator.ADAPTIVE
    #: a chunk of variants in one pass: ``solved_variants`` (``variants``)
    solves_variants = True
    #: the kinetostatic reactions from natural-coordinate inverse dynamics: ``reactions``
    gives_reactions = True

    def __init__(self, answered: Answered | None = None):
        self._forms: dict = {}
        #: (formulation, t0, tolerance, q, z) of the last plain solve's first step
        #: (``_solved_start``)
        self._solved = None
        #: a run solved beforehand with other variants (``variants.Answered``): the positions
        #: it asks for exactly are read from it, not solved again
        self.answered = answered

    def formulation(self, mech, all_angles: bool = False) -> Formulation:
        """The mechanism's formulation (made once per mechanism and kind)."""
        key = (id(mech), all_angles)
        if key not in self._forms:
            self._forms[key] = (mech, Formulation(mech, all_angles))
        return self._forms[key][1]

    def weights(self, form: Formulation, mech) -> np.ndarray:
        """What Newton's step is measured in: points / L, unit vectors and angles as they are."""
        def make():
            L = mech.scale()
            return np.array([1.0 / L if c.kind == "point" else 1.0 for c in form.coordinates])
        return _kept(form, "weights", make)

    def solve_positions(self, mech, times, start, settings, *, redundant=False, forces=False,
                        anchor_stiffness=0.0, rates=False) -> Positions:
        """See ``Backend.solve_positions``; ``rates``: also return q̇ and q̈."""
        times = np.asarray(times, dtype=float)
        start = np.asarray(start, dtype=float)
        form = self.formulation(mech, all_angles=anchor_stiffness > 0)
        w = self.weights(form, mech)
        if self.answered is not None and not (redundant or anchor_stiffness):
            given = self.answered.positions(form, times, start, w, settings.tolerance)
            if given is not None:
                z, zd, zdd = given
                return self._found(form, mech, times, start, z, forces, rates, zd, zdd,
                                   converted=self.answered.converted(len(z), start))
        solver = Solver(form.terms, w, settings, least_squares=redundant, rates=rates)
        n = len(times)
        q = np.full((n, mech.nq), np.nan)
        plain = not (redundant or anchor_stiffness)
        z0 = self._solved_start(form, times[0], start, settings) if plain else None
        if z0 is None:
            z_start = form.from_q(start)[0]
            try:
                if anchor_stiffness > 0:
                    z0 = self._anchored(form, mech, times[0], z_start, settings, w)
                else:
                    found, ok = solver.newton(times[:1], z_start[None])
                    z1, ok = found[0], ok[0]
                    if not ok:                     # a poor guess: shorter steps
                        z1, ok = solver.damped(times[0], z_start)
                    z0 = z1 if ok else None
            except SolverError as exc:
                return Positions(q, 0, str(exc), start)
            if z0 is None:               # where Newton stopped: the diagnosis starts there
                last = self.to_q(form, mech, z1[None], start)[0]
                return Positions(q, 0, self._failed(form, solver, times[0], z1, settings),
                                 last if np.isfinite(last).all() else start)
        if form.nz == 0:                 # every solid held: nothing moves, nothing to solve
            z, solved = np.zeros((n, 0)), n
        else:
            z, solved = solver.run(times, z0)
        error = None
        if solved < n:
            error = self._failed(form, solver, times[solved], z[solved - 1], settings)
        zd = zdd = None
        if rates and solved:
            zd, zdd = (solver.run_rates(times[:solved], z[:solved]) if form.nz
                       else (z[:solved], z[:solved]))
        found = self._found(form, mech, times, start, z[:solved], forces, rates, zd, zdd,
                            error, solver.iterations)
        if plain and solved:
            self._solved = (form, float(times[0]), settings.tolerance, found.q[0].copy(),
                            z[0].copy())
        return found

    def _solved_start(self, form, t0, start, settings):
        """z at t0 already solved for ``start`` by this backend's last run (the assembly the
        analysis starts from: its q, whole turns added to angles), else None: the run does not
        solve it again (its z, its angle coordinates those of ``start``)."""
        if self._solved is None:
            return None
        kept_form, t, tolerance, q, z = self._solved
        if kept_form is not form or t != t0 or tolerance != settings.tolerance:
            return None
        turns = (start[ANGLES] - q[ANGLES]) / (2 * np.pi)
        xy = np.ones(len(q), dtype=bool)
        xy[ANGLES] = False
        kind = self._angle_kinds(form)
        fi = column(kind.coordinate, 2)
        if not (np.array_equal(start[xy], q[xy]) and np.all(np.abs(turns - np.rint(turns)) <= 1e-9)
                and np.array_equal(z[kind.columns], q[fi])):
            return None
        z0 = z.copy()
        z0[kind.columns] = start[fi]
        return z0

    def _found(self, form, mech, times, start, z, forces, rates, zd, zdd, error=None,
               iterations=0, converted=None) -> Positions:
        """The ``Positions`` of the solved steps z (the first len(z) of ``times``): x, y,
        fi, with ``rates`` their rates from ż, z̈, with ``forces`` the multipliers;
        ``converted``: (q, q̇, q̈) of z already (the pass's)."""
        n, solved = len(times), len(z)
        q = np.full((n, mech.nq), np.nan, order="F")    # as converted: column by column
        with_rates = rates and solved
        if converted is None:
            converted = self._converted(form, mech, z, start, zd if with_rates else None, zdd)
        q[:solved] = converted[0]
        found = Positions(q, solved, error, q[solved - 1], iterations=iterations)
        if with_rates:
            qd, qdd = converted[1:]
            if solved < n:                     # NaN after the last solved step, as q
                qd, qdd = (np.r_[x, np.full((n - solved, mech.nq), np.nan)] for x in (qd, qdd))
            found.qd, found.qdd = qd, qdd
        if forces and solved:
            found.multipliers = multipliers(form, times[:solved], z, q[:solved])
        return found

    def solved_variants(self, mechs, times, settings) -> list:
        """See ``Backend.solved_variants``: the variants whose equations have one structure
        (and are square) stacked and solved step by step all at once (``variants``); each
        one solved to the last step gets a ``Natural`` holding its answers."""
        times = np.asarray(times, dtype=float)
        out: list = [None] * len(mechs)
        groups: dict = {}
        for i, mech in enumerate(mechs):
            terms = self.formulation(mech).terms
            if stackable(terms):
                groups.setdefault(structure(terms), []).append(i)
        for members in groups.values():
            forms = [self.formulation(mechs[i]) for i in members]
            guesses = [mechs[i].initial_q() for i in members]
            stack = Stack([f.terms for f in forms],
                          [self.weights(f, mechs[i]) for f, i in zip(forms, members)], times)
            z0 = np.stack([f.from_q(g)[0] for f, g in zip(forms, guesses)], axis=1)
            found = solve(stack, z0, settings.tolerance, settings.max_iterations)
            done = np.flatnonzero(found.solved == len(times))
            # the variants solved to the end, read-only: each one's answers are views
            answers = [a if done.size == len(members) else a[:, :, done]
                       for a in (found.z, found.zd, found.zdd)]
            for a in answers:
                a.setflags(write=False)
            group, poses = self._group([forms[j] for j in done], times, *answers,
                                       [guesses[j] for j in done])
            for k, j in enumerate(done):
                i = members[j]
                answer = Answered(times, guesses[j], *(a[:, :, k] for a in answers))
                if poses is not None:
                    answer.q, answer.qd, answer.qdd = (p[k] for p in poses[:3])
                    answer.free_fi = self._angle_kinds(forms[j]).free_fi
                    answer.first, answer.group, answer.index = poses[3][:, k], group, k
                out[i] = Natural(answer)
                out[i]._forms[(id(mechs[i]), False)] = (mechs[i], forms[j])
        return out

    def _group(self, forms, times, z, zd, zdd, guesses):
        """(``population.Group``, ``population.poses``) of the variants solved to the end,
        or (None, None) when there are none, their x, y, fi would take more than
        ``population.MOST_BYTES``, or their angles are not of one kind (each run converts
        its own)."""
        if not forms or not population.fits(len(forms), len(times), guesses[0].size):
            return None, None
        kinds = [self._angle_kinds(f) for f in forms]
        first = kinds[0]
        if any(not all(np.array_equal(a, b) for a, b in zip(vars(k).values(),
                                                                vars(first).values()))
               for k in kinds[1:]):
            return None, None
        K = np.stack([f.pose_forms() for f in forms], axis=2)
        poses = population.poses(first, K, np.stack(guesses, axis=1), z, zd, zdd)
        return population.Group(forms, times, z, zd, zdd, poses[0]), poses

    def _anchored(self, form, mech, t0, z_start, settings, w):
        """The assembly with free degrees of freedom: nearest the model's x, y, fi (the same
        distance as the Exudyn backend's springs: x, y in m, fi times the length scale)."""
        rows, target, weight = pose_distance(form, mech, mech.initial_q())
        return anchored(form.terms, t0, z_start, rows, target, weight, settings, w)

    def static_equilibrium(self, mech, t, start, settings, *, redundant=False,
                           anchor_stiffness=0.0) -> Positions:
        """See ``Backend.static_equilibrium``: Newton's iteration on Q(z) − Φ_zᵀ λ = 0,
        Φ(z, t) = 0 with the anchor springs (``statics``), in the formulation with every
        angle; λ back in pam2exu's rows from the loads on x, y, fi (``loads.multipliers``)."""
        start = np.asarray(start, dtype=float)
        form = self.formulation(mech, all_angles=True)
        w = self.weights(form, mech)
        statics = Statics(form, mech, t, start, anchor_stiffness)
        z0 = form.from_q(start)[0]
        z, _, iterations, ok = statics.solve(z0, w, settings.tolerance,
                                             settings.max_iterations)
        nan = np.full((1, mech.nq), np.nan)
        if not ok:
            last = self.to_q(form, mech, z[None], start)[0]
            return Positions(nan, 0, f"Newton's iteration on the static equilibrium did not "
                             f"converge at t = {t:.6g} s in {iterations} iterations",
                             last if np.isfinite(last).all() else start,
                             iterations=iterations)
        if np.array_equal(z, z0):         # no step taken: the start, unmoved
            q = start[None].copy()
        else:
            q = self.to_q(form, mech, z[None], start)
        extra = None
        if anchor_stiffness:              # the springs' forces on x, y, fi: −k W (q − q_s)
            moving = np.array([i not in form.grounds for i in range(len(mech.solids))])
            scale = np.tile([1.0, 1.0, mech.scale() ** 2], len(mech.solids))
            extra = -anchor_stiffness * scale * np.repeat(moving, PER_SOLID) * (q - start)
        lam = multipliers(form, np.array([float(t)]), z[None], q, extra)
        return Positions(q, 1, None, q[0], lam, iterations)

    def _failed(self, form, solver, t, z, settings) -> str:
        with np.errstate(all="ignore"):
            phi = np.abs(form.terms.residual(np.array([t]), z[None])[0])
        text = (f"Newton's iteration did not converge at t = {t:.6g} s in "
                f"{settings.max_iterations} iterations, nor in {MAX_SUBSTEPS} sub-steps")
        if phi.size and np.isfinite(phi).all():
            k = int(np.argmax(phi))
            text += f" (largest natural-coordinate residual {phi[k]:.3g}, {form.labels[k]})"
        return text

    def motion(self, mech, times, q0, qd0, tolerance, verbose=0):
        """See ``Backend.motion``: M z̈ + Φ_zᵀ μ = Q, Φ = 0 at index 1, integrated by
        DOP853 (Radau if stiff) with projections, to the tolerance (``dynamics.motion``)."""
        return motion(self, self.formulation(mech), mech, times, q0, qd0, tolerance, verbose)

    def reactions(self, mech, times, q, qd, qdd, redundant=False):
        """See ``Backend.reactions``: M z̈ + Φ_zᵀ μ = Q with the constant mass matrix, the
        reactions from μ and each solid's equilibrium at the shared basic points
        (``reactions``); None in the cases that module names."""
        times = np.asarray(times, dtype=float)
        if self.answered is not None and not redundant:
            given = self.answered.reactions(times, q, qd, qdd)
            if given is not None:            # made with the other variants of its pass
                return given
        return constraint_wrenches(self.formulation(mech), times, q, qd, qdd, redundant)

    # ---- back to x, y, fi ---------------------------------------------------------------------
    def to_q(self, form: Formulation, mech, z: np.ndarray, start: np.ndarray) -> np.ndarray:
        """x, y, fi (n, nq) of configurations z; fi continuous over the steps, its first
        value in the whole turn nearest ``start`` (in chunks of steps: bounded memory; one
        row per quantity inside, the step axis last)."""
        return self._converted(form, mech, z, start)[0]

    def to_rates(self, form: Formulation, mech, z, zd, zdd):
        """(q̇, q̈) from (z, ż, z̈): x, y, cos, sin are linear in z; fi = atan2(sin, cos)
        (in chunks of steps: bounded memory; one row per quantity inside)."""
        return self._converted(form, mech, z, None, zd, zdd)[1:]

    def _converted(self, form: Formulation, mech, z, start=None, zd=None, zdd=None):
        """(q, q̇, q̈) of ``to_q`` (None without ``start``) and ``to_rates`` (None without
        ``zd``) from one product K [z; 1] per chunk (the pose x, y, cos, sin of each solid)."""
        # K sparse: K @ z sums the same terms in the same order whatever the number of
        # columns (a dense product's order depends on it: chunked runs would differ)
        K = _kept(form, "pose_sum", lambda: csr(form.pose_forms()))
        kind = self._angle_kinds(form)
        n = len(z)
        qT = None if start is None else np.empty((mech.nq, n))    # one row per x, y, fi
        rates = None if zd is None else (np.empty((mech.nq, n)), np.empty((mech.nq, n)))
        raw = np.empty((kind.free.size, n))
        for s in _chunks(n):
            zT = z[s].T
            pose = K @ extended(zT)                             # x, y, cos, sin per solid
            if qT is not None:
                raw[:, s] = self._chunk_q(kind, zT, pose, qT[:, s])
            if rates is not None:
                self._chunk_rates(kind, K, pose, zd[s].T, zdd[s].T, rates[0][:, s],
                                  rates[1][:, s])
        if qT is not None and kind.free.size:
            if n > 1:                                    # (one step: nothing to unwrap)
                raw = _unwrapped(raw)
            raw += 2 * np.pi * turns(start[kind.free_fi], raw[:, 0])[:, None]
            qT[kind.free_fi] = raw
        return (None if qT is None else qT.T,
                *((None, None) if rates is None else (rates[0].T, rates[1].T)))

    @staticmethod
    def _chunk_q(kind, zT, pose, qT) -> np.ndarray:
        """x, y, fi of a chunk into qT (a view), but the free solids' fi: their atan2 (the
        unwrapping is over the whole run), returned."""
        qT[0::PER_SOLID], qT[1::PER_SOLID] = pose[0::4], pose[1::4]
        fi = qT[2::PER_SOLID]
        fi[kind.fixed] = kind.fixed_values[:, None]
        # fi is the angle coordinate where the solid's vector points that way (to
        # round-off), else the vector's direction: the tie v × e(fi) = 0 also holds π
        # away, and the residual check then sees the actuator violated instead
        angle = np.arctan2(pose[kind.sines], pose[kind.cosines])    # coordinate, then free
        theta = zT[kind.columns]
        gap = angle[:kind.coordinate.size] - theta
        gap -= 2 * np.pi * np.rint(gap / (2 * np.pi))
        fi[kind.coordinate] = theta + np.where(np.abs(gap) > 1e-6, gap, 0.0)
        return angle[kind.coordinate.size:]

    @staticmethod
    def _chunk_rates(kind, K, pose, zdT, zddT, qdT, qddT) -> None:
        """q̇, q̈ of a chunk into qdT, qddT (views) from its pose and ż, z̈."""
        # K [ż; 0]: a row's sum ends with + c·0 = ±0, which changes no sum (one matrix
        # for x, y, cos, sin and their rates)
        d1, d2 = K @ extended(zdT, 0.0), K @ extended(zddT, 0.0)
        Natural._pose_rates(kind, pose, d1, d2, zdT, zddT, qdT, qddT)

    @staticmethod
    def _pose_rates(kind, pose, d1, d2, zdT, zddT, qdT, qddT) -> None:
        """q̇, q̈ into qdT, qddT (views) from the pose, its rates d1 = K [ż; 0] and
        d2 = K [z̈; 0] (x, y, cos, sin of each solid: one row each), and ż, z̈."""
        f = kind.free
        for out, d in ((qdT, d1), (qddT, d2)):
            out[0::PER_SOLID], out[1::PER_SOLID] = d[0::4], d[1::4]
        w, a = qdT[2::PER_SOLID], qddT[2::PER_SOLID]
        w[kind.fixed] = a[kind.fixed] = 0.0
        w[kind.coordinate], a[kind.coordinate] = zdT[kind.columns], zddT[kind.columns]
        if f.size:
            cs, sn = pose[4 * f + 2], pose[4 * f + 3]
            dc, ds = d1[4 * f + 2], d1[4 * f + 3]
            ddc, dds = d2[4 * f + 2], d2[4 * f + 3]
            r2 = cs * cs + sn * sn
            w[f] = (cs * ds - sn * dc) / r2
            a[f] = (cs * dds - sn * ddc) / r2 - 2 * (cs * dc + sn * ds) * w[f] / r2

    def _angle_kinds(self, form: Formulation):
        """Which solids' fi are constant (ground), an angle coordinate, or atan2 of the vector."""
        return _kept(form, "angle_kinds", lambda: self._find_angle_kinds(form))

    @staticmethod
    def _find_angle_kinds(form: Formulation):
        fixed = [i for i, f in enumerate(form.frames) if f.fixed_angle is not None]
        coordinate = [i for i, f in enumerate(form.frames)
                      if f.fixed_angle is None and f.angle is not None]
        free = [i for i, f in enumerate(form.frames) if f.fixed_angle is None and f.angle is None]
        both = np.array(coordinate + free, dtype=int)
        return SimpleNamespace(
            fixed=np.array(fixed, dtype=int),
            fixed_values=np.array([form.frames[i].fixed_angle for i in fixed]),
            coordinate=np.array(coordinate, dtype=int),
            columns=np.array([form.frames[i].angle for i in coordinate], dtype=int),
            free=np.array(free, dtype=int),
            # rows of the pose: sin and cos of the coordinate solids, then of the free ones
            sines=4 * both + 3, cosines=4 * both + 2,
            # the free solids' fi in q
            free_fi=column(np.array(free, dtype=int), 2))


#: steps converted to x, y, fi at a time: the chunk's own arrays (its pose, ż, z̈ and
#: their products, ~1 MB) are then reused from one chunk to the next rather than fresh
#: memory each (65,536 steps: ~35 MB a 50,000-step part, the page faults a third of
#: the conversion); the results do not depend on it (tests/backend/test_natural.py)
CONVERT_ROWS = 1 << 12


def _kept(form: Formulation, name: str, make):
    """What ``make()`` returns for this formulation, made once (it depends only on the
    mechanism)."""
    kept = form.__dict__.setdefault("_kept", {})
    if name not in kept:
        kept[name] = make()
    return kept[name]


def _chunks(n: int):
    """Slices of n steps, CONVERT_ROWS at a time."""
    return (slice(a, min(n, a + CONVERT_ROWS)) for a in range(0, n, CONVERT_ROWS))


#: ``_unwrapped`` leaves runs with more wraps than this to ``numpy.unwrap`` (one slice each)
MOST_WRAPS = 64


def _unwrapped(raw: np.ndarray) -> np.ndarray:
    """``numpy.unwrap(raw, axis=1)`` (raw (r, n), n > 1) bit for bit, in a few passes
    instead of about fifteen: its correction is 0 where |Δ| < π, so it is computed only at
    the steps where an angle wraps, and each run of steps between them gets its running sum
    added (adding 0 changes no sum). Non-finite values, and many wraps, go to numpy."""
    dd = np.diff(raw, axis=1)
    if not np.isfinite(dd).all():            # (NaN's sign would follow numpy's loops)
        return np.unwrap(raw, axis=1)
    rows, at = np.nonzero(np.abs(dd) >= np.pi)
    if len(at) > MOST_WRAPS:
        return np.unwrap(raw, axis=1)
    out = np.empty_like(raw)
    out[:, 0] = raw[:, 0]
    for r in range(len(raw)):
        wraps = at[rows == r]
        d = dd[r, wraps]
        low = -np.pi                             # numpy.unwrap's arithmetic at the wraps
        turned = np.mod(d - low, 2 * np.pi) + low
        np.copyto(turned, np.pi, where=(turned == low) & (d > 0))
        sums = np.cumsum(turned - d).tolist()
        edges = [0, *wraps.tolist(), dd.shape[1]]
        for c, a, b in zip([0.0, *sums], edges[:-1], edges[1:]):
            np.add(raw[r, 1 + a:1 + b], c, out=out[r, 1 + a:1 + b])
    return out
