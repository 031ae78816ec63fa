"""Many variants of one mechanism solved together (a study's chunk): every variant's
natural-coordinate equations stacked, Newton's iteration on the variant × step systems.

Variants of one model share their equations' structure (which coordinates multiply which,
``Terms``) and differ in the constants: point coordinates, lengths, angles, the laws'
constants. ``Stack`` keeps one structure with its constants as arrays over the variants, one
column each, so that one evaluation gives Φ and Φ_z of every variant at a step. The run goes
step by step, every variant at once, each from its own assembly (Newton from its own guess,
so on its own branch) and then from its own Taylor predictor z + h ż + h²/2 z̈ (the steps
between: from the quintic through the steps around them), its rates Φ_z ż = g', Φ_z z̈ = γ
solved with the Jacobian at the converged step.

A variant whose iteration fails (no assembly, a step that does not converge, a singular
Jacobian, a step that lands far from its predictor: perhaps another branch) is dropped from
the rest of the run, its ``solved`` the steps it had: the caller solves it alone on the
reference path (``Natural.solve_positions``), which says why it fails. It never holds the
other variants back, and no variant's answer depends on which others share its chunk.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from ...batched import lu_factor, lu_solve
from .linear import PIVOT_THRESHOLD, SPARSE_FROM
from .solver import (COARSE, COARSE_GROW, COARSE_LONGEST, COARSE_LONGEST_STEPS,
                     COARSE_MISS, SHORT, quintic_hermite)
from .terms import Terms


def turns(start: np.ndarray, first: np.ndarray) -> np.ndarray:
    """The whole turns k added to the free solids' angles: rint((start − first) / 2π), the
    turns of ``start`` nearest the first step's atan2 (``Natural._converted``)."""
    return np.rint((start - first) / (2 * np.pi))


#: steps between the coarse pass's steps at the start of a run (``_coarse``)
STRIDE = 4
#: variant × step columns solved at once by the fill (bounded memory: about 1 kB each for a
#: small mechanism)
FILL_COLUMNS = 1 << 13
#: the constants of a ``Terms`` (each a column (k, 1)): what differs between variants
CONSTANTS = ("_pc", "_sc", "_alpha", "_apc", "_asc", "_jp_c", "_js_c", "_js_alpha",
             "_jc_c", "_jc_alpha")
#: the arrays that fix a ``Terms``' structure: variants stack only when these are equal
STRUCTURE = ("pr", "pa", "pb", "sr", "sa", "sb", "law_rows", "rows", "cols")


def structure(terms: Terms) -> tuple:
    """What must be equal for two variants' equations to stack: sizes, the terms'
    coordinates, the Jacobian's pattern, the laws' rows and powers."""
    return (terms.nz, terms.m, tuple(p for _, _, p in terms.laws),
            *(getattr(terms, name).tobytes() for name in STRUCTURE))


def stackable(terms: Terms) -> bool:
    """Whether the batched pass solves these equations: a square system (a redundant one
    is least squares, solved per variant)."""
    return terms.m == terms.nz and terms.nz > 0


@dataclass
class Answers:
    """The stacked run: z, ż, z̈ (n, nz, V); ``solved`` (V,) the steps each variant has
    (n: all; 0: not even assembled); ``iterations`` Newton's, over all columns."""

    z: np.ndarray
    zd: np.ndarray
    zdd: np.ndarray
    solved: np.ndarray
    iterations: int = 0

    def variant(self, v: int):
        """(z, ż, z̈) of variant v, (n, nz) each (NaN after its last solved step)."""
        return self.z[:, :, v], self.zd[:, :, v], self.zdd[:, :, v]


@dataclass
class Answered:
    """One variant's run from the batched pass, for its own run to read (``Natural``).

    ``times`` the run's, ``guess`` the x, y, fi it started from (the model's), z, ż, z̈
    (n, nz) every step's; ``q``, ``qd``, ``qdd`` (n, nq) its x, y, fi and rates from them
    when the pass converted them (``population.poses``: the bits of ``Natural._converted``),
    with ``free_fi`` the columns of the free solids' angles and ``first`` their atan2 at the
    first step (another start with the same whole turns has the same x, y, fi); ``group``
    and ``index`` where its reactions are made (``population.Group``), if at all.
    """

    times: np.ndarray
    guess: np.ndarray
    z: np.ndarray
    zd: np.ndarray
    zdd: np.ndarray
    q: np.ndarray | None = None
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    free_fi: np.ndarray | None = None
    first: np.ndarray | None = None
    group: object = None
    index: int = 0

    def converted(self, n: int, start: np.ndarray):
        """(q, q̇, q̈) of the first n steps (copies) for a run from ``start``: the pass's, when
        the start puts the free solids' angles in the same whole turns as the guess did
        (``turns``); else None (converted as usual)."""
        if self.q is None:
            return None
        if not np.array_equal(start, self.guess) and not np.array_equal(
                turns(start[self.free_fi], self.first), turns(self.guess[self.free_fi],
                                                              self.first)):
            return None
        return self.q[:n].copy(), self.qd[:n].copy(), self.qdd[:n].copy()

    def reactions(self, times: np.ndarray, q, qd, qdd):
        """The ``Reactions`` of this motion from the pass's group when it is the pass's own
        (the run's times, x, y, fi and rates as the pass found them), or its configurations
        at rest (the pass's times and x, y, fi, q̇ = q̈ = 0: the quasi-static equilibrium),
        else None."""
        if self.group is None or self.q is None or not (
                np.array_equal(times, self.times) and np.array_equal(q, self.q)):
            return None
        if np.array_equal(qd, self.qd) and np.array_equal(qdd, self.qdd):
            return self.group.reactions(self.index)
        if not (np.any(qd) or np.any(qdd)):
            return self.group.reactions(self.index, at_rest=True)
        return None

    def positions(self, form, times: np.ndarray, start: np.ndarray, w: np.ndarray,
                  tolerance: float):
        """(z, ż, z̈) of the steps ``times`` when they are this run's first steps asked from
        where it started: the guess itself, or a start within the Newton tolerance of its
        first step (what Newton from there gives, to the tolerance); else None (another
        request: solved as usual)."""
        n = len(times)
        if n > len(self.times) or not np.array_equal(times, self.times[:n]):
            return None
        if not np.array_equal(start, self.guess):
            with np.errstate(all="ignore"):
                off = np.max(np.abs(form.from_q(start)[0] - self.z[0]) * w, initial=0.0)
            if not off <= tolerance:
                return None
        return self.z[:n], self.zd[:n], self.zdd[:n]


class Stacked:
    """Equations of one structure with the constants of each of V variants as a column
    (``CONSTANTS``): ``terms(columns)`` evaluates them for any columns at once.

    Parameters
    ----------
    terms : list of Terms
        Each variant's equations, all with one ``structure``.
    """

    def __init__(self, terms: list[Terms]):
        first = terms[0]
        shape = structure(first)
        if any(structure(t) != shape for t in terms[1:]):
            raise ValueError("variants with different equation structures do not stack")
        self.base = copy.copy(first)
        self.base.laws = []                  # the targets are added here, per variant
        self.constants = {c: np.concatenate([getattr(t, c) for t in terms], axis=1)
                          for c in CONSTANTS}
        self.nz, self.m = first.nz, first.m

    def terms(self, columns: np.ndarray) -> Terms:
        """The equations of the variants ``columns``, one column each (a shallow copy of
        the structure with their constants)."""
        out = copy.copy(self.base)
        for c, value in self.constants.items():
            setattr(out, c, value[:, columns])
        return out


class Stack(Stacked):
    """The equations of V variants with one structure (``Stacked``), with what their run
    needs: each variant's Newton weights and its laws' targets at the run's times.

    Parameters
    ----------
    terms : list of Terms
        Each variant's equations (``Formulation.terms``), all with one ``structure``.
    weights : list of arrays (nz,)
        What each variant's Newton step is measured in (``Natural.weights``).
    times : array (n,)
        The run's times: the laws' targets g, g', g'' of every variant there, once.
    """

    def __init__(self, terms: list[Terms], weights: list[np.ndarray], times: np.ndarray):
        super().__init__(terms)
        self.w = np.stack(weights, axis=1)                                   # (nz, V)
        self.times = np.asarray(times, dtype=float)
        #: g^(order) (3, laws, V, n): the laws' targets of every variant at every time
        self.g = np.stack([np.stack([t.targets(self.times, order) for t in terms], axis=1)
                           for order in range(3)]) if terms[0].laws else None

    def targets(self, order: int, steps: np.ndarray, columns: np.ndarray
                ) -> np.ndarray | None:
        """g^(order) (laws, N) of the columns: variant ``columns`` at step ``steps``."""
        return None if self.g is None else self.g[order][:, columns, steps]


def solve(stack: Stack, z_start: np.ndarray, tolerance: float, max_iterations: int) -> Answers:
    """Every variant's run from its guess ``z_start`` (nz, V) at the first time (module
    doc): the assembly, then the coarse pass (``_coarse``), then every step in between at
    once, variant × step (``_fill``)."""
    t, nz, V = stack.times, stack.nz, z_start.shape[1]
    n = len(t)
    z, zd, zdd = (np.full((n, nz, V), np.nan) for _ in range(3))
    alive = np.arange(V)
    found, ok, rates, spent = solved_steps(stack, np.zeros(V, dtype=int), alive,
                                           np.array(z_start, dtype=float), tolerance,
                                           max_iterations)
    alive = alive[ok]
    z[0][:, alive], (zd[0][:, alive], zdd[0][:, alive]) = found[:, ok], rates
    coarse = [0]
    if alive.size and n > 1:
        alive, coarse, used = _coarse(stack, z, zd, zdd, alive, tolerance, max_iterations)
        spent += used
    if alive.size:
        alive, used = _fill(stack, z, zd, zdd, coarse, alive, tolerance, max_iterations)
        spent += used
    solved = np.zeros(V, dtype=int)
    solved[alive] = n
    z[:, :, solved < n] = np.nan              # a failed variant: its own run solves it
    return Answers(z, zd, zdd, solved, spent)


def _coarse(stack: Stack, z, zd, zdd, alive: np.ndarray, tolerance: float,
            max_iterations: int):
    """(the variants still running, the coarse steps, Newton iterations): steps one interval
    after the other for every variant at once, each from its Taylor predictor
    z + h ż + h²/2 z̈, as the single run's coarse pass (``solver``): the interval is cut
    to a quarter where some variant's predictor missed by more than COARSE_MISS, doubled
    where all missed by less than COARSE_MISS / COARSE_GROW; step by step in a short run.
    A variant that fails a single step is left out."""
    t, n = stack.times, len(stack.times)
    base = 1 if n < SHORT else max(STRIDE, (n - 1) // COARSE)
    longest = max(base, min(COARSE_LONGEST * base, COARSE_LONGEST_STEPS))
    k, stride, coarse, spent = 0, base, [0], 0
    while k < n - 1 and alive.size:
        j = min(n - 1, k + stride)
        h = t[j] - t[k]
        guess = z[k][:, alive] + h * zd[k][:, alive] + 0.5 * h * h * zdd[k][:, alive]
        found, ok, rates, used = solved_steps(stack, np.full(alive.size, j), alive, guess,
                                              tolerance, max_iterations)
        spent += used
        miss = np.max(np.abs(found - guess) * stack.w[:, alive], axis=0, initial=0.0)
        miss[~ok] = np.inf
        if j - k > 1 and np.max(miss) > COARSE_MISS:     # a shorter interval
            stride = max(1, stride // 4)
            continue
        if j - k > 1 and np.max(miss) < COARSE_MISS / COARSE_GROW:
            stride = min(longest, 2 * stride)
        alive = alive[ok]
        z[j][:, alive], (zd[j][:, alive], zdd[j][:, alive]) = found[:, ok], rates
        coarse.append(j)
        k = j
    return alive, coarse, spent


def _fill(stack: Stack, z, zd, zdd, coarse: list[int], alive: np.ndarray, tolerance: float,
          max_iterations: int):
    """(the variants that solved every step, Newton iterations): the steps between the
    coarse ones, FILL_COLUMNS variant × step columns at a time, each from the quintic
    through z, ż and z̈ at the coarse steps around it (``solver.quintic_hermite``: a
    study's runs are short, their coarse intervals long for the motion, where the cubic
    through z and ż costs a third Newton iteration: 2.5 per variant-step instead of 3.2
    for 400 four-bars × 100 steps)."""
    t = stack.times
    inner = [(a, b, k) for a, b in zip(coarse[:-1], coarse[1:]) for k in range(a + 1, b)]
    failed = np.zeros(len(stack.w[0]), dtype=bool)
    spent = 0
    if not inner:
        return alive, spent
    per = max(1, FILL_COLUMNS // alive.size)
    for lo in range(0, len(inner), per):
        block = np.array(inner[lo:lo + per])                      # (a, b, k) per step
        cols = np.tile(alive, len(block))                          # variant of each column
        a, b, k = (np.repeat(block[:, i], alive.size) for i in range(3))
        h = t[block[:, 1]] - t[block[:, 0]]                        # the Hermite weights
        s = (t[block[:, 2]] - t[block[:, 0]]) / h                  # per step, then each
        w = np.repeat(np.array(quintic_hermite(s, h)), alive.size, axis=1)   # variant's
        guess = (w[0] * z[a, :, cols].T + w[1] * zd[a, :, cols].T + w[2] * zdd[a, :, cols].T
                 + w[3] * z[b, :, cols].T + w[4] * zd[b, :, cols].T + w[5] * zdd[b, :, cols].T)
        found, ok, rates, used = solved_steps(stack, k, cols, guess, tolerance,
                                              max_iterations, far=COARSE_MISS)
        spent += used
        good = np.nonzero(ok)[0]
        z[k[good], :, cols[good]] = found[:, good].T
        zd[k[good], :, cols[good]], zdd[k[good], :, cols[good]] = (r.T for r in rates)
        failed[cols[~ok]] = True
    return alive[~failed[alive]], spent


def solved_steps(stack: Stack, steps: np.ndarray, columns: np.ndarray, guess: np.ndarray,
                 tolerance: float, max_iterations: int, far: float | None = None):
    """(z (nz, N), ok (N,), (ż, z̈) of the ok columns, Newton iterations): each column
    (variant ``columns``, step ``steps``) solved from its guess, its rates then from the
    Jacobian at the solution; not ok where Newton failed, landed more than ``far``
    (weighted) from the guess (perhaps another branch), or Φ_z is singular."""
    terms = stack.terms(columns)
    found, ok, spent = newton(stack, terms, steps, columns, guess, tolerance, max_iterations)
    if far is not None:
        miss = np.max(np.abs(found - guess) * stack.w[:, columns], axis=0, initial=0.0)
        ok &= miss <= far
    if not ok.all():
        terms = stack.terms(columns[ok])
    rates = rates_at(stack, terms, steps[ok], columns[ok], found[:, ok])
    if rates is None:                         # a singular Jacobian somewhere: leave it out
        regular = np.zeros_like(ok)
        regular[ok] = _regular(terms, found[:, ok])
        ok &= regular
        terms = stack.terms(columns[ok])
        rates = rates_at(stack, terms, steps[ok], columns[ok], found[:, ok])
        if rates is None:
            ok[:] = False
            empty = np.empty((stack.nz, 0))
            rates = (empty, empty)
    return found, ok, rates, spent


def newton(stack: Stack, terms: Terms, steps: np.ndarray, columns: np.ndarray, z: np.ndarray,
           tolerance: float, max_iterations: int):
    """(z (nz, N), ok (N,), iterations): Newton's iteration for the columns (variant
    ``columns`` at step ``steps``) from z; a column stops when its weighted step is below
    the tolerance."""
    z = np.array(z, dtype=float)
    N = z.shape[1]
    ok = np.zeros(N, dtype=bool)
    active = np.arange(N)
    g = stack.targets(0, steps, columns)
    spent = 0
    for _ in range(max_iterations):
        if not active.size:
            break
        part = terms if active.size == N else stack.terms(columns[active])
        with np.errstate(all="ignore"):
            phi, data = part.residual_jacobian_cols(None, z[:, active])
            if g is not None:
                phi[part.law_rows] -= g[:, active]
            dz = linear_solve(part, data, -phi)
        spent += active.size
        step = np.max(np.abs(dz) * stack.w[:, columns[active]], axis=0, initial=0.0)
        finite = np.isfinite(step)
        z[:, active[finite]] += dz[:, finite]
        done = finite & (step <= tolerance)
        ok[active[done]] = True
        active = active[finite & ~done]
    return z, ok, spent


def rates_at(stack: Stack, terms: Terms, steps: np.ndarray, columns: np.ndarray,
             z: np.ndarray):
    """(ż, z̈) (nz, N) of the columns: Φ_z ż = g', Φ_z z̈ = γ with one factorisation of Φ_z
    at the solved z; None when a Jacobian is singular."""
    N = z.shape[1]
    if not N:
        return np.empty((stack.nz, 0)), np.empty((stack.nz, 0))
    vel = np.zeros((terms.m, N))
    if stack.g is not None:
        vel[terms.law_rows] = stack.targets(1, steps, columns)
    with np.errstate(all="ignore"):
        data = terms.jacobian_cols(z)
        factors = factor(terms, data)
        if factors is None:
            return None
        zd = factors(vel)
        acc = terms.gamma_cols(None, z, zd)
        if stack.g is not None:
            acc[terms.law_rows] += stack.targets(2, steps, columns)
        zdd = factors(acc)
    if not (np.isfinite(zd).all() and np.isfinite(zdd).all()):
        return None
    return zd, zdd


def linear_solve(terms: Terms, data: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x (nz, N) with Φ_z x = b per column (NaN where Φ_z is singular)."""
    factors = factor(terms, data)
    if factors is None:                      # some singular: each alone
        x = np.full((terms.nz, b.shape[1]), np.nan)
        for j in range(b.shape[1]):
            A = terms.dense_cols(data[:, j:j + 1])[:, :, 0]
            try:
                x[:, j] = np.linalg.solve(A, b[:, j])
            except np.linalg.LinAlgError:
                pass
        return x
    return factors(b)


def factor(terms: Terms, data: np.ndarray):
    """The solve b ↦ Φ_z⁻¹ b of every column at once (a function of b (m, N)), from one
    factorisation: batched dense LU with threshold pivoting for a small system, a sparse LU
    of the block-diagonal system for a large one; None when some Φ_z is singular or not
    finite. Each column's arithmetic is its own (its pivots chosen from its own values): a
    variant's answer does not depend on the others in its chunk."""
    if not np.isfinite(data).all():
        return None
    N = data.shape[1]
    if terms.nz < SPARSE_FROM:
        A = terms.dense_cols(data)
        swaps, regular = lu_factor(A, PIVOT_THRESHOLD)
        if not regular.all():
            return None
        return lambda b: lu_solve(A, swaps, b)
    from scipy.sparse import csc_matrix
    from scipy.sparse.linalg import splu
    m, nz = terms.m, terms.nz
    step = np.arange(N)[:, None]
    A = csc_matrix((data.T.ravel(), ((step * m + terms.rows).ravel(),
                                     (step * nz + terms.cols).ravel())), shape=(N * m, N * nz))
    try:
        lu = splu(A, permc_spec="NATURAL")     # each block as it is: its own arithmetic
    except RuntimeError:
        return None
    return lambda b: lu.solve(np.ascontiguousarray(b.T).ravel()).reshape(N, nz).T


def _regular(terms: Terms, z: np.ndarray) -> np.ndarray:
    """Which variants' Φ_z at z (nz, N) is regular (finite, of full rank)."""
    data = terms.jacobian_cols(z)
    A = np.moveaxis(terms.dense_cols(data), 2, 0)
    good = np.isfinite(A).all(axis=(1, 2))
    good[good] = np.linalg.matrix_rank(A[good]) == terms.nz
    return good
