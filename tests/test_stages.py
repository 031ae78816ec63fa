"""benchmarks/stages.py: a study variant's instructions by part. The counted process runs
here without valgrind (callgrind's client requests do nothing then): every part it wraps
must still be a function the study's run calls."""
import os
from collections import Counter
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks import instructions, stages

ROOT = Path(__file__).resolve().parents[1]

DUMP = "version: 1\ndesc: Trigger: Client Request: {name}\nevents: Ir\nsummary: {count}\n"


@pytest.mark.skipif(shutil.which("valgrind") is None or shutil.which("cc") is None,
                    reason="the client requests' library needs valgrind's headers and cc")
def test_every_part_is_entered_in_a_studys_chunk(tmp_path):
    """A renamed or moved function, or one a module imports under another name, would
    leave its part empty and its instructions counted under its caller's."""
    library = instructions.client_library(tmp_path)
    done = subprocess.run([sys.executable, "-c", stages.CHILD, str(library), "2"], cwd=ROOT,
                          capture_output=True, text=True, timeout=600,
                          env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"


def test_the_dumps_of_one_part_add_up(tmp_path):
    out = tmp_path / "callgrind.stages"
    for k, (name, count) in enumerate([("the one pass", 600), ("other", 40),
                                       ("the one pass", 400), ("the table", 160)]):
        (tmp_path / f"callgrind.stages.{k + 1}").write_text(DUMP.format(name=name, count=count))
    parts = Counter(instructions.totals(out))
    assert parts == {"the one pass": 1000, "other": 40, "the table": 160}
    lines = stages.table(parts, 2)
    assert lines[0] == "0.00 M instructions a variant (2 variants)"
    assert lines[3] == "| the one pass | 0.00 | 83 % |"
    assert lines[5] == "| other | 0.00 | 3 % |"
