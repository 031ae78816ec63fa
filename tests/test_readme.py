"""The Python blocks of the README and of docs/*.md run as written (from the repository root)."""
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _blocks(page: Path, language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", page.read_text(encoding="utf-8"), re.S)


def test_readme_python_blocks_run(monkeypatch, tmp_path):
    blocks = _blocks(ROOT / "README.md", "python")
    assert blocks
    monkeypatch.chdir(ROOT)
    for k, block in enumerate(blocks):
        code = block.replace('"out.csv"', repr(str(tmp_path / "out.csv")))
        namespace: dict = {}
        exec(compile(code, f"README.md python block {k + 1}", "exec"), namespace)
        assert (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("page", [p for p in PAGES if p.name != "README.md"
                                  and _blocks(p, "python")], ids=lambda p: p.name)
def test_docs_python_blocks_run(monkeypatch, page):
    monkeypatch.chdir(ROOT)
    for k, block in enumerate(_blocks(page, "python")):
        exec(compile(block, f"{page.name} python block {k + 1}", "exec"), {})


def test_readme_cli_examples_run(tmp_path):
    """Every `pam2exu ...` line of the README's shell block runs and exits 0."""
    text = "\n".join(_blocks(ROOT / "README.md", "bash"))
    text = text.replace("\\\n", " ")
    commands = [shlex.split(line, comments=True) for line in text.splitlines()
                if line.strip().startswith("pam2exu ")]
    assert len(commands) >= 4
    for cmd in commands:
        cmd = [str(tmp_path / a) if a.endswith(".csv") else a for a in cmd]
        done = subprocess.run([sys.executable, "-m", "pam2exu", *cmd[1:]], cwd=ROOT,
                              capture_output=True, text=True)
        assert done.returncode == 0, (cmd, done.stderr)
