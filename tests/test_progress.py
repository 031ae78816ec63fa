"""The progress bar (pam2exu/progress.py): silent off a terminal, and with ``rate`` the
units done, their rate and the time left, computed by hand from a clock the test sets.
"""
import io

from pam2exu.progress import Progress
from tests.conftest import Terminal



def test_the_rate_and_time_left_count_from_the_first_update(monkeypatch):
    monkeypatch.delenv("PAM2EXU_PROGRESS", raising=False)
    now = [100.0]
    stream = Terminal()
    bar = Progress(1000, "variants", stream=stream, rate=True, clock=lambda: now[0])
    bar.update(400)                     # resumed: 400 done before, not counted in the rate
    assert stream.getvalue().endswith("40%  400/1,000 variants")
    now[0] = 104.0
    bar.update(500)                     # 100 in 4 s: 25/s, 500 left: 20 s
    line = stream.getvalue().rpartition("\r")[2]
    assert line.rstrip().endswith("50%  500/1,000 variants  25/s  0:00:20 left")
    now[0] = 4104.0
    bar.update(520)                     # 120 in 4004 s; 480 left: 16,016 s = 4:26:56
    line = stream.getvalue().rpartition("\r")[2]
    assert line.rstrip().endswith("52%  520/1,000 variants  0.03/s  4:26:56 left")
    bar.close()
    assert stream.getvalue().endswith("\r")


def test_nothing_is_written_off_a_terminal():
    stream = io.StringIO()
    with Progress(1000, "variants", stream=stream, rate=True) as bar:
        bar.update(500)
    assert stream.getvalue() == ""
