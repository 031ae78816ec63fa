"""The self-checks fire: each test breaks what a check guards and sees it caught.

Issue 10, "checks that no test shows firing": raising ``RESIDUAL_TOLERANCE`` to 1e3, or the
branch criterion ``JUMP`` by 1e9, left every test green. These tests fail under those
mutations.
"""
from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import branch
from pam2exu.elements import Revolute

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_a_wrong_translation_is_caught_by_the_residual_check(monkeypatch):
    """Revolute 'B' translated with its marker on the rocker 1e-6 m off the point: Exudyn
    then closes a loop that pam2exu's own equation r2 − r1 = 0 says is open by 1e-6 m, far
    above the check's 1e-8 × L = 4e-9 m. The error names the element and the size."""
    real = Revolute.build

    def off_by_a_micron(self, ex):
        if self.name != "B":
            return real(self, ex)
        shifted = dataclasses.replace(self.ref2, local=(self.ref2.local[0] + 1e-6,
                                                        self.ref2.local[1]))
        ex.add(self, ex.items.ObjectJointRevolute2D(
            markerNumbers=[ex.point_marker(self.ref1), ex.point_marker(shifted)]))

    monkeypatch.setattr(Revolute, "build", off_by_a_micron)
    with pytest.raises(pam2exu.TranslationError) as info:
        pam2exu.run(EXAMPLES / "four_bar.toml", analysis="kinematic", steps=20)
    message = str(info.value)
    found = re.search(r"violates pam2exu's equations of element 'B' \(revolute\) by "
                      r"([0-9.e+-]+) \(tolerance 4e-09\)", message)
    assert found, message
    # one component of the 1e-6 m offset, turned with the rocker: between 1/√2 and 1 of it
    assert 0.7e-6 < float(found.group(1)) <= 1.0e-6
    assert "the translation of this element for Exudyn is wrong" in message


def test_the_translation_of_the_examples_passes_the_residual_check():
    """The same check on the true translation: the residual is round-off."""
    res = pam2exu.run(EXAMPLES / "four_bar.toml", analysis="kinematic", steps=20)
    assert res.info["max_residual"] < 1e-13


def test_a_velocity_jump_among_steps_that_all_jump_is_followed():
    """A branch switch shows as a velocity jump (``continuity.continuity_defect``) above JUMP =
    5 % of the velocities' scale, or as a spike above its neighbours. On a coarse grid near
    a change point every step jumps: no step stands out of the median of its neighbours,
    so only the absolute criterion finds the first jump (step 3 here)."""
    defect = np.array([0.0, 0.01, 0.01, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2])
    singular = np.zeros(len(defect), dtype=bool)
    assert branch._first_jump(defect, singular, set()) == 3
    assert branch._first_jump(defect, singular, {3, 4}) == 5
    # a smooth motion's defect, O((ω dt)³) and even, has no jump
    assert branch._first_jump(np.full(9, 1e-3), singular, set()) is None


def test_a_spike_above_its_neighbours_is_a_jump():
    """Below JUMP, a defect 10 × (SPIKE) the median of the 17 steps around it is a jump."""
    defect = np.full(40, 1e-3)
    defect[20] = 0.02
    assert branch._first_jump(defect, np.zeros(40, dtype=bool), set()) == 20


@pytest.mark.filterwarnings("ignore::pam2exu.ConditionWarning")
def test_following_the_branch_has_bounded_work(monkeypatch):
    """Re-solving to follow the branch may take at most RESOLVE_WORK times the run's
    position solves (plus a floor): with no allowance, the first re-solve the parallelogram
    needs at a change point is refused with a SolverError that says so, instead of
    re-solving the rest of the run (issue 10: the work of a run, re-solves included, is
    bounded)."""
    from test_hard_cases import parallelogram_model
    model = parallelogram_model(math.pi / 4)
    res = pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=600)
    assert res.info["branch_resolves"] >= 1                 # it needs re-solves
    monkeypatch.setattr(branch, "RESOLVE_WORK", 0)
    monkeypatch.setattr(branch, "RESOLVE_FLOOR", 0)
    with pytest.raises(pam2exu.SolverError, match=r"keeps switching branch near singular "
                                                  r"positions \(solving it again would take "
                                                  r"[0-9,]+ position solves, more than 0 "
                                                  r"times the run\)"):
        pam2exu.run(model, analysis="kinematic", t_end=1.0, steps=600)


def test_the_residual_check_takes_the_length_scale_only_above_its_smallest():
    """``check_residual`` leaves out the length scale when the residual is within the check
    at any scale: ``SMALLEST_SCALE`` is the least ``Mechanism.scale`` (a mechanism of
    points at the origin); a residual of 1.5e-8 × 1e-3 m is caught at that scale, not at
    the four-bar's 0.4 m; one of 0.5e-8 × 1e-3 m at neither."""
    from pam2exu.analyses import checks
    from pam2exu.errors import TranslationError
    four_bar = pam2exu.load(EXAMPLES / "four_bar.toml").mechanism()
    model = pam2exu.load(EXAMPLES / "four_bar.toml")
    for s in model.solids:
        s.x = s.y = 0.0
        for name in s.points:
            s.points[name] = [0.0, 0.0]
    point = model.mechanism()
    assert point.scale() == checks.SMALLEST_SCALE < four_bar.scale()
    t, q = np.zeros(1), np.zeros((1, point.nq))
    for size, caught in ((1.5, True), (0.5, False)):
        res = np.zeros((1, point.n_equations))
        res[0, 3] = size * checks.RESIDUAL_TOLERANCE * checks.SMALLEST_SCALE
        checks.check_residual(four_bar, t, q, res=res)
        if caught:
            with pytest.raises(TranslationError, match="violates"):
                checks.check_residual(point, t, q, res=res)
        else:
            checks.check_residual(point, t, q, res=res)
