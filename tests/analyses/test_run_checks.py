"""The checks of every run done with less work (issue 25, the per-run costs), checked by
comparing bits with the plain computations, never by time: the equilibration of Cq in place,
the condition check's eigenvalues at the steps that can be the worst only."""
from __future__ import annotations

import numpy as np
import pytest

from pam2exu.analyses import rank


def _norm_equilibrated(J):
    """Rows and columns of J scaled to unit length, three passes, by np.linalg.norm."""
    for _ in range(3):
        J = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        J = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
    return J


@pytest.mark.parametrize("m, nq", [(1, 3), (5, 6), (12, 12), (9, 12), (14, 12), (40, 45)])
def test_the_equilibration_is_the_norms_bits(m, nq):
    """``_equilibrated`` (squares summed in place) gives np.linalg.norm's passes bit for bit,
    zero rows and columns and scales from 1e-6 to 1e6 included, complex too."""
    rng = np.random.default_rng(m * 100 + nq)
    J = rng.standard_normal((7, m, nq)) * rng.choice([1e-6, 1.0, 1e6], size=nq)
    J[2, 0] = 0.0
    J[3, :, -1] = 0.0
    assert rank._equilibrated(J).tobytes() == _norm_equilibrated(J).tobytes()
    Z = J + 1e-20j * rng.standard_normal(J.shape)
    assert rank._equilibrated(Z).tobytes() == _norm_equilibrated(Z).tobytes()


def _smooth(rng, steps, m, nq, peak):
    """Equilibrated Cq along a smooth closed path whose κ peaks near step ``peak``."""
    a, b, c = (0.1 * rng.standard_normal((m, nq)) for _ in range(3))
    s = np.linspace(0.0, 2 * np.pi, steps)[:, None, None]
    J = np.eye(m, nq) + a + np.cos(s) * b + np.sin(s) * c
    J[:, :, 0] += 0.5 * np.exp(-((s[:, :, 0] - s[peak, 0, 0]) ** 2)) * J[:, :, 1]
    return rank._equilibrated(J)


@pytest.mark.parametrize("steps, peak", [(101, 50), (101, 3), (102, 101), (5, 2), (400, 217)])
def test_steps_ruled_out_by_a_probed_neighbour_are_below_the_largest(steps, peak, monkeypatch):
    """On a smooth motion the Gram eigenvalues are taken at fewer steps than the run's
    (every PROBE-th step, then those Weyl's bound from a probed neighbour cannot rule out),
    and the largest condition number and its step are still every step's SVD's."""
    rng = np.random.default_rng(steps + peak)
    A = _smooth(rng, steps, 12, 12, peak)
    sizes, eigvalsh = [], np.linalg.eigvalsh
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda G: sizes.append(len(G)) or eigvalsh(G))

    class Mech:
        nq = 12

    every = rank.condition_numbers(Mech, None, None, A)
    k = int(np.argmax(every))
    sizes.clear()
    assert rank.largest_condition(Mech, None, None, A) == (k, float(every[k]))
    if steps > 5:
        assert sum(sizes) < steps
    assert k in rank._candidates(rank._equilibrated(A))
