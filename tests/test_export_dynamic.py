"""The exported script of a dynamic model (pam2exu/export_dynamic.py): standalone, and the
positions of ``pam2exu.run(..., analysis="dynamic")`` to its tolerance.

References: the dynamic analysis itself (the script runs the same Exudyn system from the
same initial state, with the analysis's finest step count and half of it, extrapolated as
the analysis extrapolates; the analysis then projects onto the constraints, a correction of
the size of the integration error), and the analysis at a 100 times tighter tolerance, for
the script's own accuracy. Measured (tolerance 1e-8): the free pendulum's script equals the
run to 3e-28, the free four-bar's to 2.0e-11 · (1 + |value|), and the four-bar's script is
within 1.2e-10 (1 + |value|) of the run at tolerance 1e-10.
"""
import warnings

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.law_code import RATE_CODE
from pam2exu.laws import LAWS
from references.pendulum import pendulum_toml, slider_toml
from test_export import POSITIONS, check_imports, max_difference, run_script

PENDULUM = pendulum_toml(0.3, analysis='type = "dynamic"\nt_end = 2.0\nsteps = 50')
#: a second solid hinged to the pendulum's end A
ARM = """
[[solid]]
name = "arm"
x = 0.4776682445628
y = 0.1477601033307
fi = -0.5
mass = 1.0
inertia = 0.01
cog = [0.2, 0.0]

[[element]]
type = "revolute"
name = "elbow"
anc1 = "lever.A"
anc2 = "arm"
"""


def relative_difference(header, data, res) -> float:
    """Largest |script − run| / (1 + |run|) over every x, y, fi column and row."""
    assert header == ["t", *res.columns]
    np.testing.assert_allclose(data[:, 0], res.t, rtol=0, atol=1e-15)
    return max(float(np.max(np.abs(data[:, k + 1] - res[c]) / (1.0 + np.abs(res[c]))))
               for k, c in enumerate(res.columns))


def dynamic(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return pam2exu.run(model, analysis="dynamic", outputs=POSITIONS, **kw)


@pytest.fixture
def four_bar(examples, tmp_path):
    """spring_four_bar.toml let go (its [analysis] dynamic, 0.3 s in 15 steps)."""
    text = (examples / "equilibrium" / "spring_four_bar.toml").read_text()
    path = tmp_path / "free_four_bar.toml"
    path.write_text(text.replace('type = "equilibrium"',
                                 'type = "dynamic"\nt_end = 0.3\nsteps = 15'))
    return path


def test_free_pendulum_script_gives_the_dynamic_positions(tmp_path, capsys):
    model = tmp_path / "pendulum.toml"
    model.write_text(PENDULUM)
    path = tmp_path / "pendulum.py"
    assert main(["export", str(model), "-o", str(path)]) == 0      # the model's type
    assert f"wrote {path}" in capsys.readouterr().out
    text = path.read_text()
    check_imports(text)
    res = dynamic(model)
    steps = res.info["integration_steps"]
    assert f"    (0.0, 2.0, range(1, 51), {steps}, False),\n" in text    # one piece
    assert "SolveDynamic(" in text and "def velocities_after" not in text
    assert "initialVelocities=[0.0, 0.0, 0.0]" in text
    header, data = run_script(path)
    assert len(data) == 51
    assert relative_difference(header, data, res) <= 1e-8          # measured 3e-28
    assert np.ptp(data[:, header.index("lever.fi")]) > 0.5          # it swings


def test_free_four_bar_script_gives_the_dynamic_positions_to_the_tolerance(four_bar, tmp_path):
    path = pam2exu.export(four_bar, tmp_path / "four_bar.py")
    text = path.read_text()
    check_imports(text)
    lines = text.splitlines()
    model = pam2exu.load(four_bar)
    for solid in model.solids:
        assert f"# --- solid '{solid.name}'" in lines
    for el in model.elements:
        assert any(line.startswith(f"# --- {el.name}: {el.type}") for line in lines)
    assert "ObjectConnectorSpringDamper(" in text and "LoadMassProportional(" in text
    header, data = run_script(path)
    res = dynamic(four_bar)
    assert len(data) == len(res) == 16
    assert relative_difference(header, data, res) <= 1e-8          # measured 2.0e-11
    finer = dynamic(four_bar, tolerance=1e-10)
    assert relative_difference(header, data, finer) <= 1e-8        # measured 1.2e-10
    assert np.ptp(res["crank.fi"]) > 0.1


def test_analysis_option_picks_the_dynamic_script(examples, tmp_path):
    """--analysis dynamic on a model whose [analysis] is equilibrium, with --tolerance."""
    model = examples / "equilibrium" / "spring_four_bar.toml"
    path = tmp_path / "fb.py"
    assert main(["export", str(model), "-o", str(path), "-a", "dynamic", "--t-end", "0.1",
                 "--steps", "5", "--tolerance", "1e-6"]) == 0
    text = path.read_text()
    assert "tolerance 1e-06" in text and "t_end = 0.1\n" in text
    header, data = run_script(path)
    res = dynamic(model, t_end=0.1, steps=5, tolerance=1e-6)
    assert relative_difference(header, data, res) <= 1e-6


def test_driven_actuators_follow_their_laws_in_the_script(tmp_path):
    """A pendulum on a slider driven by a linear actuator (a distance: pre-step function)
    and a lever turned by an angular actuator (an offset: user function of t)."""
    model = pam2exu.loads(PENDULUM[:PENDULUM.index("[analysis]")] + ARM + """
[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "lever"
law = "harmonic"
C = [0.3, 0.2, 5.0, 0.0]

[analysis]
type = "dynamic"
t_end = 0.5
steps = 10
""")
    path = pam2exu.export(model, tmp_path / "double.py")
    text = path.read_text()
    assert "def offset_motor(mbs, t, itemNumber, lOffset):" in text
    header, data = run_script(path)
    assert relative_difference(header, data, dynamic(model)) <= 1e-8


@pytest.mark.parametrize("C, measured", [((0.2, 0.7, 0.5, 0.9), 1.5e-14),
                                         ((0.215, 0.705, 0.5, 0.9), 8.8e-12)],
                         ids=["breakpoints on rows", "breakpoints between rows"])
def test_a_ramp_while_a_dof_is_free_jumps_in_the_script_as_in_the_analysis(C, measured,
                                                                           tmp_path):
    """The pendulum on a slider driven by a ramp: its velocities jump at C1 and C2 (the
    plastic impulse of the contract, M and C_q from Exudyn); the script integrates the
    analysis's pieces between them with the analysis's step counts."""
    model = pam2exu.loads(slider_toml("ramp", C))
    path = pam2exu.export(model, tmp_path / "slider.py")
    text = path.read_text()
    check_imports(text)
    for call in ("ComputeMassMatrix(mbs)", "ComputeJacobianAE(mbs", "def velocities_after",
                 "def ramp_rate(t, C1, C2, C3, C4):", "lambda t: ramp_rate(t, "):
        assert call in text
    assert text.count(", True),\n") == 2                        # two breakpoints
    header, data = run_script(path)
    res = dynamic(model)
    assert len(data) == len(res) == 51
    difference = relative_difference(header, data, res)
    assert difference <= 1e-8, difference                       # measured: see the ids
    assert difference <= 100 * measured
    fi = data[:, header.index("lever.fi")]
    assert np.ptp(np.diff(fi)) > 0.01                           # it is jerked about
    # the interval ending at the first breakpoint: no jump inside, one piece
    path = pam2exu.export(model, tmp_path / "before.py", t_end=C[0], steps=10)
    assert "def velocities_after" not in path.read_text()
    header, data = run_script(path)
    assert relative_difference(header, data, dynamic(model, t_end=C[0], steps=10)) <= 1e-8


def test_an_angular_ramp_jumps_in_the_script_as_in_the_analysis(tmp_path):
    """An angular actuator (an offset by a user function of t, no pre-step function) with a
    ramp whose breakpoints fall between rows, driving a lever with a free arm."""
    model = pam2exu.loads(PENDULUM[:PENDULUM.index("[analysis]")] + ARM + """
[[element]]
type = "angular_actuator"
name = "motor"
anc1 = "ground"
anc2 = "lever"
law = "ramp"
C = [0.13, 0.33, 0.3, -0.2]

[analysis]
type = "dynamic"
t_end = 0.5
steps = 10
""")
    path = pam2exu.export(model, tmp_path / "motor.py")
    text = path.read_text()
    assert "(o_motor, lambda t: ramp_rate(t, 0.13, 0.33, 0.3, -0.2))," in text
    assert "PreStepUserFunction" not in text
    header, data = run_script(path)
    assert relative_difference(header, data, dynamic(model)) <= 1e-8   # measured 2.9e-13


@pytest.mark.parametrize("name", list(RATE_CODE))
def test_rate_code_is_the_laws_derivative_with_right_hand_limits(name):
    namespace = {"np": np}
    exec(RATE_CODE[name], namespace)
    rate = namespace[f"{name}_rate"]
    C = (0.2, 0.7, 0.5, 0.9)
    for t in (0.0, 0.1, 0.2, 0.3, 0.45, 0.7, 0.9):
        expected = float(LAWS[name][0](np.float64(t), C)[1])
        assert rate(t, *C) == pytest.approx(expected, rel=1e-15, abs=1e-15)


def test_a_fully_driven_dynamic_model_gets_the_positions_script(examples, tmp_path):
    """Its dynamic results are the kinetostatic ones, whose positions are kinematic."""
    model = examples / "four_bar.toml"
    path = pam2exu.export(model, tmp_path / "fb.py", analysis="dynamic", steps=20)
    assert "SolveStatic(" in path.read_text()
    header, data = run_script(path)
    res = pam2exu.run(model, analysis="dynamic", steps=20, outputs=POSITIONS)
    assert max_difference(header, data, res) <= 1e-10


def test_an_unknown_analysis_is_a_model_error(examples, tmp_path, capsys):
    assert main(["export", str(examples / "four_bar.toml"), "-o", str(tmp_path / "x.py"),
                 "-a", "dynamics"]) == 2
    assert "unknown analysis 'dynamics'" in capsys.readouterr().err
