"""Cheap chunk tasks for tests/studies/test_execute.py, in a module of their own so that
the worker processes of a pool or a Dask cluster import only NumPy to run them.

Row i depends only on the payload's seed and i (``numpy.random.default_rng([seed, i])``),
as a study's variant does; every call leaves a file in the payload's ``calls`` folder, so
a test counts the chunks computed.
"""
import os
import sys
from pathlib import Path

import numpy as np


def rows(payload, start, stop):
    """Rows start … stop − 1: ``sample`` = i, ``x`` a normal draw, ``v`` three more (a 2-D
    column), ``status`` "ok" for x > 0 else "rejected"."""
    Path(payload["calls"], f"{start}-{stop}-{os.getpid()}").touch()
    draws = np.array([np.random.default_rng([payload["seed"], i]).standard_normal(4)
                      for i in range(start, stop)])
    return {"sample": np.arange(start, stop), "x": draws[:, 0], "v": draws[:, 1:],
            "status": np.where(draws[:, 0] > 0, "ok", "rejected")}


def own_rows(payload, start, stop, rows):
    """Rows start … stop − 1 from the chunk's ``rows`` (``run_chunks``' rows): ``x`` = 2 ×
    its first column, ``sent`` the rows the chunk was sent, ``first`` the first one's x."""
    return {"sample": np.arange(start, stop), "x": 2.0 * rows[:, 0],
            "sent": np.full(stop - start, len(rows)), "first": np.full(stop - start, rows[0, 0])}


def dies_once(payload, start, stop):
    """``rows``, but the first attempt at the chunk holding row ``payload["die_at"]`` kills
    its process (the marker file ``payload["marker"]`` tells the first attempt)."""
    if start <= payload["die_at"] < stop:
        try:
            os.close(os.open(payload["marker"], os.O_CREAT | os.O_EXCL))
        except FileExistsError:
            pass
        else:
            os._exit(1)
    return rows(payload, start, stop)


def always_dies(payload, start, stop):
    """``rows``, but the chunk holding row ``payload["die_at"]`` kills its process."""
    if start <= payload["die_at"] < stop:
        os._exit(1)
    return rows(payload, start, stop)


def raises(payload, start, stop):
    """``rows``, but the chunk holding row ``payload["bad"]`` raises (a bug)."""
    if start <= payload["bad"] < stop:
        raise ZeroDivisionError("a bug in the task")
    return rows(payload, start, stop)


def short(payload, start, stop):
    """``rows`` with one row too few in ``x``."""
    columns = rows(payload, start, stop)
    columns["x"] = columns["x"][1:]
    return columns


def imported(names):
    """Which of the modules ``names`` this process had imported when it ran this task
    (this module imports none of pam2exu)."""
    return [name in sys.modules for name in names]
