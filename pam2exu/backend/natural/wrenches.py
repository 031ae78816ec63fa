"""Every constraint element's wrench on its receiver from the solids' constraint forces W and
the multipliers μ of the natural inverse dynamics (``reactions``' plan): the elements with
equations from their rows in each solid's own frame, the revolutes at the shared basic points
by per-body equilibrium, the fixed links by the held solid's balance (``reactions``' module
doc)."""
from __future__ import annotations

import numpy as np


def wrenches(pl, z, zeta, J, Jh, W, mu, origins):
    """Each constraint element's wrench (n, elements, 3) on its receiver, about the
    receiver's origin, from the solids' constraint forces W and the multipliers μ (linear in
    both: ``reactions``' module doc). Inside, one row per quantity with the steps along it (step-last
    copies of the inputs): every operation runs along the steps, none along an axis of 2."""
    form, mech = pl.form, pl.mech
    n, nc = len(z), len(mech.constraints)
    Wt, Zt = (np.ascontiguousarray(x.transpose(1, 2, 0)) for x in (W, zeta))  # (ns, 4, n)
    mut, zt = np.ascontiguousarray(mu.T), z.T
    wrench = np.zeros((nc, 3, n))                              # about O, on the receiver
    on = {}                                                    # (element, solid) -> about O
    # A_sᵀ W_s per solid, on the columns of its column pins only (``Plan.copied``), then
    # s's rigid rows on its copy, in rounds (``Plan._copied``): each entry's terms in order
    copy = np.zeros((pl.copy_size, n))
    flat = Wt.reshape(-1, n)
    for number, (rows, sources, numbers) in enumerate(pl.copy_terms):
        if number:
            copy[rows] += flat[sources] * numbers
        else:
            copy[rows] = flat[sources] * numbers
    for rows, r, c in pl.copy_rigid:
        copy[rows] += J[:, r, c].T * mut[r]
    for k, rows in pl.rows_of.items():
        total = np.zeros((3, n))
        weights = mut[pl.first + rows]
        for i in pl.solids_of[k]:
            if i in form.grounds or (k, i) in on:
                continue
            wanted = pl.frame_columns[i]
            part = np.ascontiguousarray(Jh[:, rows[:, None], wanted].transpose(1, 2, 0))
            g = _summed(weights, part)                                  # (Φ_ζ̂ᵀ μ) there
            minus = -g
            on[(k, i)] = w = _about_origin(Zt[i], minus[0:2], minus[2:4],
                                           minus[4] if len(wanted) == 5 else 0.0)
            total += w
            if i in pl.copy_rows:          # (its angle column is no pin's)
                copy[pl.copy_rows[i]] += _combined(g, pl.copied[i][1])
        receiver = pl.receivers[k]
        wrench[k] = -total if receiver in form.grounds else on[(k, receiver)]
        for i in pl.solids_of[k]:
            if i in form.grounds:
                on[(k, i)] = on.get((k, i), 0.0) - total
    balance = _about_origin(Zt, Wt[:, :2], Wt[:, 2:])          # (ns, 3, n)
    left = balance.copy()                                      # what the pins must give
    for (k, i), w in on.items():
        if i not in form.grounds:                              # (a ground's is not read)
            left[i] -= w
    for pin in pl.ordered_pins:                                # column points first
        if pin.columns is not None:
            point = zt[pin.take]
            force = [copy[at] for at in pin.at]
            for r, i in enumerate(pin.solids):
                left[i, :2] -= force[r]
                left[i, 2] -= _cross(point, force[r])
        else:
            point = pin.constant
            force = [left[i, :2] for i in pin.solids]      # (views: left is done)
        for e, k in enumerate(pin.revolutes):                  # on each receiver
            w = wrench[k]
            w[:2] = _mixed(pin.inverse[e], force)
            w[2] = _cross(point, w[:2])
            for i in pl.solids_of[k]:
                if i in form.grounds:
                    sign = 1.0 if i == pl.receivers[k] else -1.0
                    on[(k, i)] = on.get((k, i), 0.0) + sign * w
    for k, g in pl.held:                                       # the held solid's balance
        w = balance[g].copy()
        for (kk, i), other in on.items():
            if i == g and kk != k:
                w -= other
        wrench[k] = w
    ox, oy = origins                                           # about the receiver's origin
    wrench[:, 2] -= ox * wrench[:, 1] - oy * wrench[:, 0]
    return wrench.transpose(2, 0, 1)


def _summed(weights, rows) -> np.ndarray:
    """Σ_r weights[r] rows[r] (rows (R, k, n), weights (R, n)), r ascending from 0 (as
    numpy.einsum: no negative zeros)."""
    out = np.zeros(rows.shape[1:])
    for r in range(len(weights)):
        out += weights[r] * rows[r]
    return out


def _mixed(weights, vectors) -> np.ndarray:
    """Σ_s weights[s] vectors[s] (weights (S,), vectors S of (2, n)), s ascending."""
    out = weights[0] * vectors[0]
    for s in range(1, len(weights)):
        out = out + weights[s] * vectors[s]
    return out


def _about_origin(zeta, force_p, force_v, moment=0.0):
    """(…, 3, n): forces (force_p, force_v) (…, 2, n) on a frame's (p, v) (zeta (…, 4, n)),
    and a moment on its angle, as a force and a moment about the global origin:
    (F, p × F + G_v·Ω v + M) (one row per quantity, the steps along it; … the solids)."""
    out = np.empty(force_p.shape[:-2] + (3, force_p.shape[-1]))
    out[..., :2, :] = force_p
    px, py, vx, vy = (zeta[..., k, :] for k in range(4))
    fx, fy, gx, gy = force_p[..., 0, :], force_p[..., 1, :], force_v[..., 0, :], force_v[..., 1, :]
    out[..., 2, :] = (px * fy - py * fx) + (gy * vx - gx * vy) + moment
    return out


def _cross(a, b):
    """a × b (n,) of two vectors given as rows (2, n) (a: also a constant (2,))."""
    return a[0] * b[1] - a[1] * b[0]


def _combined(rows, terms) -> np.ndarray:
    """(len(terms), n): row r = Σ rows[k] c over the (k, c) of terms[r], k ascending (the
    nonzero terms of an einsum over k: the same sums)."""
    out = np.zeros((len(terms), rows.shape[-1]))
    for r, pairs in enumerate(terms):
        for number, (k, c) in enumerate(pairs):
            out[r] = out[r] + rows[k] * c if number else rows[k] * c
    return out
