"""The refactor check (tests/snapshot.py): a run captured twice is identical, and a change
of one bit of one number, or of a warning's text, is reported.

Reference: the captured run itself, changed by hand.
"""
from __future__ import annotations

import copy

import numpy as np

from tests.snapshot import capture, differences, ROOT


def test_one_bit_of_one_number_is_a_difference():
    key = ("examples/four_bar.toml", "assembly", "exudyn", None)
    before = {key: capture(ROOT, key[0], "assembly", None, "exudyn")}
    assert differences(before, {key: capture(ROOT, key[0], "assembly", None, "exudyn")}) == []
    after = copy.deepcopy(before)
    values = np.frombuffer(after[key]["data"]).copy()
    values[-1] = np.nextafter(values[-1], np.inf)
    after[key]["data"] = values.tobytes()
    after[key]["caught"] = after[key]["caught"] + [("InputWarning", "a new warning")]
    found = differences(before, after)
    assert len(found) == 2 and "table's bytes" in found[1] and "a new warning" in found[0]
    assert differences(before, {}) == [f"missing on one side: {key}"]
