"""The command line: exit codes, one-paragraph errors on stderr, CSV output."""
import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pam2exu.cli import main


def test_run_writes_csv(examples, tmp_path, capsys):
    out = tmp_path / "sc.csv"
    code = main(["run", str(examples / "slider_crank.toml"), "--analysis", "kinematic",
                 "--steps", "50", "--t-end", "0.1", "--outputs", "crank.*", "-o", str(out)])
    assert code == 0
    assert "wrote 51 rows" in capsys.readouterr().out
    rows = list(csv.reader(open(out, encoding="utf-8")))
    assert rows[0][:3] == ["t", "crank.x", "crank.y"]
    data = np.array(rows[1:], dtype=float)
    np.testing.assert_allclose(data[:, rows[0].index("crank.fi")], 10.0 * data[:, 0], atol=1e-14)


def test_run_prints_summary(examples, capsys):
    assert main(["run", str(examples / "slider_crank.toml"), "-a", "kinematic",
                 "--steps", "10"]) == 0
    out = capsys.readouterr().out
    assert "kinematic analysis of 'slider-crank': 11 rows" in out
    assert "slider.DDx" in out


def test_model_error_exit_2_names_file_and_element(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[[solid]]\nname = "a"\n[[element]]\ntype = "revolut"\nname = "j"\n')
    assert main(["run", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pam2exu: model error: {bad}: [[element]] #1 'j'")
    assert "did you mean 'revolute'" in err
    assert "Traceback" not in err


def test_solver_failure_exit_1(tmp_path, capsys):
    """A rod (0.05) shorter than the crank (0.1): the loop cannot close once the crank turns."""
    src = (Path(__file__).resolve().parents[1] / "examples" / "slider_crank.toml").read_text().replace("B = [0.3, 0.0] }", "B = [0.05, 0.0] }")
    path = tmp_path / "short_rod.toml"
    path.write_text(src)
    assert main(["run", str(path), "-a", "kinematic", "--steps", "50"]) == 1
    err = capsys.readouterr().err
    # the crank drives it to the limit where rod and crank are collinear: a dead point
    assert "solver failure" in err and "singular (dead-point) position" in err
    assert "'motor'" in err and "between t =" in err
    assert "Traceback" not in err


def test_check_prints_mobility(examples, capsys):
    assert main(["check", str(examples / "slider_crank.toml")]) == 0
    out = capsys.readouterr().out
    assert "degrees of freedom not driven: 0" in out
    assert "redundant constraint equations: 0" in out
    assert "guide  prismatic" in out


def test_check_names_free_solids(tmp_path, examples, capsys):
    src = (examples / "slider_crank.toml").read_text()
    src = src[:src.index('[[element]]\ntype = "angular_actuator"')]
    path = tmp_path / "free.toml"
    path.write_text(src)
    assert main(["check", str(path), "-a", "assembly"]) == 0
    assert "degrees of freedom not driven: 1 (solids free to move: crank, rod, slider)" \
        in capsys.readouterr().out


def test_check_fails_like_run_when_the_analysis_needs_every_dof_driven(tmp_path, examples,
                                                                      capsys):
    """Issue 10, fault 6: check passed a model that run refuses (exit 0 before)."""
    src = (examples / "slider_crank.toml").read_text()
    path = tmp_path / "free.toml"
    path.write_text(src[:src.index('[[element]]\ntype = "angular_actuator"')])
    assert main(["run", str(path)]) == 2
    run_message = capsys.readouterr().err
    assert main(["check", str(path)]) == 2              # the model's kinetostatic analysis
    out, err = capsys.readouterr()
    assert "degrees of freedom not driven: 1" in out
    assert err == run_message and "free degree(s) of freedom" in err


def test_console_script_and_debug_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("not toml [")
    r = subprocess.run([sys.executable, "-m", "pam2exu", "run", str(bad)], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "not valid TOML" in r.stderr and "Traceback" not in r.stderr
    r = subprocess.run([sys.executable, "-m", "pam2exu", "--debug", "run", str(bad)],
                       capture_output=True, text=True)
    assert "Traceback" in r.stderr


@pytest.mark.parametrize("argv", [["run"], ["frobnicate"]])
def test_bad_command_line_exit_2(argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2


def test_exudyn_console_quiet_unless_verbose(examples, capfd):
    assert main(["run", str(examples / "four_bar.toml"), "--steps", "3"]) == 0
    quiet = capfd.readouterr().out
    assert main(["run", str(examples / "four_bar.toml"), "--steps", "3", "--verbose"]) == 0
    loud = capfd.readouterr().out
    assert quiet.startswith("kinematic analysis")
    assert len(loud) > len(quiet) and "STATIC" in loud.upper()


def test_energy_with_outputs_runs_once_and_writes_both(examples, tmp_path, capsys):
    """Issue 22: ``--energy PNG --outputs X`` ran the whole analysis, then failed (exit 2,
    "the result has no ground.x …: run without --outputs"). The account is computed from
    every default column; --outputs selects what is written: the same largest |balance| as
    without --outputs, and a CSV of t and crank.fi only."""
    model = str(examples / "slider_crank.toml")
    base = ["run", model, "-a", "kinetostatic", "--steps", "50"]
    assert main([*base, "--energy", str(tmp_path / "all.png")]) == 0
    whole = capsys.readouterr().out
    out = tmp_path / "sel.csv"
    assert main([*base, "--energy", str(tmp_path / "sel.png"), "--outputs", "crank.fi",
                 "-o", str(out)]) == 0
    chosen = capsys.readouterr().out
    line = next(s for s in whole.splitlines() if s.startswith("energy: largest |balance|"))
    assert line in chosen
    assert (tmp_path / "sel.png").stat().st_size > 1000
    assert next(csv.reader(open(out, encoding="utf-8"))) == ["t", "crank.fi"]


@pytest.mark.parametrize("options, says", [
    (["-a", "kinematic", "--energy", "e.png"], "a kinetostatic or dynamic run, not 'kinematic'"),
    (["-a", "assembly", "--energy", "e.png", "-o", "r.csv"], "not 'assembly'"),
    (["-a", "kinetostatic", "--energy", "e.xyz"], "--energy: cannot write 'e.xyz'"),
    (["--plot", "crank.fi", "--plot-file", "p.xyz"], "--plot-file: cannot write 'p.xyz'"),
    (["--plot-file", "p.png"], "--plot-file is for --plot"),
    (["--x", "crank.fi"], "--x is for --plot"),
    (["--sep", ";", "--decimal", ","], "--sep and --decimal are for the CSV file of -o"),
    (["--bom"], "--bom is for the CSV file of -o"),
    (["-a", "kinematic", "--tolerance", "1e-6", "-o", "r.csv"],
     "the kinematic analysis does not use it: drop --tolerance"),
])
def test_option_conflicts_exit_2_before_the_run(examples, tmp_path, monkeypatch, capsys,
                                                options, says):
    """Issue 22: options that do not go together (or one that needs another, or a file the
    run could not write at its end) exit 2 before anything runs or is written; before,
    --energy and --plot-file were refused after the whole run (the CSV of -o written) and
    --x, --plot-file, --sep, --bom and --tolerance were silently ignored (exit 0)."""
    import pam2exu.analyses

    def no_run(*args, **kwargs):
        raise AssertionError("the analysis ran")
    monkeypatch.setattr(pam2exu.analyses, "run", no_run)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(examples / "slider_crank.toml"), "--steps", "20", *options]) == 2
    err = capsys.readouterr().err
    assert says in err and err.count("\n") == 1, err
    assert not list(tmp_path.iterdir())


def _unused_variation(examples, tmp_path) -> Path:
    """The example four-bar with a [[variation]] of its coupler point P, which no joint
    uses: a VariationWarning when the model is read."""
    path = tmp_path / "unused_variation.toml"
    path.write_text((examples / "four_bar.toml").read_text(encoding="utf-8")
                    + '\n[[variation]]\nanchor = "coupler.P"\ndx = 1e-3\nw = 1.0\n',
                    encoding="utf-8")
    return path


def test_warnings_are_one_clean_line_on_stderr(examples, tmp_path):
    """Issue 22: a warning printed through ``warnings.showwarning`` showed its source line
    (``sys.exit(main())`` under the console script, '<frozen runpy>:88: VariationWarning:'
    under python -m). The command prints it as the one line 'pam2exu: warning: …'."""
    path = _unused_variation(examples, tmp_path)
    r = subprocess.run([sys.executable, "-m", "pam2exu", "run", str(path), "--steps", "3"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stderr.splitlines() == [
        f"pam2exu: warning: {path}: [[variation]] #1 (anchor 'coupler.P'): no constraint "
        "element anchors the point 'coupler.P': the variation has no effect"]


@pytest.mark.parametrize("command", [
    ["run", "-a", "clearance", "--steps", "3"], ["run", "--steps", "3"],
    ["run", "--steps", "3", "--at", "0.1"], ["check"], ["verify", "--steps", "3"],
    ["draw", "--t", "0.3", "-o", "fig.png"]])
def test_a_warning_is_printed_once(examples, tmp_path, monkeypatch, capsys, command):
    """Issue 22: the unused-variation warning was printed twice by ``run -a clearance``
    (when the model was read, and again from the result's warnings, which carry it without
    the file's name). Every command says it once, on stderr, and nothing on stdout."""
    path = _unused_variation(examples, tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main([command[0], str(path), *command[1:]]) == 0
    out, err = capsys.readouterr()
    said = [line for line in err.splitlines() if "the variation has no effect" in line]
    assert len(said) == 1 and said[0].startswith("pam2exu: warning: "), err
    assert "warning:" not in out


def test_any_warning_of_the_package_is_printed_cleanly(examples, monkeypatch, capsys):
    """Warnings that ``pam2exu.run`` issues (RedundancyWarning on the parallelogram with a
    fifth bar, and any other class the package adds, here a made-up one issued twice and
    kept in the result as well) reach stderr as one line each, once, and the summary on
    stdout does not repeat them. Before: issued warnings were silenced during the run and
    the result's were printed in the summary."""
    import warnings

    import pam2exu.analyses
    from pam2exu.errors import warn_outside

    class NewWarning(UserWarning):
        pass
    real = pam2exu.analyses.run

    def run(*args, **kwargs):
        res = real(*args, **kwargs)
        for _ in range(2):
            warn_outside("a new\nwarning of the package", NewWarning)
        warnings.warn("a plain warnings.warn", UserWarning)
        res.warnings.append("a new warning of the package")
        return res
    monkeypatch.setattr(pam2exu.analyses, "run", run)
    data = Path(__file__).resolve().parent / "data"
    assert main(["run", str(data / "parallelogram5.toml"), "--steps", "4"]) == 0
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert "pam2exu: warning: a new warning of the package" in lines
    assert "pam2exu: warning: a plain warnings.warn" in lines
    assert len([s for s in lines if "redundant constraint equation" in s]) == 1
    assert len(lines) == 3 and all(s.startswith("pam2exu: warning: ") for s in lines), err
    assert "warning:" not in out and out.startswith("kinematic analysis")
