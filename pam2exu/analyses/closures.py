"""The closure of a mechanism with clearance joints, as the clearance analysis evaluates it
(shared/spec/clearance.md): F(u(t), j, q, r(t)) = C(q, t) + F_j j at one time or at many
rows at once, its rate along the path of dimensions, and its clearance parameters laid out.

``Closures.evaluate`` gives C, F_q, F_j and W = Σ λ_i ∂²F_i/∂q² at one (t, q, λ), every
constraint element's rows (``Element.constraint``, or ``Element.clearance_constraint``
where the element has ``clearance = true``) with the points and lines of the
``[[variation]]`` entries at u(t); ``evaluate_rows`` the same at n rows in one State (the
checks and the Newton corrections of every output row at once); ``evaluate_rate`` adds
h_t = (0, F_qtᵀλ, C_t) from the same evaluation: F_u u′ and F_qu u′ by one complex step in
the dimensions u, the laws' f′ from the laws. The mathematics they feed is ``least_norm``.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, replace

import numpy as np

from ..kinematics import PER_SOLID, PointSet, State
from ..model.solid import LineRef
from ..laws import LAWS, Law
from ..model.variation import COMPONENTS
from .least_norm import Closure
from .native import target_values

#: the imaginary step of ``Closures.evaluate_rate``: Im F(u + i STEP u′) / STEP = F_u u′,
#: exact to rounding (no difference is taken)
STEP = 1e-30


class Closures:
    """The closure of ``mech`` at any time, with its clearance parameters laid out.

    Parameters
    ----------
    mech : Mechanism
        The validated mechanism (its ``variations`` bound).
    start : numpy.ndarray
        q at the nominal assembly (what a prismatic's sense is read from).
    """

    def __init__(self, mech, start: np.ndarray):
        self.mech = mech
        self.start = State([0.0], np.asarray(start, dtype=float)[None])
        #: the clearance elements, in element order, and the names of their parameters
        self.elements = [el for el in mech.constraints if el.clearance]
        self.names = [f"{el.name}.{var.name}" for el in self.elements
                      for var in el.clearance_parameters]
        self.p, self.nq, self.m = len(self.names), mech.nq, mech.n_equations
        #: (element, anchor k, its Variation) of every varied anchor of a constraint element
        self.varied = [(el, k, v) for el in mech.constraints for k in range(len(el.refs))
                       if (v := mech.variation(el, k)) is not None]
        #: the Variations that move some anchor, once each
        self._variations = list({id(v): v for _, _, v in self.varied}.values())
        #: their laws' constants (V, 3): τ, ω, Δ/2 and δ of x, y, angle (``_offsets``)
        laws = [[(float(v.tau), v.omega(name), 0.5 * float(getattr(v, key)))
                 for name, key, *_ in COMPONENTS] for v in self._variations]
        self._tau, self._omega, self._half = np.array(laws).reshape(-1, 3, 3).transpose(2, 0, 1)
        self._fixed = np.array([v.fixed for v in self._variations]).reshape(-1, 3)
        #: (index, element, [(anchor k, Variation)]) of the elements with a varied anchor
        self._varied_elements = []
        for index, el in enumerate(mech.constraints):
            anchors = [(k, v) for e, k, v in self.varied if e is el]
            if anchors:
                self._varied_elements.append((index, el, anchors))
        #: the points and directions of the elements at their nominal dimensions
        #: (``State.prepare``: built at once at every evaluation; a varied one is built
        #: where it is asked for, at its dimensions then)
        nominal = State([0.0], self.start.q, hessians=True)
        for el in mech.constraints:
            self._constraint(el, nominal)
        self._points = PointSet.of(nominal.asked)
        self._fitted: Linear | None = None
        self.Fj = np.zeros((self.m, self.p))
        k = 0
        for el, rows in zip(mech.constraints, mech.rows):
            if el in self.elements:
                width = len(el.clearance_parameters)
                self.Fj[rows, k:k + width] = np.asarray(el.clearance_terms, dtype=float)
                k += width

    def columns(self, j: np.ndarray) -> dict[str, np.ndarray]:
        """The result columns of the clearance parameters j (n, p), and those derived from
        them (a revolute's jr), as ``<element>.<name>``."""
        out, k = {}, 0
        for el in self.elements:
            values = {}
            for var in el.clearance_parameters:
                values[var.name] = j[:, k]
                k += 1
            values.update(el.clearance_derived_values(values))
            out.update({f"{el.name}.{name}": v for name, v in values.items()})
        return out

    @property
    def has_fixed(self) -> bool:
        """Some ``[[variation]]`` has a fixed deviation (``fixed_dx`` …) to reach at t = 0
        (``as_made``)."""
        return any(v.has_fixed for v in self.mech.variations)

    def at(self, t, reached: float = 1.0, along: str | None = None) -> list:
        """The constraint elements with their varied points and lines at time t (copies;
        the elements whose anchors do not vary are the mechanism's own), the fixed
        deviations ``reached`` of the way (``Variation.offsets``). ``t`` a float, or an
        array (n,): the varied coordinates are then arrays, one value per row. ``along``
        "t" or "s": each offset u − u0 is given the imaginary part ``STEP`` · du/dt (time)
        or ``STEP`` · δ (the path u0 + s δ), the complex step of ``evaluate_rate``."""
        rows = np.ndim(t) > 0
        moved = self._moved_offsets(t, reached, along)
        out = list(self.mech.constraints)
        for index, el, anchors in self._varied_elements:
            refs = list(el.refs)
            for k, variation in anchors:
                refs[k] = _moved(refs[k], moved[id(variation)], rows)
            el = copy.copy(el)
            el.refs = tuple(refs)
            el.ref1, el.ref2 = refs[0], refs[1] if len(refs) > 1 else None
            out[index] = el
        return out

    def _moved_offsets(self, t, reached: float, along: str | None) -> dict:
        """id(Variation) -> u − u0 (3,) at the time t (an array (3, n) for times (n,)),
        with the complex step of ``along`` (``at``)."""
        moved = {}
        if self._variations:
            u, du = self._offsets(np.atleast_1d(t), reached)           # (V, n, 3)
            if along is not None:
                u = u + 1j * STEP * (du if along == "t" else self._fixed[:, None])
            for variation, offset in zip(self._variations, u):
                moved[id(variation)] = offset.T if np.ndim(t) > 0 else offset[0]
        return moved

    def _offsets(self, t: np.ndarray, reached: float):
        """u − u0 and u′ (V, n, 3) of every varied anchor's Variation at the times t (n,):
        ``Variation.offsets`` of them all at once (``variation.ramped_cosine``'s terms)."""
        tt = t[None, :, None]
        tau, omega, half = self._tau[:, None], self._omega[:, None], self._half[:, None]
        decay = np.exp(-tt / tau)
        ramp = -np.expm1(-tt / tau)
        cos, sin = np.cos(omega * tt), np.sin(omega * tt)
        return (reached * self._fixed[:, None] + ramp * half * cos,
                half * (decay / tau * cos - ramp * omega * sin))

    def _offsets_at(self, t: float, reached: float):
        """``_offsets`` at one time t, (V, 3) each (fewer operations: the ODE's
        right-hand sides)."""
        x = t / self._tau
        ramp = -np.expm1(-x)
        phase = self._omega * t
        cos = np.cos(phase)
        return (reached * self._fixed + ramp * self._half * cos,
                self._half * (np.exp(-x) / self._tau * cos - ramp * self._omega * np.sin(phase)))

    def evaluate(self, t: float, q: np.ndarray, lam: np.ndarray,
                 reached: float = 1.0) -> Closure:
        """C (without F_j j), F_q, F_j and W = Σ λ_i ∂²F_i/∂q² at (t, q), the fixed
        deviations ``reached`` of the way."""
        C, Fq, W, _, _ = self._evaluate(t, q[None], lam[None], reached)
        return Closure(C[0], Fq[0], self.Fj, W[0])

    def evaluate_rows(self, times: np.ndarray, q: np.ndarray, lam: np.ndarray,
                      reached: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(C (n, m), F_q (n, m, nq), W (n, nq, nq)) at the rows (t_k, q_k, λ_k) in one
        State: ``evaluate`` at each row."""
        return self._evaluate(np.asarray(times, dtype=float), q, lam, reached)[:3]

    def evaluate_rate(self, t: float, q: np.ndarray, lam: np.ndarray, reached: float = 1.0,
                      along: str = "t") -> tuple[Closure, np.ndarray]:
        """(the Closure at (t, q, λ), h_t): the rate of the Lagrange conditions along the
        path at fixed y = (j, q, λ), h_t = (0, F_qtᵀλ, C_t) (F_j constant), along the time
        (``along`` "t": C_t = F_u u′ − f′, u′ the variations' rates, f′ the laws') or the
        straight path of the fixed deviations (``along`` "s": F_u δ at time t): F_u u′ and
        F_qu u′ exact, by one complex step in the dimensions u (``STEP``)."""
        C, Fq, W, rate, jacobian_rate = self._evaluate(t, q[None], lam[None], reached, along)
        closure = Closure(C[0], Fq[0], self.Fj, W[0])
        return closure, np.concatenate([np.zeros(self.p), jacobian_rate[0].T @ lam, rate[0]])

    def _evaluate(self, t, q, lam, reached=1.0, along=None):
        """(C, F_q, W, C_t, F_qt) at the rows (t, q, λ) (t a float for one row; the last
        two None without ``along``)."""
        n = q.shape[0]
        lam = np.asarray(lam, dtype=float)
        fast = along is not None and n == 1 and self._linear.elements
        if fast and len(self._linear.elements) == len(self.mech.constraints):
            u, du = self._offsets_at(float(t), reached)
            return self._linear.rate(float(t), q[0], lam[0], u,
                                     du if along == "t" else self._fixed, along == "t")
        if fast:                                  # the ODE's right-hand sides
            moved = self._moved_offsets(t, reached, along)
            C, Fq, W, f_rate = self._linear.evaluate(np.array([t], dtype=float), q[0],
                                                     lam[0], moved)
        st = State(np.broadcast_to(t, (n,)), np.asarray(q, dtype=float), hessians=True)
        dtype = complex if along is not None else float
        if fast:
            C, Fq, W, f_rate = (a[None].astype(dtype) for a in (C, Fq, W, f_rate))
            f_rate = f_rate.real
        else:
            C = np.zeros((n, self.m), dtype)
            Fq = np.zeros((n, self.m, self.nq), dtype)
            W = np.zeros((n, self.nq, self.nq), dtype)
            f_rate = np.zeros((n, self.m))
            st.prepare(self._points)
        for k, (el, rows) in enumerate(zip(self.at(t, reached, along), self.mech.rows)):
            if fast and k in self._linear.elements:
                continue
            v, target = self._constraint(el, st)
            f, df, _ = target_values(target, st.t, el.equations)
            C[:, rows] = v.value - f
            if along == "t":
                f_rate[:, rows] = df
            v.rows(Fq, rows.start)
            v.weighted_hessian(lam[:, rows], W)
        if along is None:
            return C, Fq, W, None, None
        return C.real, Fq.real, W.real, C.imag / STEP - f_rate, Fq.imag / STEP

    @property
    def _linear(self) -> "Linear":
        """The elements evaluated by products in the ODE's right-hand sides (``Linear``),
        found when first needed (a run with no ODE never fits them)."""
        if self._fitted is None:
            lines = [el for el, a, _ in self.varied if isinstance(el.refs[a], LineRef)]
            self._fitted = Linear(self, [k for k, el in enumerate(self.mech.constraints)
                                         if not any(el is e for e in lines)])
        return self._fitted

    def _constraint(self, el, st: State):
        """(v, target) of an element's rows: with clearance, ``clearance_constraint``."""
        if el.clearance:
            return el.clearance_constraint(st, self.start)
        return el.constraint(st)


#: random configurations on which ``Linear`` fits (beyond the unknowns) and checks
SAMPLES = 8


class Linear:
    """The constraint elements (their indices ``elements``) whose rows are linear in x =
    (the values of the closure's points and directions, q): v = A x, A found by least
    squares on random configurations and checked on as many others (a revolute P2 − P1,
    a fixed solid's or an actuator's coordinates). For the ODE's right-hand sides they are
    evaluated by products: F_q = A ∂x/∂q, and W from the points' ∂²(A s)/∂fi² = −A s.
    Their rows do not depend on the varied dimensions; their C_t is −f′ (the laws)."""

    def __init__(self, closures: "Closures", candidates: list[int]):
        self.points, self.nq, self.m = closures._points, closures.nq, closures.m
        mech, K = closures.mech, len(closures._points.keys)
        rng = np.random.default_rng(0)
        size = 2 * K + self.nq + SAMPLES
        q = rng.uniform(-np.pi, np.pi, (2 * size, self.nq))
        x = self.values(q)
        st = State(np.zeros(2 * size), q, hessians=False)
        self.elements, self.rows, blocks, self.targets = {}, [], [], []
        #: (rows, ∂v/∂P (d, 2), the point's solid, id(Variation)) of every varied point
        #: anchor of an element here: v moves by ∂v/∂P A(fi) δ with the point's offset δ
        self.moves: list[tuple] = []
        for k in candidates:
            el, rows = mech.constraints[k], mech.rows[k]
            v, target = closures._constraint(el, st)
            A = np.linalg.lstsq(x[:size], v.value[:size], rcond=None)[0].T
            if np.max(np.abs(x[size:] @ A.T - v.value[size:])) <= 1e-11 * (
                    1.0 + np.max(np.abs(v.value))):
                self.elements[k] = el
                self.rows.append(np.arange(rows.start, rows.stop))
                blocks.append(A)
                self.targets.append((rows, target, el.equations))
                self.moves += self._moves(closures, el, rows)
        self.rows = np.concatenate(self.rows) if self.rows else np.zeros(0, int)
        self.A = np.vstack(blocks) if blocks else np.zeros((0, 2 * K + self.nq))
        s = self.points
        self.fi = PER_SOLID * s.solids + 2
        #: the targets that are constants (f, f′ = 0), once; the laws at each evaluation
        self.constant = np.zeros(self.m)
        laws = []
        for rows, target, d in self.targets:
            if isinstance(target, Law):
                laws.append((rows, target))
            else:
                self.constant[rows] = target_values(target, np.zeros(1), d)[0]
        self.targets = laws
        #: the laws as (rows, function, constants), called at a float time (``rate``)
        self.laws = [(rows, LAWS[law.name].function, law.C) for rows, law in laws]
        index = {id(v): i for i, v in enumerate(closures._variations)}
        #: ``moves`` with the Variation's index in ``Closures._offsets`` and the fi column
        self.indexed = [(rows, G, PER_SOLID * solid + 2, index[v])
                        for rows, G, solid, v in self.moves]
        self.local_x, self.local_y = s.local[:, 0].copy(), s.local[:, 1].copy()
        #: ∂x/∂q but its angle columns of the points (``evaluate`` writes them)
        self.jac = np.zeros((2 * K + self.nq, self.nq))
        point = np.arange(K)[s.translate]
        self.jac[2 * point, PER_SOLID * s.solids[s.translate]] = 1.0
        self.jac[2 * point + 1, PER_SOLID * s.solids[s.translate] + 1] = 1.0
        self.jac[2 * K:, :] = np.eye(self.nq)
        self.even, self.odd = 2 * np.arange(K), 2 * np.arange(K) + 1
        #: the entries of x that are points' coordinates, and the columns of q added there
        self.shift = np.r_[2 * point, 2 * point + 1]
        self.origin = np.r_[PER_SOLID * s.solids[s.translate],
                            PER_SOLID * s.solids[s.translate] + 1]
        self._rate_layout(K)

    @staticmethod
    def _moves(closures: "Closures", el, rows: slice) -> list[tuple]:
        """``moves`` of an element linear in its points: ∂v/∂P of each varied point anchor,
        from its values with the point's local coordinates moved by (1, 0) and (0, 1) at
        q = 0 (A(fi) = I there; exact for rows linear in P)."""
        out = []
        for e, a, variation in closures.varied:
            if e is not el:
                continue
            st = State([0.0], np.zeros((1, closures.nq)), jacobians=False)
            base = closures._constraint(el, st)[0].value[0]
            G = []
            for unit in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
                shifted = copy.copy(el)
                refs = list(el.refs)
                refs[a] = _moved(refs[a], np.array(unit))
                shifted.refs = tuple(refs)
                shifted.ref1, shifted.ref2 = refs[0], refs[1] if len(refs) > 1 else None
                st = State([0.0], np.zeros((1, closures.nq)), jacobians=False)
                G.append(closures._constraint(shifted, st)[0].value[0] - base)
            out.append((np.arange(rows.start, rows.stop), np.array(G).T,
                        el.refs[a].solid, id(variation)))
        return out

    def values(self, q: np.ndarray) -> np.ndarray:
        """x (n, 2K + nq) at the configurations q (n, nq)."""
        return np.hstack([self._rotated(q)[1].reshape(len(q), -1), q])

    def _rotated(self, q):
        """(A s (n, K, 2), the points' and directions' values (n, K, 2))."""
        s = self.points
        fi = q[:, PER_SOLID * s.solids + 2]
        c, sn = np.cos(fi), np.sin(fi)
        As = np.stack([c * s.local[:, 0] - sn * s.local[:, 1],
                       sn * s.local[:, 0] + c * s.local[:, 1]], axis=-1)
        origin = np.stack([q[:, PER_SOLID * s.solids], q[:, PER_SOLID * s.solids + 1]],
                          axis=-1)
        return As, np.where(s.translate[None, :, None], As + origin, As)

    def evaluate(self, t: np.ndarray, q: np.ndarray, lam: np.ndarray, moved: dict):
        """(C, F_q, W, f′) of the rows of ``elements`` at one (t, q, λ), zero elsewhere, their
        varied points at the offsets ``moved`` (id(Variation) -> u − u0, complex in a complex
        step: then so are C, F_q and W)."""
        K, s = len(self.points.keys), self.points
        c, sn = np.cos(q[self.fi]), np.sin(q[self.fi])
        x = np.empty(2 * K + self.nq)
        x[self.even] = c * s.local[:, 0] - sn * s.local[:, 1]      # A s
        x[self.odd] = sn * s.local[:, 0] + c * s.local[:, 1]
        jac = self.jac.copy()
        jac[self.even, self.fi] = -x[self.odd]                      # ∂(A s)/∂fi = Ω A s
        jac[self.odd, self.fi] = x[self.even]
        weights = lam[self.rows] @ self.A[:, :2 * K]
        curvature = -(weights[self.even] * x[self.even] + weights[self.odd] * x[self.odd])
        x[self.shift] += q[self.origin]                             # points: R + A s
        x[2 * K:] = q
        C, Fq = -self.constant, np.zeros((self.m, self.nq))
        f_rate = np.zeros(self.m)
        C[self.rows] += self.A @ x
        Fq[self.rows] = self.A @ jac
        W = np.diag(np.bincount(self.fi, curvature, minlength=self.nq))   # ∂²(A s)/∂fi²
        for rows, law in self.targets:
            f, df, _ = law(t)
            C[rows] -= f[0]
            f_rate[rows] = df[0]
        if self.moves:
            C, Fq, W = C.astype(complex), Fq.astype(complex), W.astype(complex)
        for rows, G, solid, variation in self.moves:
            dx, dy = moved[variation][0], moved[variation][1]
            fi = q[PER_SOLID * solid + 2]
            c, sn = np.cos(fi), np.sin(fi)
            Ad = np.array([c * dx - sn * dy, sn * dx + c * dy])       # A(fi) δ
            C[rows] += G @ Ad
            Fq[rows, PER_SOLID * solid + 2] += G @ np.array([-Ad[1], Ad[0]])
            W[PER_SOLID * solid + 2, PER_SOLID * solid + 2] -= lam[rows] @ (G @ Ad)
        return C, Fq, W, f_rate

    def _rate_layout(self, K: int) -> None:
        """``rate``'s x: the K points and directions, then each varied point's offset δ and
        its rate δ′ as two directions of its solid (E of each: ``indexed``), then q; its
        A (the offsets' columns ∂v/∂P) and A′ (the rates' columns ∂v/∂P, C_t = A′ x)."""
        E = len(self.indexed)
        self.rate_K = K + 2 * E
        cols = np.array([col for _, _, col, _ in self.indexed], dtype=int)
        self.rate_fi = np.r_[self.fi, cols, cols]
        self.rate_v = np.array([v for *_, v in self.indexed], dtype=int)
        self.rate_even = 2 * np.arange(self.rate_K)
        self.rate_odd = self.rate_even + 1
        width, R = 2 * self.rate_K + self.nq, len(self.rows)
        self.rate_A, self.rate_A1 = np.zeros((R, width)), np.zeros((R, width))
        self.rate_A[:, :2 * K], self.rate_A[:, 2 * self.rate_K:] = self.A[:, :2 * K], \
            self.A[:, 2 * K:]
        position = {int(r): i for i, r in enumerate(self.rows)}
        for i, (rows, G, _, _) in enumerate(self.indexed):
            at = [position[int(r)] for r in rows]
            for A, entry in ((self.rate_A, K + i), (self.rate_A1, K + E + i)):
                A[at, 2 * entry] += G[:, 0]
                A[at, 2 * entry + 1] += G[:, 1]
        self.rate_points = np.ascontiguousarray(self.rate_A[:, :2 * self.rate_K])
        self.rate_jac = np.zeros((width, self.nq))
        self.rate_jac[:2 * K] = self.jac[:2 * K]
        self.rate_jac[2 * self.rate_K:] = np.eye(self.nq)

    def rate(self, t: float, q: np.ndarray, lam: np.ndarray, u: np.ndarray,
             du: np.ndarray, laws: bool = True):
        """(C, F_q, W, C_t, F_qt) (each with a leading axis of 1) at one (t, q, λ) when
        ``elements`` are all the constraint elements, in real numbers: the varied points at
        the offsets u (V, 3) moving at du (V, 3) (C_t += ∂v/∂P A(fi) du, F_qt its ∂/∂fi),
        and C_t −= f′ of the laws where ``laws`` (a rate along the time). ``evaluate``'s
        complex step, by hand."""
        K, v = self.rate_K, self.rate_v
        fi = q[self.rate_fi]
        c, sn = np.cos(fi), np.sin(fi)
        lx = np.concatenate((self.local_x, u[v, 0], du[v, 0]))
        ly = np.concatenate((self.local_y, u[v, 1], du[v, 1]))
        ax, ay = c * lx - sn * ly, sn * lx + c * ly                 # A s, A δ, A δ′
        x = np.empty(2 * K + self.nq)
        x[self.rate_even], x[self.rate_odd] = ax, ay
        jac = self.rate_jac.copy()
        jac[self.rate_even, self.rate_fi] = -ay                     # ∂(A s)/∂fi = Ω A s
        jac[self.rate_odd, self.rate_fi] = ax
        weights = lam[self.rows] @ self.rate_points
        curvature = -(weights[self.rate_even] * ax + weights[self.rate_odd] * ay)
        x[self.shift] += q[self.origin]                             # points: R + A s
        x[2 * K:] = q
        C = -self.constant
        C[self.rows] += self.rate_A @ x
        Fq = np.zeros((self.m, self.nq))
        Fq[self.rows] = self.rate_A @ jac
        W = np.diag(np.bincount(self.rate_fi, curvature, minlength=self.nq))  # ∂²(A s)/∂fi²
        C_t, F_qt = np.zeros(self.m), np.zeros((self.m, self.nq))
        if self.indexed:                                            # ∂v/∂P A(fi) δ′
            C_t[self.rows] = self.rate_A1 @ x
            F_qt[self.rows] = self.rate_A1 @ jac
        for rows, function, constants in self.laws:
            f, df, _ = function(t, constants)
            C[rows] -= f
            if laws:
                C_t[rows] -= df
        return C[None], Fq[None], W[None], C_t[None], F_qt[None]


@dataclass(frozen=True)
class _MovedLine(LineRef):
    """A line whose defining point and angle are arrays, one value per row
    (``Closures.at`` on rows): its direction and normal by NumPy."""

    @property
    def direction(self):
        return (np.cos(self.angle), np.sin(self.angle))

    @property
    def normal(self):
        return (-np.sin(self.angle), np.cos(self.angle))


def _moved(ref, offset: np.ndarray, rows: bool = False):
    """A point or line reference moved by u − u0 = (dx, dy, dangle) in its solid's frame
    (``rows``: each an array, one value per row)."""
    if isinstance(ref, LineRef):
        line = _MovedLine if rows else type(ref)
        return line(ref.solid, (ref.point[0] + offset[0], ref.point[1] + offset[1]),
                    ref.angle + offset[2], ref.label)
    return replace(ref, local=(ref.local[0] + offset[0], ref.local[1] + offset[1]))

