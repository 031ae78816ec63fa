"""The Python blocks of the README and of docs/*.md run as written (from the repository root)."""
import os
import re
import shlex
import shutil
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


def _commands(page: Path) -> list[tuple[str, int]]:
    """(command, expected exit code) for every line of the page's ```bash blocks.

    Continuation lines are joined; ``# exit N`` in a line's comment expects exit code N.
    """
    out = []
    for block in _blocks(page, "bash"):
        for line in block.replace("\\\n", " ").splitlines():
            if line.strip() and not line.lstrip().startswith("#"):
                code = re.search(r"#\s*exit (\d+)", line)
                out.append((line.strip(), int(code.group(1)) if code else 0))
    return out


def _workspace(tmp_path: Path) -> Path:
    """A working directory that sees the repository's examples, docs and tests (read-only
    use), so that the files a command writes land in ``tmp_path``, never in the repository."""
    for name in ("examples", "docs", "tests", "benchmarks"):
        (tmp_path / name).symlink_to(ROOT / name)
    return tmp_path


SHELL_PAGES = [p for p in PAGES if _commands(p)]


@pytest.mark.parametrize("page", SHELL_PAGES, ids=lambda p: p.name)
def test_shell_blocks_run(page, tmp_path):
    """Every line of every ```bash block runs as written, in order, with the exit code its
    comment states (0 when none). Lines that install (pip) or need ffmpeg when it is missing
    are skipped; `pam2exu` and `python` mean this interpreter's."""
    work = _workspace(tmp_path)
    commands = _commands(page)
    if page.name == "README.md":
        assert sum(c.startswith("pam2exu ") for c, _ in commands) >= 4
    ran = 0
    for command, expected in commands:
        if command.startswith("pip ") or "--quick" not in command and "benchmarks/" in command:
            continue            # installing, and the full benchmark (minutes): not in CI
        if "ffmpeg" in command and shutil.which("ffmpeg") is None:
            continue
        shell = re.sub(r"^(pam2exu|python)\b",
                       lambda m: shlex.quote(sys.executable)
                       + (" -m pam2exu" if m.group(1) == "pam2exu" else ""), command)
        done = subprocess.run(shell, shell=True, cwd=work, capture_output=True, text=True,
                              env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"})
        assert done.returncode == expected, (page.name, command, done.stdout[-2000:],
                                             done.stderr[-2000:])
        ran += 1
    assert ran


TOML_PAGES = [p for p in PAGES if p.name != "README.md"
              and any("[[solid]]" in b for b in _blocks(p, "toml"))]


@pytest.mark.parametrize("page", TOML_PAGES, ids=lambda p: p.name)
def test_docs_model_blocks_are_valid_models(page):
    """A ```toml block of the docs that holds solids is a whole, valid model."""
    import pam2exu
    for block in _blocks(page, "toml"):
        if "[[solid]]" in block:
            pam2exu.loads(block, source=f"{page.name} toml block").mechanism()


def _shipped_blocks():
    """(page, example path, block) for every toml block a page says is a shipped example."""
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for m in re.finditer(r"shipped as\s*\[`(examples/\w+\.toml)`\][^`]*?```toml\n(.*?)```",
                             text, re.S):
            out.append((page.name, m.group(1), m.group(2)))
    return out


@pytest.mark.parametrize("page,example,block", _shipped_blocks(), ids=lambda v: str(v)[:30])
def test_docs_model_blocks_equal_the_shipped_example(page, example, block):
    """A model shown in the docs as a shipped example is that file, key for key."""
    import dataclasses

    import pam2exu
    shown, shipped = pam2exu.loads(block), pam2exu.load(ROOT / example)

    def content(model):
        solids = [dataclasses.asdict(s) for s in model.solids]
        elements = [(type(e).__name__, {k: getattr(e, k) for k in type(e).keys()[1:]})
                    for e in model.elements]
        return model.name, model.gravity, solids, elements, dataclasses.asdict(model.analysis)
    assert content(shown) == content(shipped)


def test_docs_show_the_shipped_examples():
    assert {example for _, example, _ in _shipped_blocks()} >= {
        "examples/scotch_yoke.toml", "examples/pam_crank.toml"}
