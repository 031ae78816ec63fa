"""Forward dynamics in natural coordinates (the ``dynamic`` analysis on the natural backend).

With the constant mass matrix M of the formulation (``Formulation.mass_matrix``), the
equations of motion of the constrained system are

    M z̈ + Φ_zᵀ μ = Q(z, ż, t),    Φ(z, t) = 0,

Q the forces of gravity, the torsors and the spring-dampers on the natural coordinates
(``inverse.on_coordinates`` of ``loads.Loads``; the dampers from the rates).
Differentiating the constraints twice (index 1) gives, at every state,

    [M   Φ_zᵀ] [z̈]   [Q]
    [Φ_z  0  ] [μ] = [γ],    γ = g'' − (d/dt Φ_z) ż   (``Terms.gamma``),

an ODE in y = (z, ż) that scipy's DOP853 integrates (Radau where DOP853 would need too
many steps: a stiff model). Index 1 alone lets Φ and Φ_z ż − g' drift; after every
accepted step the state is projected back onto both (least-norm Gauss–Newton, then the
velocity equations: a correction of the size of the step's error), and so is each output
state, interpolated by the method's dense output.

Accuracy on demand: the run is made at rtol = atol = r and again at r / ``REFINE``; the
larger difference of the two, per coordinate and rate of x, y, fi relative to
1 + |value|, bounds the error of the coarser run, and the finer one is returned. While it
exceeds the tolerance, r is divided by ``REFINE`` again.
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import SolverError
from ...kinematics import ANGLES, column
from ...progress import Progress
from .inverse import bodies, on_coordinates
from .loads import Loads

#: the first run's rtol and atol, times the tolerance
FIRST = 0.1
#: the ratio of the tolerances of two successive runs
REFINE = 16.0
#: below this rtol DOP853 cannot go (scipy: 100 machine epsilons)
SMALLEST = 1e-13
#: DOP853 steps per run beyond which the model is taken as stiff (Radau from then on)
STIFF_STEPS = 20_000
#: steps of one run at most
MOST_STEPS = 2 ** 21
#: a run's pace (the interval's share its steps have covered) is extrapolated to the end of
#: the interval after this many steps, then after twice as many, … : at a pace that needs
#: more than PACE_FACTOR × MOST_STEPS it stops there (an interval of 1e7 s for Andrews'
#: mechanism, 4 ms a step: over a minute before DOP853 even handed over to Radau), not at
#: MOST_STEPS; a run whose later steps are longer than its first by less than PACE_FACTOR
#: (a motion that settles) never meets it
PACE_STEPS = 1000
PACE_FACTOR = 64
#: units of the progress bar of one integration over the interval (per mille)
PROGRESS_UNITS = 1000
#: Gauss–Newton iterations of the projection onto Φ = 0
PROJECTIONS = 4


class Dynamics:
    """The equations of motion of a formulation, and their integration.

    Parameters
    ----------
    backend : Natural
        Its ``to_q`` and ``to_rates`` turn z into x, y, fi.
    form : Formulation
    mech : Mechanism
    """

    def __init__(self, backend, form, mech):
        self.backend, self.form, self.mech = backend, form, mech
        self.terms = form.terms
        self.nz, self.m = form.nz, form.terms.m
        self.M = form.mass_matrix()
        self.K = form.pose_forms()                  # (x, y, cos, sin) per solid = K [z; 1]
        self.kind = backend._angle_kinds(form)
        self.fi = mech.initial_q()[ANGLES].copy()   # the continuous angles, followed
        # gravity acts at fixed points of the solids (a, b constant): Q_z is constant
        weight = Loads(form, np.zeros((1, self.nz)), np.zeros((1, mech.nq)))
        weight.gravity(mech.gravity)
        self.bodies = bodies(form)                  # Q on (p, v) -> Q on z
        self.weight = on_coordinates(self.bodies, weight.Q)[0]
        self.stiff = False                          # DOP853 until it needs too many steps
        self.evaluations = 0

    @property
    def method(self):
        """scipy's integrator: DOP853, Radau once the model is taken as stiff (imported
        here, not with the module: a study or a kinematic run never integrates)."""
        from scipy.integrate import DOP853, Radau
        return Radau if self.stiff else DOP853

    # ---- the equations ------------------------------------------------------------------
    def angles(self, z: np.ndarray) -> np.ndarray:
        """fi of every solid at z (nz,), continuous: the turn nearest the last ones."""
        pose = self.K[:, :-1] @ z + self.K[:, -1]
        fi = np.arctan2(pose[3::4], pose[2::4])
        fi += 2 * np.pi * np.rint((self.fi - fi) / (2 * np.pi))
        k = self.kind
        fi[k.fixed] = k.fixed_values
        fi[k.coordinate] = z[k.columns]
        return fi

    def generalized_forces(self, t: float, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """Q (nz,) of gravity, torsors and spring-dampers at the state."""
        q = np.zeros((1, self.mech.nq))
        q[0, ANGLES] = self.angles(z)
        loads = Loads(self.form, z[None], q, zd[None], t=t)
        for el in self.mech.elements:
            el.natural_loads(loads)
        return self.weight + on_coordinates(self.bodies, loads.Q)[0]

    def jacobian(self, z: np.ndarray) -> np.ndarray:
        """Φ_z (m, nz) at one configuration."""
        return self.terms.dense(self.terms.jacobian(z[None]))[0]

    def accelerations(self, t: float, z: np.ndarray, zd: np.ndarray) -> np.ndarray:
        """z̈ from [[M, Φ_zᵀ], [Φ_z, 0]] [z̈; μ] = [Q; γ] (least squares where redundant
        constraints make it singular: consistent, so exact)."""
        J = self.jacobian(z)
        A = np.zeros((self.nz + self.m, self.nz + self.m))
        A[:self.nz, :self.nz] = self.M
        A[:self.nz, self.nz:] = J.T
        A[self.nz:, :self.nz] = J
        b = np.concatenate([self.generalized_forces(t, z, zd),
                            self.terms.gamma(np.array([t]), z[None], zd[None])[0]])
        if self.redundant:
            return np.linalg.lstsq(A, b, rcond=1e-12)[0][:self.nz]
        return np.linalg.solve(A, b)[:self.nz]

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """ẏ = (ż, z̈)."""
        self.evaluations += 1
        z, zd = y[:self.nz], y[self.nz:]
        return np.concatenate([zd, self.accelerations(t, z, zd)])

    def project(self, t: float, y: np.ndarray) -> np.ndarray:
        """y moved by least norm onto Φ(z, t) = 0 and Φ_z ż = g'(t)."""
        z, zd = y[:self.nz].copy(), y[self.nz:].copy()
        tt = np.array([t])
        for _ in range(PROJECTIONS):
            phi = self.terms.residual(tt, z[None])[0]
            if not np.any(np.abs(phi) > 1e-15 * self.scale):
                break
            z -= np.linalg.lstsq(self.jacobian(z), phi, rcond=1e-12)[0]
        J = self.jacobian(z)
        zd -= np.linalg.lstsq(J, J @ zd - self.terms.velocity_rhs(self._before(tt))[0],
                              rcond=1e-12)[0]
        return np.concatenate([z, zd])

    def _before(self, t: np.ndarray) -> np.ndarray:
        """t, or just before it at the end of the interval: a law's rate jumps at its
        breakpoints, the laws give its value after the jump there, and the state at the
        end of a segment is the one before (the analysis applies the impulse)."""
        end = self.end
        return np.where(t >= end - 1e-12 * max(1.0, abs(end)), end - 1e-12 * max(1.0, abs(end)), t)

    # ---- x, y, fi -------------------------------------------------------------------------
    def start(self, t0: float, q0: np.ndarray, qd0: np.ndarray) -> np.ndarray:
        """y0 = (z, ż) of (q0, q̇0): z from the poses, ż from the velocity equations with the
        solids' rates (ẋ, ẏ = K ż and (cos, sin)˙ = (−sin, cos) ḟi), least squares."""
        self.scale, self.end = self.mech.scale(), math.inf
        z = self.form.from_q(q0[None])[0]
        J = self.jacobian(z)
        self.redundant = np.linalg.matrix_rank(J, tol=1e-10 * max(1.0, np.abs(J).max())) \
            < J.shape[0]
        self.fi = self.fi0 = np.asarray(q0, float)[ANGLES].copy()
        z = self.project(t0, np.r_[z, np.zeros(self.nz)])[:self.nz]
        Kz = self.K[:, :self.nz]
        fi, w = q0[ANGLES], qd0[ANGLES]
        rates = np.empty(len(self.K))
        rates[0::4], rates[1::4] = qd0[column(np.arange(len(fi)), 0)], \
            qd0[column(np.arange(len(fi)), 1)]
        rates[2::4], rates[3::4] = -np.sin(fi) * w, np.cos(fi) * w
        A = np.r_[self.jacobian(z), Kz]
        b = np.r_[self.terms.velocity_rhs(np.array([t0]))[0], rates]
        zd = np.linalg.lstsq(A, b, rcond=1e-12)[0]
        return self.project(t0, np.r_[z, zd])

    def to_q(self, ys: np.ndarray, fis: np.ndarray, q0: np.ndarray):
        """(q, q̇) (n, nq) of states ys (n, 2 nz), the angles in the turns ``fis`` followed."""
        z, zd = ys[:, :self.nz], ys[:, self.nz:]
        q = self.backend.to_q(self.form, self.mech, z, q0)
        q[:, ANGLES] += 2 * np.pi * np.rint((fis - q[:, ANGLES]) / (2 * np.pi))
        qd, _ = self.backend.to_rates(self.form, self.mech, z, zd, np.zeros_like(z))
        return q, qd

    # ---- one integration ---------------------------------------------------------------
    def run(self, times: np.ndarray, y0: np.ndarray, r: float):
        """States (n, 2 nz) at ``times`` and the angles followed, from y0 at times[0], with
        rtol = atol = r, projected after every step; and the steps taken."""
        n = len(times)
        self.end = float(times[-1])
        out, fis = np.empty((n, len(y0))), np.empty((n, len(self.fi)))
        self.fi = self.fi0
        self.fi = self.angles(y0[:self.nz])
        out[0], fis[0] = y0, self.fi
        solver = self.method(self.rhs, float(times[0]), y0.copy(), float(times[-1]),
                             rtol=max(r, SMALLEST), atol=r)
        with Progress(PROGRESS_UNITS, f"integrating the motion ({self.method.__name__}, "
                                      f"tolerance {r:.2g})") as bar:
            return self._stepped(solver, times, out, fis, bar)

    def _check_pace(self, steps: int, t0: float, t: float, end: float) -> None:
        """SolverError when ``steps`` steps from t0 to t, at that pace, would need more than
        PACE_FACTOR × MOST_STEPS steps to reach ``end``."""
        needed = steps * (end - t0) / (t - t0) if t > t0 else math.inf
        if needed > PACE_FACTOR * MOST_STEPS:
            raise SolverError(
                f"t={t:g}: the natural backend's integrator ({self.method.__name__}) took "
                f"{steps:,} steps to reach t = {t:.3g} s of the interval's {end:g} s: at that "
                f"pace it would need about {needed:.1g} steps, far more than the "
                f"{MOST_STEPS:,} a run may take. The interval is far longer than the "
                f"motion's time scale (a step of about {(t - t0) / steps:.1g} s): end it "
                f"earlier ([analysis] t_end), check that it is in seconds, or loosen the "
                f"tolerance", time=t)

    def _stepped(self, solver, times, out, fis, bar):
        """``run``'s steps of ``solver`` until the last time, each reported to ``bar``."""
        n, t0 = len(times), float(times[0])
        k, steps, pace = 1, 0, PACE_STEPS
        end = float(times[-1])
        while k < n:
            message = solver.step()
            steps += 1
            bar.update(int(PROGRESS_UNITS * (solver.t - t0) / (end - t0)))
            if steps == pace:
                pace *= 2
                self._check_pace(steps, t0, float(solver.t), end)
            if solver.status == "failed" or steps > MOST_STEPS:
                raise SolverError(
                    f"t={solver.t:g}: the natural backend's integrator ({self.method.__name__}) "
                    f"stopped ({message or f'more than {MOST_STEPS:,} steps'}). The motion "
                    "may reach a singular position where the mechanism locks or branches: "
                    "check the model there (pam2exu draw MODEL --t T), or end the interval "
                    "before it", time=float(solver.t))
            if not self.stiff and steps > STIFF_STEPS:
                return None, None, steps
            t = solver.t
            last = k
            while k < n and times[k] <= t + 1e-12 * max(1.0, abs(end)):
                k += 1
            if k > last:
                dense = solver.dense_output()
                for j in range(last, k):
                    y = solver.y if times[j] >= t else dense(float(times[j]))
                    out[j] = self.project(float(times[j]), y)
                    self.fi = fis[j] = self.angles(out[j][:self.nz])
            solver.y = self.project(t, solver.y)
            solver.f = self.rhs(t, solver.y)
            self.fi = self.angles(solver.y[:self.nz])
        return out, fis, steps


def motion(backend, form, mech, times, q0, qd0, tolerance: float, verbose: int = 0):
    """(q, q̇ (n, nq) at ``times``, error estimate, steps of the finest run): runs at
    rtol = atol = r = ``FIRST`` · tolerance, r / ``REFINE``, … until two successive runs
    differ by at most tolerance · (1 + |value|) on every x, y, fi and rate (the finer one
    returned), or r reaches ``SMALLEST`` (the estimate then says what was reached; r starts
    there for a tolerance below 10 ``SMALLEST``)."""
    times = np.asarray(times, dtype=float)
    q0, qd0 = np.asarray(q0, float), np.asarray(qd0, float)
    dyn = Dynamics(backend, form, mech)
    y0 = dyn.start(float(times[0]), q0, qd0)
    if len(times) < 2:
        return q0[None], qd0[None], 0.0, 0
    # below SMALLEST the runs would not go finer (a subnormal tolerance made r = 0: rtol
    # and atol 0, a run that never ends; 1e-300 an atol DOP853 cannot step to)
    r = max(FIRST * tolerance, SMALLEST)
    previous, estimate = None, math.inf
    while True:
        ys, fis, steps = dyn.run(times, y0, r)
        if ys is None:                     # stiff: Radau from the same tolerance
            dyn.stiff = True
            continue
        found = dyn.to_q(ys, fis, q0)
        if verbose:
            print(f"natural dynamics: {dyn.method.__name__} rtol {r:.3g}: {steps} steps, "
                  f"{dyn.evaluations} evaluations")
        if previous is not None:
            estimate = max(float(np.max(np.abs(a - b) / (1.0 + np.abs(b))))
                           for a, b in zip(previous, found))
            if estimate <= tolerance or r <= SMALLEST:
                return found[0], found[1], estimate, steps
        previous = found
        r /= REFINE
