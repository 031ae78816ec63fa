"""The README's Python blocks run as written (from the repository root)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_readme_python_blocks_run(monkeypatch, tmp_path):
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)
    assert blocks
    monkeypatch.chdir(ROOT)
    for k, block in enumerate(blocks):
        code = block.replace('"out.csv"', repr(str(tmp_path / "out.csv")))
        namespace: dict = {}
        exec(compile(code, f"README.md python block {k + 1}", "exec"), namespace)
        assert (tmp_path / "out.csv").exists()
