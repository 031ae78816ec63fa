"""The position solve's predictor, and the measurement that decides whether it pays.

Exudyn's static solver starts each load step's Newton iteration from the previous step's
solution; ``Predictor`` starts it from the parabola through the last three steps instead
(one iteration per step instead of two on smooth motions), through a Python pre-step
function. What that call costs against the Newton iteration it saves depends on the machine
and its load, so a long run first solves a short probe (``Probe``): blocks of steps with the
predictor and without it, alternately, each step timed; the rest of the run is then solved
with the predictor only where it was clearly the faster (``predictor_pays``).
"""
from __future__ import annotations

import time

import numpy as np

#: runs of at least this many steps are probed (shorter ones always predict: the probe would
#: be a large part of the run, and a step of a short run moves far, so the predictor saves
#: two iterations or more there)
PROBE_FROM = 4096
#: steps of the probe: WARM_UP steps first (not timed: the first steps after the assembly
#: take more iterations), then BLOCKS blocks of BLOCK steps, with and without the predictor
#: alternately, ending with the predictor (so that its history is ready for the rest)
WARM_UP, BLOCK, BLOCKS = 8, 32, 6
PROBE_STEPS = WARM_UP + BLOCK * BLOCKS
#: the predictor's first steps after a break have no three-step history: not timed
HISTORY = 3
#: the predictor is kept only if its median step is this much shorter: in the probe both ways
#: pay for a pre-step call (about 1 µs of a 20 µs step), after it only the predictor's way
MARGIN = 0.05
#: the percentile of each way's step times that is compared: the lower quartile, a step's own
#: cost (the probe times this thread's CPU, ``ExudynSystem.clock``; other processes on the
#: machine still slow some steps through the caches, and a median then followed the load: on
#: a loaded machine it kept the predictor in 7 of 12 probes where the lower quartile kept it
#: in 9 of 9, the whole run 0.77x as long with it)
QUANTILE = 25


def extrapolate(q1: np.ndarray, q2: np.ndarray, q3: np.ndarray) -> np.ndarray:
    """q_k ≈ 3 q_{k−1} − 3 q_{k−2} + q_{k−3}: the parabola through three equally spaced steps, one step on."""
    return 3.0 * (q1 - q2) + q3


class Predictor:
    """Sets Exudyn's coordinates, before each load step, to ``extrapolate`` of the last three
    steps solved on the grid.

    Called once per load step with the step's grid index, or None for a step Exudyn made
    smaller after a failure; the coordinates at a call are the previous step's solution, so
    only an unbroken run of grid steps k−3, k−2, k−1 feeds the extrapolation. The last three
    solutions are kept in a ring and combined in place (few NumPy calls: this runs once per
    step).
    """

    def __init__(self, system_data):
        self.get, self.set = system_data.GetODE2Coordinates, system_data.SetODE2Coordinates
        self.last, self.count, self.history = None, 0, [None, None, None]
        self.guess = None

    def __call__(self, k: int | None) -> None:
        if k is None or self.last is None or k != self.last + 1:
            self.count = 0
        else:
            history, slot = self.history, self.count % 3
            history[slot] = self.get()
            self.count += 1
            if self.count >= 3:
                # extrapolate(q1, q2, q3) in place, operation for operation (same rounding)
                q1, q2, q3 = history[slot], history[slot - 1], history[slot - 2]
                if self.guess is None:
                    self.guess = np.empty_like(q1)
                guess = np.subtract(q1, q2, out=self.guess)
                guess *= 3.0
                guess += q3
                self.set(guess.tolist())      # a list: Exudyn converts it faster
        self.last = k


def predictor_pays(with_predictor, without) -> bool:
    """Q(with) < (1 − MARGIN) · Q(without), Q the lower quartile of the probe's step times [s]."""
    return bool(len(with_predictor) and len(without)
                and np.percentile(with_predictor, QUANTILE)
                < (1.0 - MARGIN) * np.percentile(without, QUANTILE))


class Probe:
    """The probe's pre-step part: predicts in the blocks that use the predictor and times every
    step (the time from one call to the next), by ``clock``.

    Called like ``Predictor`` with the step's index in the probe (None: a cut step); after
    the probe, ``pays()`` tells whether the predictor's steps were the faster.
    """

    def __init__(self, predict: Predictor, clock=time.perf_counter):
        self.predict, self.clock = predict, clock
        self.times = {True: [], False: []}
        self.previous = None          # (clock, mode and whether that step is timed)

    @staticmethod
    def predicting(i: int) -> bool:
        """Whether probe step i uses the predictor: the warm-up and the odd blocks."""
        return i < WARM_UP or ((i - WARM_UP) // BLOCK) % 2 == (BLOCKS - 1) % 2

    @staticmethod
    def timed(i: int) -> bool:
        """Whether probe step i counts: past the warm-up, and past a predictor block's first
        steps (no history yet)."""
        return i >= WARM_UP and (not Probe.predicting(i) or (i - WARM_UP) % BLOCK >= HISTORY)

    def __call__(self, i: int | None) -> None:
        now = self.clock()
        if self.previous is not None:
            then, mode, timed = self.previous
            if timed:
                self.times[mode].append(now - then)
        on = i is not None and self.predicting(i)
        if on:
            self.predict(i)
        else:
            self.predict.last = None          # a break in the predictor's history
        self.previous = None if i is None else (now, on, self.timed(i))

    def pays(self) -> bool:
        """Whether the probe's predictor steps were the faster (``predictor_pays``)."""
        return predictor_pays(self.times[True], self.times[False])
