"""The exported Exudyn script: standalone, and the same positions as pam2exu.

Reference: ``pam2exu.run(model, analysis="kinematic")``, whose positions come from the
translation's own Exudyn system (the script is written from that very construction, so the
two must agree to the Newton tolerance, 1e-13 × the length scale; checked to 1e-10 m/rad).
The laws written into the script are checked against ``pam2exu.laws`` on their own.
"""
import ast
import csv
import subprocess
import sys

import numpy as np
import pytest

import pam2exu
from pam2exu.analyses import RedundancyWarning
from pam2exu.cli import main
from pam2exu.elements import ELEMENTS
from pam2exu.export import LAW_CODE, script
from pam2exu.laws import LAWS, Law

POSITIONS = ["*.x", "*.y", "*.fi"]


def run_script(path, *args) -> tuple[list[str], np.ndarray]:
    """Run an exported script as a user would (python script.py, in its folder); returns
    the CSV's header and rows."""
    done = subprocess.run([sys.executable, path.name, *args], cwd=path.parent,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    out = path.parent / (args[0] if args else path.with_suffix(".csv").name)
    rows = list(csv.reader(open(out, encoding="utf-8")))
    return rows[0], np.array(rows[1:], dtype=float)


def max_difference(header, data, res) -> float:
    """Largest |script − pam2exu| over every x, y, fi column and row (same times first)."""
    assert header == ["t", *res.columns]
    np.testing.assert_array_equal(data[:, 0], res.t)
    return max(float(np.max(np.abs(data[:, k + 1] - res[c]))) for k, c in enumerate(res.columns))



def test_example_has_every_element_type_and_law(examples):
    model = pam2exu.load(examples / "all_elements.toml")
    assert {e.type for e in model.elements} == {k for k, c in ELEMENTS.items() if not c.extension}
    assert {Law(e.law).name for e in model.elements if e.drives} == set(LAWS)


@pytest.mark.parametrize("forces", [False, True], ids=["constraints", "forces"])
def test_script_gives_pam2exus_positions(examples, tmp_path, forces):
    model = examples / "all_elements.toml"
    path = pam2exu.export(model, tmp_path / "all_elements.py", forces=forces)
    header, data = run_script(path)
    res = pam2exu.run(model, analysis="kinematic", outputs=POSITIONS)
    assert len(data) == len(res) == 201
    assert max_difference(header, data, res) <= 1e-10


def test_script_of_a_moved_ground(examples, tmp_path, moved):
    """A fixed solid at a rotated pose: ObjectGround with a rotation, actuator offsets shifted
    by the ground's angle."""
    model = moved(examples / "all_elements.toml")
    path = pam2exu.export(model, tmp_path / "moved.py", steps=50)
    text = path.read_text()
    assert "ObjectGround(" in text and " + 0.7)" in text       # the shift of fi_ground
    header, data = run_script(path, "positions.csv")
    res = pam2exu.run(model, analysis="kinematic", steps=50, outputs=POSITIONS)
    assert max_difference(header, data, res) <= 1e-10


def test_script_of_a_redundant_mechanism(data, tmp_path):
    path = pam2exu.export(data / "parallelogram5.toml", tmp_path / "p5.py", steps=40)
    assert "ignoreSingularJacobian = True" in path.read_text()
    header, rows = run_script(path)
    with pytest.warns(RedundancyWarning):
        res = pam2exu.run(data / "parallelogram5.toml", analysis="kinematic", steps=40,
                          outputs=POSITIONS)
    assert max_difference(header, rows, res) <= 1e-10


def check_imports(source: str) -> None:
    """The script imports exudyn, numpy and the standard library only, and its code (its
    docstring and comments aside) never names pam2exu."""
    tree = ast.parse(source)
    modules = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0
            modules.add(node.module.split(".")[0])
    assert {"exudyn", "numpy"} <= modules
    assert modules - {"exudyn", "numpy"} <= set(sys.stdlib_module_names)
    docstring = tree.body.pop(0)
    assert "exported by pam2exu" in docstring.value.value
    assert "pam2exu" not in ast.unparse(tree)          # the code, without comments
    assert "pickle" not in modules


def test_script_imports_only_exudyn_numpy_and_the_standard_library(examples):
    check_imports(script(examples / "all_elements.toml", forces=True))


@pytest.mark.parametrize("forces", [False, True], ids=["constraints", "forces"])
def test_one_commented_block_per_solid_and_element(examples, forces):
    model = pam2exu.load(examples / "all_elements.toml")
    text = script(model, forces=forces)
    lines = text.splitlines()
    for solid in model.solids:
        assert f"# --- solid '{solid.name}'" in lines
    for el in model.elements:
        head = next(k for k, line in enumerate(lines)
                    if line.startswith(f"# --- {el.name}: {el.type} (PAM {el.alias})"))
        block = "\n".join(lines[head:lines.index("", head)])
        assert f"anc1 = {el.anc1!r}" in block
        if forces or el.equations and not el.grounds:
            assert "= mbs.Add" in block, block         # its Exudyn items follow
        else:
            assert "= mbs.Add" not in block, block     # a note says why there are none
    # the actuators are driven by name in the pre-step function
    for el in model.elements:
        if el.drives:
            assert f"mbs.SetObjectParameter(o_{el.name}, " in text


@pytest.mark.parametrize("name", list(LAWS))
def test_law_code_equals_the_laws(name):
    """Each law as written into the script (``LawForm.code``, the same operations) against
    pam2exu.laws, bit for bit, before, inside and after the transition (breakpoints
    included: the right-hand value)."""
    namespace = {"np": np}
    exec(LAW_CODE[name], namespace)
    f = namespace[name]
    C = (0.2, 0.7, -0.3, 1.1)
    law = Law(name, C)
    for t in [*np.linspace(-0.5, 1.5, 81), 0.2, 0.7]:
        assert f(float(t), *C) == law.value(t), t


def test_every_law_has_code():
    assert set(LAW_CODE) == set(LAWS)


def test_cli_export_with_steps_and_t_end(examples, tmp_path, capsys):
    model = examples / "slider_crank.toml"
    path = tmp_path / "sc.py"
    assert main(["export", str(model), "-o", str(path), "--steps", "20", "--t-end", "0.5"]) == 0
    assert f"wrote {path}" in capsys.readouterr().out
    text = path.read_text()
    assert "t_end = 0.5\n" in text and "steps = 20\n" in text
    header, data = run_script(path)
    res = pam2exu.run(model, analysis="kinematic", steps=20, t_end=0.5, outputs=POSITIONS)
    assert len(data) == 21
    assert max_difference(header, data, res) <= 1e-10


def test_cli_export_forces_flag(examples, tmp_path):
    path = tmp_path / "sc_forces.py"
    assert main(["export", str(examples / "slider_crank.toml"), "-o", str(path),
                 "--forces"]) == 0
    text = path.read_text()
    assert "LoadMassProportional(" in text and "mass=2.0" in text


def test_cli_export_of_an_undriven_model_is_a_model_error(examples, tmp_path, capsys):
    src = (examples / "slider_crank.toml").read_text()
    undriven = src[:src.index('type = "angular_actuator"')].rstrip().removesuffix("[[element]]")
    model = tmp_path / "undriven.toml"
    model.write_text(undriven)
    assert main(["export", str(model), "-o", str(tmp_path / "x.py")]) == 2
    assert "model error" in capsys.readouterr().err
    assert not (tmp_path / "x.py").exists()
