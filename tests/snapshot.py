"""Bit-identity snapshot of pam2exu's results, for refactors that must change no number.

Runs every example and tests/data model, every analysis of the registry, default steps and
37 steps, on every backend, and pickles for each run: the columns and units, the table's
bytes, the run facts (timings removed), the warnings (class and text), the checks, the
summary text, or the error (class and text, and a partial table's bytes). About 4 minutes
on two idle cores (360 runs).

    python -m tests.snapshot OUT.pkl [--only SUBSTRING]     # from the checkout to measure
    python -m tests.snapshot --compare BEFORE.pkl AFTER.pkl  # exit 1 on any difference

Take the snapshot before the change (e.g. in a ``git worktree`` of the old commit), again
after, and compare: every difference is printed with both sides.
"""
from __future__ import annotations

import glob
import os
import pickle
import sys
import time
import tomllib
import warnings

#: the checkout whose models and package are run
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIMINGS = {"exudyn_seconds", "backend_seconds", "seconds", "solve_seconds"}
SKIP = {  # (model, analysis) pairs too slow for a snapshot: clearance over all_elements' 1 s
    ("examples/all_elements.toml", "clearance"),
}


def models(root):
    """The model files of examples/ and tests/data (study files, with their [study] table,
    are not models)."""
    out = []
    for pattern in ("examples/**/*.toml", "tests/data/**/*.toml"):
        out += sorted(glob.glob(os.path.join(root, pattern), recursive=True))
    return [os.path.relpath(p, root) for p in out if not _is_study(p)]


def _is_study(path) -> bool:
    with open(path, "rb") as f:
        return "study" in tomllib.load(f)


def table(res):
    import numpy as np
    return {"columns": list(res.columns), "units": dict(res.units),
            "data": np.ascontiguousarray(res.to_numpy()).tobytes(),
            "shape": res.to_numpy().shape}


def capture(root, path, analysis, steps, backend):
    import pam2exu
    from pam2exu.errors import Pam2ExuError
    entry = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = pam2exu.run(os.path.join(root, path), analysis, steps=steps, backend=backend)
            entry.update(table(res))
            entry["info"] = {k: v for k, v in dict(res.info).items() if k not in TIMINGS
                             and not k.endswith("seconds")}
            entry["warnings"] = list(res.warnings)
            entry["checks"] = list(res.checks())
            entry["summary"] = res.summary()
            entry["analysis"] = str(getattr(res.analysis, "name", res.analysis))
        except Pam2ExuError as exc:
            entry["error"] = (type(exc).__name__, str(exc).replace(root, "<root>"))
            partial = getattr(exc, "partial", None)
            if partial is not None:
                entry["partial"] = table(partial)
    entry["caught"] = [(w.category.__name__, str(w.message).replace(root, "<root>"))
                       for w in caught]
    for key in ("summary",):
        if key in entry:
            entry[key] = entry[key].replace(root, "<root>")
    entry["warnings"] = [w.replace(root, "<root>") for w in entry.get("warnings", [])]
    return entry


def snapshot(out, only=None):
    root = ROOT
    from pam2exu.registry import ANALYSES, BACKENDS
    result = {}
    start = time.perf_counter()
    for path in models(root):
        if only and only not in path:
            continue
        for analysis in ANALYSES:
            if (path, analysis) in SKIP:
                continue
            for backend in BACKENDS:
                for steps in (None, 37):
                    t0 = time.perf_counter()
                    result[(path, analysis, backend, steps)] = capture(root, path, analysis,
                                                                       steps, backend)
                    dt = time.perf_counter() - t0
                    if dt > 5:
                        print(f"  slow: {path} {analysis} {backend} {steps}: {dt:.1f} s",
                              file=sys.stderr)
    with open(out, "wb") as f:
        pickle.dump(result, f)
    print(f"{len(result)} runs in {time.perf_counter() - start:.0f} s -> {out}")


def differences(before: dict, after: dict) -> list[str]:
    """Every run missing on one side and every field of a run that differs, as text."""
    out = []
    for key in sorted(set(before) | set(after), key=str):
        if key not in before or key not in after:
            out.append(f"missing on one side: {key}")
            continue
        ea, eb = before[key], after[key]
        for field in sorted(set(ea) | set(eb)):
            va, vb = ea.get(field), eb.get(field)
            if va == vb:
                continue
            if field == "data":
                out.append(f"DIFF {key} {field}: the table's bytes differ")
            else:
                out.append(f"DIFF {key} {field}:\n   before: {va!r}\n   after:  {vb!r}")
    return out


def compare(a, b):
    with open(a, "rb") as f:
        before = pickle.load(f)
    with open(b, "rb") as f:
        after = pickle.load(f)
    found = differences(before, after)
    print("\n".join(found))
    errors = sum("error" in e for e in before.values())
    print(f"{len(before)} runs before ({errors} errors), {len(after)} after: "
          f"{len(found)} differences")
    return len(found)


if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        sys.exit(1 if compare(sys.argv[2], sys.argv[3]) else 0)
    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
    snapshot(sys.argv[1], only)
