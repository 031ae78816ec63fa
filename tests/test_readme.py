"""The README and docs/*.md as a user meets them: every ```python block runs (from the
repository root), every ```bash line runs with the exit code it states (from a scratch
directory), marked output blocks match a fresh run, and the models shown are valid and
equal the shipped files they name. The conventions are in docs/README.md."""
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
def test_docs_python_blocks_run(monkeypatch, page, tmp_path):
    monkeypatch.chdir(_workspace(tmp_path))       # what a block writes lands in tmp_path
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


#: the pages whose commands take longest (idle, 2 cores: performance.md's benchmarks 77 s,
#: pictures.md's animations 63 s, clearance.md's runs 28 s, getting-started.md 25 s,
#: compare.md 17 s, verify.md 13 s): run
#: with --long, so that the test command stays within 8 minutes
LONG_PAGES = ("performance.md", "pictures.md", "clearance.md", "getting-started.md",
              "compare.md", "verify.md", "studies.md")
SHELL_PAGES = [pytest.param(p, marks=pytest.mark.long) if p.name in LONG_PAGES else p
               for p in PAGES if _commands(p)]


@pytest.mark.parametrize("page", SHELL_PAGES,
                         ids=lambda p: getattr(p, "name", None) or p.values[0].name)
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
        done = subprocess.run(_shell(command), shell=True, cwd=work, capture_output=True,
                              text=True, env=_env())
        assert done.returncode == expected, (page.name, command, done.stdout[-2000:],
                                             done.stderr[-2000:])
        ran += 1
    assert ran
    for command, shown in _outputs(page):      # after the page's commands made their files
        done = subprocess.run(_shell(command), shell=True, cwd=work, capture_output=True,
                              text=True, env=_env())
        _assert_shows(done.stdout, shown, f"{page.name}: output of {command}")


def _shell(command: str) -> str:
    """`pam2exu` and `python` at the start of a line mean this interpreter's."""
    return re.sub(r"^(pam2exu|python)\b", lambda m: shlex.quote(sys.executable)
                  + (" -m pam2exu" if m.group(1) == "pam2exu" else ""), command)


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}


def _outputs(page: Path) -> list[tuple[str, str]]:
    """(command, output shown) for every ```text block marked `<!-- output of: COMMAND -->`."""
    return re.findall(r"<!-- output of: (.*?) -->\s*```text\n(.*?)```",
                      page.read_text(encoding="utf-8"), re.S)


def _same_line(got: str, shown: str) -> bool:
    """Equal word by word; numbers to 5 % (the docs print 2 to 6 digits) or 1e-9 (round-off
    zeros such as -3.8e-17 may differ in sign and size between machines)."""
    a, b = got.split(), shown.split()
    if b and b[-1] == "…":                       # a line cut short: its beginning
        b, a = b[:-1], a[:len(b) - 1]
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        try:
            fx, fy = float(x), float(y)
        except ValueError:
            if x != y:
                return False
            continue
        if abs(fx - fy) > 1e-9 + 0.05 * abs(fy):
            return False
    return True


def _assert_shows(output: str, shown: str, what: str) -> None:
    """Every line shown appears in the output, in order; a line holding only `…` (or a
    table row `| …`) stands for lines left out, and a line ending in ` …` for its end."""
    lines = output.splitlines()
    k = 0
    for line in shown.splitlines():
        if line.strip() in ("…", "| …", "") or line.strip().startswith("| …"):
            continue
        while k < len(lines) and not _same_line(lines[k], line):
            k += 1
        assert k < len(lines), f"{what}: the docs show\n  {line}\nbut the output is\n{output}"
        k += 1


def test_output_blocks_are_checked():
    """The convention is in use (docs/README.md, "Runnable blocks")."""
    assert sum(len(_outputs(p)) for p in PAGES) >= 4


def test_output_comparison_can_fail():
    assert _same_line("x  0.1   -3.8e-17", "x 0.1 1e-17")
    assert not _same_line("x 0.1", "x 0.2")
    assert not _same_line("PASS: all", "FAIL: all")
    assert _same_line("FAIL: a, b, c", "FAIL: a, …") and not _same_line("FAIL: b, c", "FAIL: a, …")
    with pytest.raises(AssertionError, match="the docs show"):
        _assert_shows("a 1\nb 2\n", "b 2\n…\na 1", "order")


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


def test_ci_runs_exactly_the_readmes_test_command():
    """`.ci/run` calls the README's test command, word for word (the brief's set-up rule)."""
    readme = [c for c, _ in _commands(ROOT / "README.md") if "pytest" in c]
    ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()
          if "pytest" in line and not line.lstrip().startswith("#")]
    assert readme[:1] == ci and len(ci) == 1, (readme, ci)
