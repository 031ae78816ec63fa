"""The energy account (pam2exu.energy, run --energy; pam2exu/analyses/energy.py).

References computed here from the result columns alone: the kinetic energy
Σ ½ m |v_G|² + ½ I_G ω² and the potential energy of gravity of a pendulum; the work of a
constant torsor M (fi − fi0) and the energy a torsional damper dissipated, which close the
balance of a damped, driven pendulum (dynamic) to the integration tolerance; the slider-crank
(kinetostatic) whose motor's work equals the rise of T + V.
"""
import numpy as np
import pytest

import pam2exu
from pam2exu.analyses.energy import account
from pam2exu.cli import main
from references.pendulum import D, G, IG, M, pendulum_toml

ROOT = pam2exu.__file__.replace("pam2exu/__init__.py", "")
K4, TORQUE = 0.05, 1.5
PENDULUM = pendulum_toml(-1.0, elements=f"""
[[element]]
type = "torsional_spring"
name = "damper"
anc1 = "ground"
anc2 = "lever"
C = [0.0, 0.0, 0.0, {K4}]

[[element]]
type = "torsor"
name = "torque"
anc1 = "lever"
C = [0.0, 0.0, {TORQUE}]
""", analysis='type = "dynamic"\nt_end = 2.0\nsteps = 200')


def test_a_damped_pendulum_driven_by_a_torque():
    """T, V against the columns; the torsor's work M (fi − fi0); the damper's dissipation
    ∫ C4 ω² dt (Simpson on the rows, against the trapezoid: measured 4.5e-6 J of 0.077); the
    balance zero to the quadrature's error (measured 1.5e-7 J, nearly all of it the Simpson
    sum of the torsor's power against M Δfi, 1.4e-7)."""
    res = pam2exu.run(pam2exu.loads(PENDULUM), tolerance=1e-9)
    acc = account(pam2exu.loads(PENDULUM), res)
    fi, w = res["lever.fi"], res["lever.Dfi"]
    IO = IG + M * D * D                   # references.pendulum's pendulum
    np.testing.assert_allclose(acc["energy.kinetic"], 0.5 * IO * w ** 2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(acc["energy.potential"], M * G * D * np.sin(fi), atol=1e-12)
    np.testing.assert_allclose(acc["energy.torsors"], TORQUE * (fi - fi[0]), atol=1e-6)
    dissipated = np.r_[0.0, np.cumsum(0.5 * K4 * (w[1:] ** 2 + w[:-1] ** 2) * np.diff(res.t))]
    np.testing.assert_allclose(acc["energy.dissipated"], dissipated, atol=2e-5)
    assert np.all(np.diff(acc["energy.dissipated"]) > 0)
    assert np.max(np.abs(acc["energy.actuators"])) == 0.0
    assert np.max(np.abs(acc["energy.balance"])) < 1e-6
    assert acc.units["energy.kinetic"] == "J"


def test_the_motor_of_a_slider_crank_pays_for_its_energy():
    """kinetostatic: W_motor = Δ(T + V) row by row (no torsor, no damper), to the
    quadrature's error O(dt⁴) (measured 7.5e-7 J at 200 steps, /16 at 400)."""
    path = ROOT + "examples/slider_crank.toml"
    errors = []
    for steps in (200, 400):
        acc = pam2exu.energy(path, steps=steps)
        total = acc["energy.kinetic"] + acc["energy.potential"]
        np.testing.assert_allclose(acc["energy.actuators"], total - total[0], atol=1e-5)
        errors.append(np.max(np.abs(acc["energy.balance"])))
    assert errors[1] < errors[0] / 8


def test_only_runs_with_rates_and_forces_have_an_account():
    with pytest.raises(pam2exu.ModelError, match="kinetostatic or dynamic run, not 'kinematic'"):
        pam2exu.energy(ROOT + "examples/four_bar.toml", analysis="kinematic")
    res = pam2exu.run(ROOT + "examples/four_bar.toml", analysis="kinetostatic",
                      outputs=["crank.*"], steps=10)
    with pytest.raises(pam2exu.ModelError, match="run without --outputs"):
        account(ROOT + "examples/four_bar.toml", res)


def test_a_model_in_degrees_has_the_same_account():
    path = ROOT + "examples/slider_crank.toml"
    rad = pam2exu.energy(path, steps=50)
    deg = account(path, pam2exu.run(path, steps=50, angles="deg"))
    for c in rad.columns:
        np.testing.assert_allclose(deg[c], rad[c], rtol=1e-12, atol=1e-12)


def test_run_energy_writes_the_plot(tmp_path, capsys):
    out = tmp_path / "energy.png"
    assert main(["run", ROOT + "examples/slider_crank.toml", "--steps", "50",
                 "--energy", str(out)]) == 0
    assert out.stat().st_size > 1000
    assert "energy: largest |balance|" in capsys.readouterr().out
