"""branch.py: the verdict on a re-solved step, and whole turns taken back only where the
constraints still hold (two of the review's hand mutations survived every test).

References: the four-bar's closed-form poses in both assembly modes (the circle
intersection of ``references.closed_form.four_bar``, written out here for the mode below
A–O4), its motor law f(t) = 2π t (examples/four_bar.toml), and the constraint residual of
each configuration.
"""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import pam2exu
from pam2exu.analyses import branch, continuity, native
from references.closed_form import four_bar_angles

FOUR_BAR = Path(__file__).resolve().parents[2] / "examples" / "four_bar.toml"
a, b, c, d = 0.1, 0.35, 0.3, 0.4             # crank, coupler, rocker, ground [m]


def pose(theta: float, mode: int = 1) -> np.ndarray:
    """q = (x, y, fi) of ground, crank, coupler, rocker at crank angle θ; mode 1: coupler
    above the line A–O4 (the example's), −1: below (``references.closed_form``)."""
    phi, psi = four_bar_angles(a, b, c, d, theta, mode)
    A = a * np.array([math.cos(theta), math.sin(theta)])
    return np.array([0, 0, 0, 0, 0, theta, A[0], A[1], phi, d, 0, psi], dtype=float)


def test_a_re_solve_on_the_other_assembly_mode_is_never_better():
    """A run of 20 steps of 0.01 s stopped at step k = 10 (q[k] unsolved: no old jump to
    compare, old = ∞). The re-solve's candidate on the example's branch continues the motion
    (its velocity jump is the trapezoid rule's O(dt³)): 'better'. The candidate in the other
    assembly mode, whose velocities jump by O(1) of their scale, must be 'worse': 'better'
    needs the new jump ≤ min(JUMP, old / 10), not ≤ max(…) (= ∞ here)."""
    mech = pam2exu.load(FOUR_BAR).mechanism()
    t = np.linspace(0.0, 0.2, 21)
    q = np.array([pose(2 * math.pi * tk) for tk in t])
    k = 10
    qd, qdd, _ = native.rates(mech, t[:k], q[:k], True, False)
    stopped = q.copy()
    stopped[k] = np.nan
    job = SimpleNamespace(mech=mech, times=t)
    scale = branch._scales(mech, qd)
    on_branch = branch._compare(job, stopped, qd, qdd, k - 1, k, q[k], scale, False)
    other = pose(2 * math.pi * t[k], mode=-1)
    assert np.max(np.abs(native.residuals(mech, t[[k]], other[None]))) < 1e-15
    across = branch._compare(job, stopped, qd, qdd, k - 1, k, other, scale, False)
    assert (on_branch, across) == ("better", "worse")


def test_a_whole_turn_the_motor_demands_is_not_taken_back():
    """Two steps, t = 0 and 1 s, with rates 0 given: the motor's law puts the crank at
    f(1) = 2π, a whole turn more than the rates predict, so ``continuity.turns_jumped`` counts
    one turn. Taking it back would break the motor's equation by 2π: ``_unwrap`` must keep
    q. The rocker off by a whole turn (its joints are 2π-periodic) is taken back."""
    mech = pam2exu.load(FOUR_BAR).mechanism()
    t = np.array([0.0, 1.0])
    q = np.array([pose(0.0), pose(2 * math.pi)])
    still = np.zeros_like(q)
    assert np.max(np.abs(native.residuals(mech, t, q))) < 1e-15
    assert continuity.turns_jumped(t, q, still, 4)[1].tolist() == [0, 1, 0, 0]
    np.testing.assert_array_equal(branch._unwrap(mech, t, q, still, 2), q)
    t = np.array([0.0, 1e-9])
    turned = np.array([pose(0.0), pose(2 * math.pi * 1e-9)])
    turned[1, 11] += 2 * math.pi
    back = branch._unwrap(mech, t, turned, still, 2)
    assert abs(back[1, 11] - pose(2 * math.pi * 1e-9)[11]) < 1e-14
    assert back[1, 5] == turned[1, 5]
