"""Newton's method on the natural-coordinate equations, for all time steps at once.

A run is solved in two passes (vectorised over steps, sequential only where it must be):

1. a coarse sequential pass: every ``stride``-th step from the previous one (COARSE
   intervals, at least 4 steps long; twice as long where the motion is slow, the run's
   own predictor says: COARSE_GROW), Newton started from the Taylor predictor
   z + h ż + h²/2 z̈ (velocities and accelerations there are two linear solves); an interval
   whose predictor misses by more than ``COARSE_MISS`` (a fast or nearly singular motion)
   is cut shorter, down to step by step. Its steps stay close enough that Newton does not
   jump to a nearby branch (a pass with intervals ten times longer, tried, did so next to
   a change point: tests/analyses/test_hard_cases.py);
2. every step in between at once: Newton started from the cubic Hermite interpolation of
   z and ż at the ends of its interval (error O(h⁴)), or from the quintic through z, ż
   and z̈ (error O(h⁶)) where the coarse pass's intervals are long for the motion (the
   cubic would take a third Newton iteration) or so short that the quintic is within the
   tolerance (one iteration: ``quintic_guess``), Jacobians and solves batched over the
   steps (``batched``: blocks of BLOCK steps, the equations ordered as the pivots at the
   start of their interval, so that rows are seldom exchanged; a large system: one sparse
   block-diagonal LU per iteration, ``linear``); a step stops iterating once its Newton
   step is below the tolerance, the others go on without it. A step that does not
   converge, or converges far from its guess (another branch), has its interval solved
   step by step.

A step that Newton cannot solve from the previous one is cut into 2, 4, … 64 sub-steps
before the run stops there. Runs shorter than SHORT steps are solved step by step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .linear import SPARSE_FROM, LinearSolves

#: intervals of the coarse pass (fewer when the run is short)
COARSE = 100
#: the coarse pass's interval doubles where the predictor missed by less than
#: COARSE_MISS / COARSE_GROW (the Taylor predictor's miss grows as the interval cubed: the
#: doubled interval misses by about COARSE_MISS / 2), up to COARSE_LONGEST times its start
#: and COARSE_LONGEST_STEPS steps: the run's own motion sets the coarse pass's size (a short
#: run of a slow mechanism takes fewer sequential steps), within bounds that keep the
#: intervals short enough to stay on the branch (4 times, tried, lost it next to a change
#: point: tests/analyses/test_hard_cases.py); a long run's intervals do not grow (its
#: coarse pass is a small share of the run; with the cubic guess the fill had before, its
#: Newton iterations grew with the interval: 2.32 per step against 2.00 for the four-bar
#: at 100,000 steps with intervals of 2,000 steps against 500)
COARSE_GROW = 16
COARSE_LONGEST = 2
COARSE_LONGEST_STEPS = 64
#: runs shorter than this are solved step by step
SHORT = 64
#: the coarse predictor may miss by this much (relative: lengths / L, angles in rad)
#: before its interval is solved step by step
COARSE_MISS = 2e-2
#: a row's magnitude (what its residual is measured against) is at least this fraction of
#: its terms with the coordinates at their scales: a coordinate whose answer is 0 otherwise
#: leaves a round-off residual as large as the row's terms, and no residual is ever small
MAGNITUDE_FLOOR = 1e-6
#: steps solved together by ``_bulk``: small enough for their arrays to stay in the cache
BLOCK = 8192
#: the fill's steps start from the quintic Hermite guess (z, ż, z̈ at both ends) in a block
#: with an interval whose coarse predictor missed by more than this, else from the cubic (z,
#: ż): the cubic's error grows as the miss to the 4/3, and above it costs the fill a third
#: Newton iteration per step (the four-bar at 1,000 steps: intervals missing 8e-5, 3.0
#: iterations a step with the cubic, 2.05 with the quintic); below it the quintic's two more
#: terms would only cost (the four-bar at 10,000 steps and more: 1e-5, 2.0 either way)
QUINTIC_MISS = 3e-5
#: ... and where its interval's miss is so small that the quintic's error (about the miss
#: squared: O(h⁶) against O(h³)) is within the tolerance, miss² ≤ QUINTIC_ONE × tolerance:
#: its steps then take one Newton iteration instead of two (the four-bar, a part of 50,000
#: steps solved with positions only: 2.00 iterations a step from either guess at misses of
#: ~1e-5 (COARSE intervals of 0.01 s), 1.34 from the quintic at ~1.3e-6 (0.005 s: a run of
#: 100,000 steps, in two parts), 1.62 at ~2.1e-6, 2.00 at ~3.6e-6)
QUINTIC_ONE = 200.0
#: ``Solver.damped`` gives up after this many line searches in a row that found no descent
#: (each a step of 1e-6 of Newton's, from nearly the same z: the same direction again); a
#: redundant parallelogram driven 1e5 s a step spent 20 s in 51 such solves of 200 iterations
STALLED_SEARCHES = 3
#: a step that failed is cut into at most this many sub-steps
MAX_SUBSTEPS = 64
#: the extrapolation of a step looks back this many times 8 steps for solved ones
COARSE_GAP = 64
#: Newton stops where quadratic convergence puts its next step below CONVERGED × tolerance
#: (``next_below``): the answer is then as accurate as a step below the tolerance makes it
CONVERGED = 1e-3
#: the machine epsilon (the size of round-off relative to a value)
EPS = float(np.finfo(float).eps)


def quintic_guess(miss: float, tolerance: float) -> bool:
    """Whether the fill's steps start from the quintic: miss > QUINTIC_MISS (the cubic would
    take a third Newton iteration) or miss² ≤ QUINTIC_ONE · tolerance (the quintic takes one,
    the cubic two); else the cubic, two terms fewer, two iterations either way."""
    return miss > QUINTIC_MISS or miss * miss <= QUINTIC_ONE * tolerance


def cubic_hermite(u, h):
    """The weights of z(0), ż(0), z(h), ż(h) in z(u h) on the cubic through them (error
    O(h⁴)), u in [0, 1]: 2u³ − 3u² + 1, h (u³ − 2u² + u), 3u² − 2u³, h (u³ − u²)."""
    u2, u3 = u * u, u * u * u
    return 2 * u3 - 3 * u2 + 1, (u3 - 2 * u2 + u) * h, 3 * u2 - 2 * u3, (u3 - u2) * h


def quintic_hermite(u, h):
    """The weights of z(0), ż(0), z̈(0), z(h), ż(h), z̈(h) in z(u h) on the quintic through
    them (error O(h⁶)), u in [0, 1]: H₀ = 1 − 10u³ + 15u⁴ − 6u⁵, H₁ = h (u − 6u³ + 8u⁴ −
    3u⁵), H₂ = h² (u² − 3u³ + 3u⁴ − u⁵)/2, and at the far end H₃ = 1 − H₀, H₄ = h (−4u³ +
    7u⁴ − 3u⁵), H₅ = h² (u³ − 2u⁴ + u⁵)/2."""
    u2 = u * u
    u3 = u2 * u
    u4, u5 = u3 * u, u3 * u2
    far = 10 * u3 - 15 * u4 + 6 * u5
    return (1 - far, h * (u - 6 * u3 + 8 * u4 - 3 * u5), 0.5 * h * h * (u2 - 3 * u3 + 3 * u4 - u5),
            far, h * (-4 * u3 + 7 * u4 - 3 * u5), 0.5 * h * h * (u3 - 2 * u4 + u5))


@dataclass
class NaturalSettings:
    """Settings of the natural-coordinate Newton solver.

    Parameters
    ----------
    tolerance : float
        Newton stops when its step is below this, relative to the mechanism's length (angles
        and unit vectors: the step itself), when quadratic convergence puts its next step
        1000 times below it (``next_below``), or when the residual is at round-off.
    max_iterations : int
        Newton iterations per step before the step is cut into sub-steps.
    verbose : int
        Unused (the solver prints nothing); kept so that settings read alike.
    """

    tolerance: float = 1e-13
    max_iterations: int = 25
    verbose: int = 0


def next_below(step, last, tol: float):
    """Whether Newton's next step, quadratic convergence's step³ / last², is below tol / 1000
    (with the step below last / 1000: the convergence is quadratic); then the iterate after
    this step is the answer, and the iteration that would only confirm it is not taken."""
    return (step < 1e-3 * last) & (last < math.inf) & \
        (step * step * step <= CONVERGED * tol * last * last)


class Solver(LinearSolves):
    """Newton's method for one ``Formulation`` (``terms``), with step weights ``w``."""

    def __init__(self, terms, weights: np.ndarray, settings: NaturalSettings,
                 least_squares: bool, rates: bool = True):
        self.terms, self.w, self.settings = terms, weights, settings
        self.least_squares = least_squares or terms.m != terms.nz
        #: whether the fill also solves ż, z̈ at its steps (the run's caller wants its rates);
        #: the coarse pass's steps have theirs whatever it is (its predictor needs them)
        self.fill_rates = rates
        self.iterations = 0
        self.floor = MAGNITUDE_FLOOR * terms.magnitude_at(1.0 / weights)[:, None]
        #: the equations in the order of the pivots at the run's start (``pivot_orders``)
        self.order = np.arange(terms.m)
        #: (z's bytes, its pivot orders) of the last ``pivot_orders``
        self._ordered = (None, None)

    # ---- Newton -------------------------------------------------------------------------------
    def newton(self, t: np.ndarray, z: np.ndarray):
        """(z, ok) after Newton's iteration from z at every step at once."""
        if len(t) == 1:
            return self._newton_one(t, z)
        terms, tol = self.terms, self.settings.tolerance
        z = np.array(z, dtype=float)
        ok = np.zeros(len(t), dtype=bool)
        active = np.arange(len(t))
        eps = EPS
        last = np.full(len(t), np.inf)        # the previous step's size
        g = terms.targets(t, 0)               # the laws' values, the same every iteration
        for _ in range(self.settings.max_iterations):
            if not active.size:
                break
            ta, za, ga = t[active], z[active], g[:, active]
            with np.errstate(all="ignore"):
                phi = terms.residual(ta, za, ga)
                dz = self.solve(terms.jacobian(za), -phi)
                step = np.max(np.abs(dz) * self.w, axis=1, initial=0.0)
                small = step <= tol
                if not self.least_squares:
                    small |= next_below(step, last[active], tol)
                # |Φ| relative to its terms: wanted where the step alone does not decide
                ask = ~small | self.least_squares
                size = np.zeros_like(phi)
                if ask.any():
                    magnitude = np.maximum(terms.magnitude(ta[ask], za[ask], ga[:, ask]),
                                           self.floor.T)
                    size[ask] = np.divide(np.abs(phi[ask]), magnitude,
                                          out=np.abs(phi[ask]) * np.inf, where=magnitude > 0)
                    size[phi == 0] = 0.0
            self.iterations += len(active)
            finite = np.isfinite(step)
            if self.least_squares:        # a least-squares step also stops where Φ ≠ 0
                small &= np.all(size <= max(64 * eps, 100 * tol), axis=1)
            # at round-off, steps stop shrinking (at a singular position Φ is quadratic in
            # the error, and a step that still halves is still worth taking); such a step
            # is round-off amplified by a nearly singular Φ_z, and is not taken
            floor = np.all(size <= 64 * eps, axis=1)
            stalled = floor & (step > 0.7 * last[active])
            take = finite & ~stalled
            z[active[take]] = za[take] + dz[take]
            last[active] = step
            done = finite & (small | stalled)
            ok[active[done]] = True
            active = active[finite & ~done]
        return z, ok

    def _newton_one(self, t: np.ndarray, z: np.ndarray):
        """``newton`` at one step (t (1,), z (1, nz)): the same arithmetic, without the
        bookkeeping of the steps still active (the sequential passes call it step by step)."""
        with np.errstate(all="ignore"):          # entered once, not per iteration
            x, ok = self._iterate_one(t, z)
        return x[None], np.array([ok])

    def _iterate_one(self, t: np.ndarray, z: np.ndarray):
        """(z (nz,), converged): ``_newton_one``'s iteration."""
        terms, tol, w = self.terms, self.settings.tolerance, self.w
        x = np.array(z[0], dtype=float)
        done_below = max(64 * EPS, 100 * tol)
        last = np.inf
        g = terms.targets(t, 0)
        g1 = g[:, 0]
        for _ in range(self.settings.max_iterations):
            phi, J = terms.residual_jacobian_one(x, g1)
            dz = self.solve_one(J, -phi)
            step = float((np.abs(dz) * w).max(initial=0.0))   # exact: the same max
            small = step <= tol or (not self.least_squares and next_below(step, last, tol))
            # Φ within round-off of its terms: it decides only a step that did not
            # shrink (``stalled``) or a least-squares one
            floor = True
            if self.least_squares or (not small and step > 0.7 * last):
                magnitude = np.maximum(terms.magnitude_cols(t, x[:, None], g)[:, 0],
                                       self.floor[:, 0])
                size = np.divide(np.abs(phi), magnitude, out=np.abs(phi) * np.inf,
                                 where=magnitude > 0)
                size[phi == 0] = 0.0
                floor = bool(np.all(size <= 64 * EPS))
                if self.least_squares:
                    small = small and bool(np.all(size <= done_below))
            self.iterations += 1
            if not math.isfinite(step):
                return x, False
            stalled = floor and step > 0.7 * last
            if not stalled:
                x = x + dz
            last = step
            if small or stalled:
                return x, True
        return x, False

    def damped(self, t: float, z: np.ndarray, iterations: int = 200):
        """(z, ok): Newton's iteration at one time from a poor guess, each step shortened
        until it lowers |Φ| (backtracking), then full steps near the solution; not solved
        after ``iterations`` steps, or ``STALLED_SEARCHES`` line searches in a row without
        descent (|Φ| at a minimum that is not 0: no configuration there)."""
        terms = self.terms
        t = np.array([t])

        def size(x):
            with np.errstate(all="ignore"):
                phi = terms.residual(t, x[None])[0]
                return float(np.sqrt(np.sum((phi / (1.0 + terms.magnitude(t, x[None])[0])) ** 2)))

        now = size(z)
        failed = 0                               # line searches in a row that found no descent
        for _ in range(iterations):
            with np.errstate(all="ignore"):
                dz = self.solve(terms.jacobian(z[None]), -terms.residual(t, z[None]))[0]
            if not np.isfinite(dz).all():
                return z, False
            alpha = 1.0
            while alpha > 1e-6 and not size(z + alpha * dz) <= (1 - 1e-4 * alpha) * now:
                alpha *= 0.5
            failed = 0 if alpha > 1e-6 else failed + 1   # (the search ends there on descent)
            if failed >= STALLED_SEARCHES:       # stuck: the same direction from the same z
                return z, False
            z = z + alpha * dz
            now = size(z)
            if alpha == 1.0:
                done, ok = self.newton(t, z[None])
                if ok[0]:
                    return done[0], True
        return z, False

    def step(self, t0: float, z0: np.ndarray, t1: float, guess: np.ndarray | None = None):
        """z at t1 from z0 at t0 (None if Newton fails even in MAX_SUBSTEPS sub-steps)."""
        z, ok = self.newton(np.array([t1]), (z0 if guess is None else guess)[None])
        if ok[0]:
            return z[0]
        parts = 2
        while parts <= MAX_SUBSTEPS:
            zk = z0
            for tk in np.linspace(t0, t1, parts + 1)[1:]:
                z, ok = self.newton(np.array([tk]), zk[None])
                if not ok[0]:
                    break
                zk = z[0]
            else:
                return zk
            parts *= 2
        return None

    def run(self, t: np.ndarray, z0: np.ndarray):
        """(z (n, nz), solved): the steps of ``t`` from the solved z0 at t[0] (module doc)."""
        n = len(t)
        z = np.full((n, self.terms.nz), np.nan)
        z[0] = z0
        #: rates found with the positions at the steps marked in own_rates
        self.zd, self.zdd = np.empty_like(z), np.empty_like(z)
        self.own_rates = np.zeros(n, dtype=bool)
        #: how far each step solved in a batch landed from its guess (weighted, ``w``)
        self.miss = np.zeros(n)
        if self._batched() and self.terms.m:     # the order at the start: ``solve``
            self.order = self.pivot_orders(z0[None])[0]
        self.terms.tabulate(t)                   # the laws at every step, once
        if n < SHORT:
            return self._sequential(t, z, 0, n)
        stride = max(4, n // COARSE)
        self.zd[:1], self.zdd[:1] = self.rates(t[:1], z[:1])
        self.own_rates[0] = True
        intervals, end = self._coarse(t, z, 0, n - 1, stride)
        #: the coarse pass's intervals (k, j, miss) of the last run
        self.intervals = intervals
        bad = self._fill(t, z, intervals)
        for number in bad:                     # another branch, or no convergence
            k, j = intervals[number][:2]
            self.own_rates[k + 1:j + 1] = False
            z, solved = self._sequential(t, z, k, j + 1)
            if solved <= j:
                return z, solved
        return z, end

    def _coarse(self, t, z, k: int, last: int, stride: int):
        """(intervals, end): steps from the solved step k to ``last`` one after the other,
        every ``stride`` steps (fewer where the motion is fast), each from the Taylor
        predictor z + h ż + h²/2 z̈; their rates kept. intervals: (k, j, miss) to fill in;
        end: the first step not solved (len(t) when all are)."""
        with np.errstate(all="ignore"):          # entered once (Newton, the rates)
            return self._coarse_steps(t, z, k, last, stride)

    def _coarse_steps(self, t, z, k: int, last: int, stride: int):
        """``_coarse``' loop."""
        base, intervals = stride, []
        longest = max(base, min(COARSE_LONGEST * base, COARSE_LONGEST_STEPS))
        while k < last:
            j = min(last, k + stride)
            if j - k < 4:                      # too fast or too near a singular position
                z, solved = self._sequential(t, z, k, j + 1)
                if solved <= j:
                    return intervals, solved
                k, stride = j, min(base, 4 * stride)
                self._keep_rates(t, z, j)
                continue
            h = t[j] - t[k]
            guess = z[k] + h * self.zd[k] + 0.5 * h * h * self.zdd[k]
            zj, ok = self._iterate_one(t[j:j + 1], guess[None])      # ``newton`` at one time
            miss = float((np.abs(zj - guess) * self.w).max()) if ok else np.inf
            if miss > COARSE_MISS:             # a shorter interval
                stride = max(1, stride // 4)
                continue
            if miss < COARSE_MISS / COARSE_GROW:
                stride = min(longest, 2 * stride)
            z[j] = zj
            self._keep_rates(t, z, j)
            intervals.append((k, j, miss))
            k = j
        return intervals, len(t)

    def _keep_rates(self, t, z, j: int):
        """Solve and keep the rates at the step j (solved; under ``numpy.errstate``)."""
        self.zd[j], self.zdd[j] = self.rates_one(t[j:j + 1], z[j])
        self.own_rates[j] = True

    def _fill(self, t, z, intervals) -> list[int]:
        """Solve the steps inside every interval at once from Hermite guesses (the quintic
        where the block's largest coarse miss says so: ``quintic_guess``); the
        numbers of the intervals where some step failed or left its guess far behind (more
        than 10 times its interval's miss)."""
        if not intervals:
            return []
        k, j = (np.array([iv[i] for iv in intervals]) for i in (0, 1))
        miss = np.array([iv[2] for iv in intervals])
        allowed = np.maximum(10 * miss, 1e-6)
        ranges = [np.arange(a + 1, b) for a, b in zip(k, j)]
        owner = np.repeat(np.arange(len(intervals)), [len(r) for r in ranges])
        steps = np.concatenate(ranges)
        failed = np.zeros(len(intervals), dtype=bool)
        for a, b, order in self._blocks(z, k, owner):
            part, at = steps[a:b], owner[a:b]
            guess = self._hermite(t, z, part, k[at], j[at],
                                  quintic=quintic_guess(float(np.max(miss[at])),
                                                        self.settings.tolerance))
            if order is not None:
                found = self._bulk(t[part], guess, order)
            else:
                found = self._bulk_sparse(t[part], guess) if self._sparse_blocks() else None
            if found is None:
                zi, ok = self.newton(t[part], guess.T)
                zi = zi.T
            else:
                zi, zd, zdd, ok = found
                if zd is not None:
                    self.own_rates[part] = True
                    self.zd[part], self.zdd[part] = zd.T, zdd.T
            self.miss[part] = np.max(np.abs(zi - guess) * self.w[:, None], axis=0)
            far = self.miss[part] > allowed[at]
            z[part] = zi.T
            failed[at[~ok | far]] = True
        return list(np.nonzero(failed)[0])

    def _blocks(self, z, k, owner):
        """(a, b, order): the steps a:b of ``_fill`` solved together, and their equations'
        order for ``_bulk`` (None: not batched). Batched: blocks of at most BLOCK steps,
        which stay in the cache, of intervals whose first steps pivot alike
        (``pivot_orders``); else chunks whose Jacobians take bounded memory."""
        if not self._batched() or not self.terms.m:
            rows = self.rows_per_chunk()
            yield from ((a, a + rows, None) for a in range(0, len(owner), rows))
            return
        if len(owner) <= BLOCK:                  # one block (a few numpy calls less)
            yield 0, len(owner), self.pivot_orders(z[k[:1]])[0]
            return
        orders = np.ascontiguousarray(self.pivot_orders(z[k]))     # of each interval
        # the order changes where an interval's differs from the last one with steps
        counts = np.bincount(owner, minlength=len(k))
        filled = np.nonzero(counts)[0]
        firsts = (np.cumsum(counts) - counts)[filled]
        change = firsts[1:][np.any(orders[filled[1:]] != orders[filled[:-1]], axis=1)]
        edges = [0, *change.tolist(), len(owner)]
        for a, b in zip(edges[:-1], edges[1:]):
            for c in range(a, b, BLOCK):
                yield c, min(b, c + BLOCK), orders[owner[c]]

    def _hermite(self, t, z, steps, k, j, quintic: bool):
        """z at the steps (nz, n) on the Hermite interpolant through the ends k, j of their
        intervals: the cubic through z and ż (``cubic_hermite``), or with ``quintic`` the
        quintic through z, ż and z̈ (``quintic_hermite``)."""
        h = t[j] - t[k]
        u = (t[steps] - t[k]) / h
        if not quintic:
            w = cubic_hermite(u, h)
            return w[0] * z[k].T + w[1] * self.zd[k].T + w[2] * z[j].T + w[3] * self.zd[j].T
        w = quintic_hermite(u, h)
        return (w[0] * z[k].T + w[1] * self.zd[k].T + w[2] * self.zdd[k].T + w[3] * z[j].T
                + w[4] * self.zd[j].T + w[5] * self.zdd[j].T)

    def _batched(self) -> bool:
        """Whether the steps are solved by ``_bulk`` (small square systems)."""
        return not self.least_squares and self.terms.nz < SPARSE_FROM

    def _sparse_blocks(self) -> bool:
        """Whether the steps are solved by ``_bulk_sparse`` (large square systems)."""
        return not self.least_squares and self.terms.nz >= SPARSE_FROM and self.terms.m > 0

    def _sequential(self, t, z, k: int, end: int):
        """(z, solved): steps k+1 … end−1 one after the other from the solved step k,
        each from the parabola through the last three solved steps (``_extrapolate``)."""
        for i in range(k + 1, end):
            guess = self._extrapolate(t, z, i)
            zi = self.step(t[i - 1], z[i - 1], t[i], guess)
            if zi is None:
                return z, i
            z[i] = zi
        return z, end

    def _extrapolate(self, t, z, i: int):
        """z at t_i on the parabola through the last (up to) three solved steps before i
        (None if there is only one): through a singular position, where the solution
        itself is a poor start for Newton and its rates are not defined."""
        known = [j for j in range(i - 1, max(-1, i - 1 - 8 * COARSE_GAP), -1)
                 if np.isfinite(z[j, 0])][:3]
        if len(known) < 2:
            return None
        ts, zs = t[known], z[known]
        out = np.zeros_like(zs[0])
        for a in range(len(known)):          # Lagrange's form
            weight = np.prod([(t[i] - ts[b]) / (ts[a] - ts[b])
                              for b in range(len(known)) if b != a])
            out += weight * zs[a]
        return out
