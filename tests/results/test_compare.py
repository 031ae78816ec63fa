"""``pam2exu compare``: errors and where they occur against known differences, the pass rule,
interpolation between different time grids against textbook bounds, times matched to the
digits a file carries, angles modulo 2π, PAM-style names, input errors, CLI exit codes, and
the acceptance cases on the shipped examples."""
import csv
import io
import math
import subprocess
import sys
import unicodedata
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.cli import main
from pam2exu.results import CompareInputError, Results, compare, read_names
from pam2exu.results.compare import abs_error, angle_error, times_match
from pam2exu.results.names import canonical_name
from pam2exu.results.reading import written_precision

ROOT = Path(__file__).resolve().parents[2]
W = 2 * np.pi                               # rad/s: one period per second


def write(path, t, columns: dict, sep=",", decimal=".", fmt="%.17g", encoding="utf-8",
          newline="\n", t_fmt=None):
    """A CSV written independently of Results.to_csv (PAM-style options; ``t_fmt`` for the
    time column, else ``fmt``)."""
    lines = [sep.join(["t", *columns])]
    for k in range(len(t)):
        cells = [(t_fmt or fmt) % t[k]] + [fmt % c[k] for c in columns.values()]
        lines.append(sep.join(c.replace(".", decimal) for c in cells))
    Path(path).write_bytes((newline.join(lines) + newline).encode(encoding))
    return path


# --- errors, where, and the rule -----------------------------------------------------------

def test_known_difference_max_error_where_and_rule(tmp_path):
    """sin vs sin + 1e-6 at t = 0.37 only; cos vs cos + 1e-6 t (largest at t = 1); zero vs
    round-off (passes by atol) and zero vs 1e-11 (fails)."""
    t = np.linspace(0.0, 1.0, 101)
    bump = np.where(np.isclose(t, 0.37), 1e-6, 0.0)
    res = write(tmp_path / "res.csv", t, {"a.x": np.sin(W * t), "a.y": np.cos(W * t),
                                          "a.z": 1e-13 + 0 * t, "a.w": 1e-11 + 0 * t})
    ref = write(tmp_path / "ref.csv", t, {"a.x": np.sin(W * t) + bump,
                                          "a.y": np.cos(W * t) + 1e-6 * t,
                                          "a.z": 0 * t, "a.w": 0 * t})
    c = compare(res, ref)
    assert c.method is None and c.rows_compared == 101 and c.rows_outside == 0
    x = c["a.x"]
    assert x.max_abs_error == pytest.approx(1e-6, rel=1e-9)
    assert x.t_at_max == pytest.approx(0.37, abs=1e-15)
    assert x.scale == pytest.approx(np.max(np.abs(np.sin(W * t) + bump)), rel=1e-15)
    assert x.max_rel_error == pytest.approx(1e-6 / x.scale, rel=1e-9)
    assert x.tolerance == pytest.approx(1e-12 + 1e-9 * x.scale, rel=1e-15)
    y = c["a.y"]
    assert y.max_abs_error == pytest.approx(1e-6, rel=1e-9) and y.t_at_max == 1.0
    assert y.scale == pytest.approx(1.0 + 1e-6, rel=1e-12)           # |cos(2π) + 1e-6|
    z, w = c["a.z"], c["a.w"]
    assert z.scale == 0 and np.isnan(z.max_rel_error) and z.passed    # 1e-13 ≤ atol
    assert w.max_abs_error == pytest.approx(1e-11) and not w.passed
    assert c.failed == ["a.x", "a.y", "a.w"] and not c.passed
    # the rule is max error ≤ atol + rtol·scale: just above and just below 1e-6 / scale
    assert compare(res, ref, rtol=1.001e-6, atol=1e-10, columns=["a.x"]).passed
    assert not compare(res, ref, rtol=0.999e-6, atol=0.0, columns=["a.x"]).passed


def test_identical_tables_pass_at_zero_tolerance(tmp_path):
    """The rule is max error ≤ tolerance, equality included: a table against itself passes
    at rtol = atol = 0 (kills the mutant ``worst < tol``)."""
    t = np.linspace(0.0, 1.0, 11)
    res = Results(t, {"a.x": np.sin(W * t), "a.y": 0 * t})
    c = compare(res, res, rtol=0, atol=0)
    assert c.passed and [(r.max_abs_error, r.tolerance) for r in c.rows] == [(0, 0), (0, 0)]
    path = write(tmp_path / "a.csv", t, {"a.x": np.sin(W * t)})
    assert main(["compare", str(path), str(path), "--rtol", "0", "--atol", "0"]) == 0


def test_abs_error_of_non_finite_values():
    """Both nan or the same infinity: equal; nan or inf on one side only: infinite error."""
    r = np.array([1.0, np.nan, np.inf, np.nan, 2.0, np.inf])
    f = np.array([1.5, np.nan, np.inf, 2.0, np.inf, -np.inf])
    np.testing.assert_array_equal(abs_error(r, f), [0.5, 0.0, 0.0, np.inf, np.inf, np.inf])


# --- different time grids ------------------------------------------------------------------

@pytest.mark.parametrize("method, bound", [
    ("cubic", 5 / 384 * 0.025 ** 4 * W ** 4),     # spline: (5/384) h⁴ max|f''''|
    ("linear", 0.025 ** 2 / 8 * W ** 2),          # chord: h²/8 max|f''|
], ids=["cubic", "linear"])
def test_interpolated_onto_reference_times(method, bound):
    """sin(2πt) on 41 points (h = 0.025) against the exact sin on a 0.01 grid to t = 1.2:
    the reported error is the interpolation error, below its textbook bound; the
    interpolation error column bounds it (issue 22: it was an estimate, max |I_h − I_2h| / 15,
    2× too small between rows) without overstating it more than 6× (measured 5.6×, cubic:
    the not-a-knot ends), and the 20 rows after t = 1 are outside the overlap."""
    t = np.linspace(0.0, 1.0, 41)
    t_ref = np.arange(121) * 0.01
    res = Results(t, {"a.x": np.sin(W * t)})
    ref = Results(t_ref, {"a.x": np.sin(W * t_ref)})
    c = compare(res, ref, method=method)
    assert c.method == method and c.overlap == (0.0, 1.0)
    assert (c.rows_compared, c.rows_outside) == (101, 20)
    row = c["a.x"]
    assert 0.1 * bound < row.max_abs_error <= bound
    assert row.max_abs_error <= row.interpolation_error < 6 * row.max_abs_error
    if method == "linear":                        # largest where |f''| is: near the peaks
        assert abs(np.sin(W * row.t_at_max)) > 0.95
    text = c.to_markdown()
    assert "interpolated onto the reference times" in text
    assert "101 of 121 reference rows compared, 20 outside" in text
    assert "interp. error" in text


def test_cubic_interpolation_is_exact_for_a_cubic():
    """A not-a-knot spline reproduces a cubic polynomial: different grids, round-off errors."""
    t, t_ref = np.linspace(0.0, 2.0, 17), np.linspace(0.0, 2.0, 301)
    cubic = lambda x: 1 - 2 * x + 0.5 * x ** 2 + 0.25 * x ** 3      # noqa: E731
    c = compare(Results(t, {"a.x": cubic(t)}), Results(t_ref, {"a.x": cubic(t_ref)}))
    assert c.method == "cubic" and c.passed
    assert c["a.x"].max_abs_error < 1e-14 and c["a.x"].interpolation_error < 1e-14
    assert not compare(Results(t, {"a.x": cubic(t)}), Results(t_ref, {"a.x": cubic(t_ref)}),
                       method="linear").passed


def test_times_equal_up_to_rounding_are_matched_row_by_row(tmp_path):
    """linspace times against the same times printed with 6 digits: no interpolation."""
    t = np.linspace(0.0, 1.0, 101)
    ref = write(tmp_path / "ref.csv", t, {"a.x": t ** 2}, fmt="%.6g")
    c = compare(Results(t, {"a.x": t ** 2}), ref)
    assert c.method is None and c.passed and "the same 101 times" in c.header()[2]


# --- times matched to the digits a file carries ----------------------------------------------

@pytest.mark.parametrize("cells, precision, digits", [
    (["0", "0.00277778", "0.5", "1", "100"], [0, 5e-9, 5e-7, 5e-6, 5e-4],
     "6 significant digits"),                               # %.6g drops trailing zeros
    (["2.77778e-03", "-1e+00", "0"], [5e-9, 5e-6, 0], "6 significant digits"),
    (["0.000", "0.250", "1.125"], [5e-4, 5e-4, 5e-4], "3 decimals"),   # %.3f keeps them
    (["2.50000E-01", "1.00000E+00"], [5e-7, 5e-6], "6 significant digits"),
    (["0", "0.0027777777777777779"], [0, 5e-20], "17 significant digits"),
    (["nan", ""], [0, 0], ""),
])
def test_written_precision(cells, precision, digits):
    """Half a unit of the last digit each time carries, from the text of the column."""
    p, d = written_precision(cells)
    assert d == digits
    np.testing.assert_allclose(p, precision, rtol=1e-12, atol=0)


def test_six_digit_times_are_matched_row_by_row_both_ways(tmp_path):
    """sin(2πt) at t = k/360 written with 6 significant digits (t = 0.00277778, …) against
    full precision: rows are matched one to one (not interpolated) whichever file carries 6
    digits, and the max error is exactly the rounding of the values."""
    t = np.arange(361) / 360
    x = np.sin(W * t)
    six_t = np.array([float(f"{v:.6g}") for v in t])
    six_x = np.array([float(f"{v:.6g}") for v in x])
    assert not times_match(t, 0 * t, six_t, 0 * t)           # float rounding alone: no
    rounding = np.abs(x - six_x)
    full = Results(t, {"a.x": x})
    six = write(tmp_path / "six.csv", t, {"a.x": x}, fmt="%.6g")
    exact = write(tmp_path / "full.csv", t, {"a.x": x})
    for res, ref, side in ((full, six, "reference"), (six, exact, "result")):
        c = compare(res, ref, rtol=5e-6)
        assert c.method is None and c.rows_compared == 361 and c.passed
        row = c["a.x"]
        assert row.max_abs_error == rounding.max()
        assert row.t_at_max == (six_t if side == "reference" else t)[np.argmax(rounding)]
        assert c.time_digits == f"6 significant digits the {side} carries"
        assert c.time_difference == np.abs(t - six_t).max()
        assert c.header()[2].startswith(f"times matched row by row to the 6 significant "
                                        f"digits the {side} carries: the same 361 times")
    both = compare(six, write(tmp_path / "five.csv", t, {"a.x": x}, fmt="%.5g"), rtol=5e-5)
    assert both.method is None and both.time_digits == (
        "6 significant digits the result carries and the 5 significant digits the reference "
        "carries")


@pytest.mark.parametrize("shift, matched", [(0.9, True), (1.1, False)])
def test_time_matching_stops_at_half_a_unit_of_the_last_digit(tmp_path, shift, matched):
    """'0.00277778' stands for 0.002777775 … 0.002777785: a result time 0.9 half-units from
    it matches, one 1.1 half-units away does not (the result is then interpolated)."""
    t = np.arange(361) / 360
    ref = write(tmp_path / "ref.csv", t, {"a.x": t}, t_fmt="%.6g")
    moved = t.copy()
    moved[1] = 0.00277778 + shift * 5e-9
    c = compare(Results(moved, {"a.x": moved}), ref)
    assert (c.method is None) is matched
    six = np.array([float(f"{v:.6g}") for v in t])
    assert c.time_difference == (np.abs(moved - six).max() if matched else 0.0)


def test_times_off_by_1e_4_relative_are_interpolated(tmp_path):
    """A reference on times 1e-4 (relative) later than the result's, written with 6 digits:
    20 times the 5e-6 they carry, so the result is interpolated, not matched row by row
    (kills the mutant that loosens the matching to 1e-3·|t|). The values are a cubic, which
    the spline reproduces: the errors are round-off; matched row by row they would be ~1e-4."""
    cubic = lambda x: 1 - 2 * x + 0.5 * x ** 2 + 0.25 * x ** 3      # noqa: E731
    t = np.linspace(0.0, 1.0, 101)
    t_ref = np.array([float(f"{v:.6g}") for v in t * (1 + 1e-4)])
    ref = write(tmp_path / "ref.csv", t * (1 + 1e-4), {"a.x": cubic(t_ref)}, t_fmt="%.6g")
    c = compare(Results(t, {"a.x": cubic(t)}), ref)
    assert c.method == "cubic" and (c.rows_compared, c.rows_outside) == (100, 1)
    assert c.time_digits == "" and c.time_difference == 0.0
    assert c.passed and c["a.x"].max_abs_error < 1e-14


def test_reading_variants(tmp_path):
    """Trailing separators, an empty cell (missing: infinite error), a BOM and tabs, '#' lines,
    and t in any column."""
    res = Results([0.0, 0.5, 1.0], {"a.x": np.array([1.0, 2.0, 3.0])})
    gap = tmp_path / "gap.csv"
    gap.write_text("t;a.x;\n0;1;\n0,5;;\n1;3;\n", encoding="utf-8")
    row = compare(res, gap)["a.x"]
    assert row.max_abs_error == np.inf and row.t_at_max == 0.5 and not row.passed
    tabs = tmp_path / "tabs.csv"
    tabs.write_text("# exported\na.x\tt\n1,0\t0\n2,0\t0,5\n3,0\t1\n", encoding="utf-8-sig")
    c = compare(res, tabs)
    assert c.passed and c.method is None and c["a.x"].max_abs_error == 0
    assert any("tab as separator" in n for n in c.notes)


# --- angles modulo 2π ------------------------------------------------------------------------

def wrap(angle):
    """An angle in (−π, π], as PAM exports it (independent of compare's reduction)."""
    return np.array([a - 2 * np.pi * math.ceil((a - np.pi) / (2 * np.pi)) for a in angle])


def test_angle_error():
    """The difference reduced to (−π, π], then its magnitude; non-finite as abs_error."""
    r = np.array([np.pi, -np.pi, 2 * np.pi + 1e-3, 0.5, 7.0, np.nan, np.nan, 1.0])
    f = np.array([0.0, 0.0, 0.0, -0.5, 0.0, np.nan, 1.0, np.inf])
    np.testing.assert_allclose(angle_error(r, f),
                               [np.pi, np.pi, 1e-3, 1.0, 7.0 - 2 * np.pi, 0, np.inf, np.inf],
                               rtol=1e-12)
    assert wrap(np.array([np.pi, -np.pi, 3.5]))[:2].tolist() == [np.pi, np.pi]


def test_wrap_angles(tmp_path):
    """An unwrapped result (3t rad, t = 0 … 2 s) against an export wrapped at ±π with a bump
    of 1e-6 at t = 0.37: modulo 2π only the bump remains, with scale π; lengths, a linear
    actuator's f(t) and an f(t) whose actuator neither file names are not wrapped."""
    t = np.linspace(0.0, 2.0, 201)
    fi = 3 * t
    bump = np.where(np.isclose(t, 0.37), 1e-6, 0.0)
    names = ["a.fi", "ts.fi_rel", "m.f(t)", "l.f(t)", "u.f(t)", "a.x"]
    res = write(tmp_path / "res.csv", t, {**{n: fi for n in names}, "m.Mz": t, "l.Força": t})
    ref = write(tmp_path / "ref.csv", t, {**{n: wrap(fi) + bump for n in names}, "m.Mz": t,
                                          "l.Força": t})
    c = compare(res, ref, wrap_angles=True)
    assert c.wrapped == ["a.fi", "ts.fi_rel", "m.f(t)"] and c.failed == names
    for name in c.wrapped:
        row = c[name]
        assert row.max_abs_error == pytest.approx(1e-6, rel=1e-8) and row.t_at_max == 0.37
        assert row.scale == math.pi and row.tolerance == pytest.approx(1e-12 + 1e-9 * math.pi)
        assert row.max_rel_error == pytest.approx(1e-6 / math.pi, rel=1e-8)
    assert c["a.x"].max_abs_error == pytest.approx(2 * np.pi, rel=1e-12)
    assert c["a.x"].scale == np.abs(wrap(fi) + bump).max()      # max |wrapped reference|
    assert ("angles compared modulo 2π (the difference reduced to (−π, π], scale π): a.fi, "
            "ts.fi_rel, m.f(t)") in c.header()
    assert "not compared modulo 2π (angle or length: neither file tells which actuator it " \
           "is): u.f(t)" in c.notes
    plain = compare(res, ref)
    assert plain.wrapped == [] and plain["a.fi"].max_abs_error == pytest.approx(2 * np.pi)
    loose = compare(res, ref, wrap_angles=True, rtol=1e-6)        # tolerance 3.14e-6
    assert loose.failed == ["l.f(t)", "u.f(t)", "a.x"]
    assert compare(res, ref, wrap_angles=True, rtol=0.3e-6).failed == names    # 0.94e-6
    with pytest.raises(CompareInputError, match=r"`wrap_angles` must be True or False"):
        compare(res, ref, wrap_angles="yes")


def test_wrapped_result_is_unwrapped_before_interpolation():
    """A wrapped result on a coarse grid against the unwrapped angle on a fine one: the
    result is unwrapped, then interpolated (a line, reproduced to round-off); the units of
    Results tables say which columns are angles (here f(t), which a CSV would not tell)."""
    t, t_ref = np.linspace(0.0, 2.0, 41), np.linspace(0.0, 2.0, 401)
    res = Results(t, {"m.f(t)": wrap(3 * t)}, {"m.f(t)": "rad"})
    ref = Results(t_ref, {"m.f(t)": 3 * t_ref}, {"m.f(t)": "rad"})
    c = compare(res, ref, wrap_angles=True)
    assert c.method == "cubic" and c.wrapped == ["m.f(t)"]
    assert c["m.f(t)"].max_abs_error < 1e-13 and c["m.f(t)"].interpolation_error < 1e-13
    assert compare(res, ref, wrap_angles=True, method="linear").passed
    assert not compare(res, ref).passed


def test_pam_export_with_6_digit_times_and_wrapped_angles(data, tmp_path):
    """crank_pam_wrapped.csv: the closed form over 3 s every 1/120 s (t = 0.00833333, …),
    angles wrapped at ±π, 6 digits. Rows match one to one; modulo 2π the angles' errors are
    exactly the rounding of the wrapped closed form; without it they fail by 2π."""
    folder = data / "compare"
    res = pam2exu.run(folder / "crank.toml", t_end=3.0, steps=360)
    ref, names = folder / "crank_pam_wrapped.csv", folder / "crank_names.csv"
    c = compare(res, ref, names=names, rtol=1e-5, wrap_angles=True)
    assert c.passed and c.method is None and len(c.rows) == 11
    assert c.time_digits == "6 significant digits the reference carries"
    assert c.wrapped == ["crank.fi", "motor.f(t)"]
    t = np.arange(361) / 120
    fi = wrap(2 * t)
    rounding = np.abs(np.array([float(f"{x:.6g}") for x in fi]) - fi)
    for name in c.wrapped:
        assert c[name].max_abs_error == pytest.approx(rounding.max(), rel=1e-6, abs=1e-13)
        assert c[name].t_at_max == pytest.approx(t[np.argmax(rounding)], abs=5e-6)
    assert compare(res, ref, names=names, rtol=1e-5).failed == ["crank.fi", "motor.f(t)"]
    csv_res = res.to_csv(tmp_path / "crank_3s.csv")
    assert main(["compare", str(csv_res), str(ref), "--names", str(names), "--rtol", "1e-5",
                 "--wrap-angles"]) == 0
    assert main(["compare", str(csv_res), str(ref), "--names", str(names), "--rtol",
                 "1e-5"]) == 1


# --- names ---------------------------------------------------------------------------------

@pytest.mark.parametrize("column, names, expected", [
    ("X.Forca", None, "X.Força"),
    ("motor.f", None, "motor.f(t)"),
    ("motor.Df", None, "motor.Df(t)"),
    ("motor.DDfi", None, "motor.DDfi"),                    # only whole variable names
    ("crank.fi", None, "crank.fi"),
    (" t ", None, "t"),
    (unicodedata.normalize("NFD", "X.Força"), None, "X.Força"),
    ("Solid1.fi", {"Solid1": "crank"}, "crank.fi"),
    ("Solid1.fi", {"Solid1.fi": "rod.fi", "Solid1": "crank"}, "rod.fi"),   # column first
    ("K1.Forca", {"K1.Força": "spring.Força"}, "spring.Força"),
    ("M1.f", {"M1": "motor"}, "motor.f(t)"),
    ("Temps", {"Temps": "t"}, "t"),
])
def test_canonical_names(column, names, expected):
    assert canonical_name(column, names) == expected


def test_names_map_file(tmp_path):
    path = tmp_path / "map.csv"
    path.write_text("pam_name,pam2exu_name\n# comment\n\nSolid1;crank\n Solid2.fi , rod.fi \n",
                    encoding="utf-8")
    assert read_names(path) == {"Solid1": "crank", "Solid2.fi": "rod.fi"}
    path.write_text("Solid1,crank\nSolid2\n", encoding="utf-8")
    with pytest.raises(CompareInputError, match=r"map.csv, line 2: expected two names"):
        read_names(path)
    path.write_text("Solid1,crank\nSolid1,rod\n", encoding="utf-8")
    with pytest.raises(CompareInputError, match=r"line 2: 'Solid1' is mapped twice"):
        read_names(path)


def test_names_map_renames_the_reference_only():
    """A PAM name that is also a pam2exu name (joint B) is not renamed in the result."""
    t = np.linspace(0.0, 1.0, 3)
    res = Results(t, {"B.Fx": t, "crank.fi": t})
    ref = Results(t, {"B.Fx": t, "Solid1.fi": t, "M1.f": t})
    c = compare(res, ref, names={"B": "slider", "Solid1": "crank", "Solid9": "rod"})
    assert [r.name for r in c.rows] == ["crank.fi"]
    assert c.only_in_result == ["B.Fx"] and c.only_in_reference == ["slider.Fx", "M1.f(t)"]
    assert "names map: no column matched Solid9" in c.notes


def test_pam_style_reference_with_names_map(data):
    """crank_pam.csv holds the closed form at 6 significant digits: the reported errors are
    exactly the rounding errors of the file, computed here from the closed form."""
    folder = data / "compare"
    res = pam2exu.run(folder / "crank.toml")
    c = compare(res, folder / "crank_pam.csv", names=folder / "crank_names.csv", rtol=1e-5)
    assert c.passed and c.method is None
    assert [r.name for r in c.rows] == ["crank.x", "crank.y", "crank.fi", "crank.Dfi",
                                        "crank.DDfi", "motor.Mz", "motor.f(t)", "motor.Df(t)",
                                        "spring.Força", "spring.ro", "spring.Dro"]
    assert c.only_in_reference == [] and "base.Fx" in c.only_in_result
    t = np.linspace(0.0, 1.0, 101)
    fi = 2 * t
    ro = np.sqrt(0.05 - 0.04 * np.cos(fi))
    force = 100 * (ro - 0.1)
    exact = {"spring.ro": ro, "spring.Dro": 0.02 * np.sin(fi) * 2 / ro, "spring.Força": force,
             "motor.Mz": 0.02 * np.sin(fi) * force / ro}
    for name, v in exact.items():
        rounding = np.abs(np.array([float(f"{x:.6g}") for x in v]) - v)
        assert c[name].max_abs_error == pytest.approx(rounding.max(), rel=1e-6, abs=1e-13)
        assert c[name].t_at_max == pytest.approx(t[np.argmax(rounding)], abs=1e-12)
        assert c[name].max_rel_error <= 5e-6                          # 6 digits
    assert any("';' as separator and ',' as decimal mark" in n for n in c.notes)
    assert any("11 columns renamed: Solid1.x → crank.x" in n for n in c.notes)
    # the default tolerance sees the 6-digit rounding of the irrational columns only
    strict = compare(res, folder / "crank_pam.csv", names=folder / "crank_names.csv")
    assert strict.failed == ["motor.Mz", "spring.Força", "spring.ro", "spring.Dro"]


# --- acceptance on the examples --------------------------------------------------------------

def test_four_bar_200_against_400_steps(examples, tmp_path):
    """Two runs of the four-bar: at the shared times they agree to round-off; in between, the
    differences are the interpolation error, and the report says so."""
    coarse = pam2exu.run(examples / "four_bar.toml", analysis="kinematic", steps=200)
    fine = pam2exu.run(examples / "four_bar.toml", analysis="kinematic", steps=400)
    a, b = coarse.to_csv(tmp_path / "200.csv"), fine.to_csv(tmp_path / "400.csv")
    c = compare(a, b)
    assert c.method == "cubic" and (c.rows_compared, c.rows_outside) == (401, 0)
    assert len(c.rows) == 38 and not c.only_in_result and not c.only_in_reference
    for r in c.rows:                     # every difference explained by the interpolation
        assert r.max_abs_error <= 3 * r.interpolation_error + 1e-12, r
    assert not c.passed and "coupler.DDfi" in c.failed
    assert compare(a, b, rtol=1e-5).passed
    shared = Results(fine.t[::2], {n: fine[n][::2] for n in fine.columns})
    same = compare(a, shared)            # the 400-step run at the 200-step times
    assert same.method is None and same.passed


def test_renamed_pam_style_export_of_a_result(examples, tmp_path):
    """Every column of a kinetostatic run, renamed PAM-style (Solid<k>, Forca, f, Df), with
    ';', decimal comma and Windows-1252: with the map, every value matches exactly."""
    res = pam2exu.run(examples / "all_elements.toml", analysis="kinetostatic", steps=20)
    solids = list(dict.fromkeys(c.split(".")[0] for c in res.columns if c.endswith(".fi")))
    pam = {s: f"Solid{k}" for k, s in enumerate(solids)}
    spell = {"Força": "Forca", "f(t)": "f", "Df(t)": "Df"}

    def pam_name(column):
        owner, variable = column.rsplit(".", 1)
        if column == "cylinder.Força":
            return column                                    # kept: cp1252 'ç'
        return f"{pam.get(owner, owner)}.{spell.get(variable, variable)}"

    columns = {pam_name(c): res[c] for c in res.columns}
    assert "Solid1.fi" in columns and "motor.f" in columns and "return_spring.Forca" in columns
    ref = write(tmp_path / "pam.csv", res.t, columns, sep=";", decimal=",",
                encoding="cp1252", newline="\r\n")
    names = {v: k for k, v in pam.items()}
    c = compare(res, ref, names=names)
    assert c.passed and len(c.rows) == len(res.columns)
    assert not c.only_in_result and not c.only_in_reference
    assert max(r.max_abs_error for r in c.rows) == 0.0       # %.17g: exact round trip
    assert any("not UTF-8: read as Windows-1252" in n for n in c.notes)
    # without the map the solids do not match, but the elements' spellings do
    plain = compare(res, ref)
    assert "motor.f(t)" in [r.name for r in plain.rows] and "Solid1.fi" in plain.only_in_reference


# --- selection, one-sided variables, output formats -----------------------------------------

def tables():
    t = np.linspace(0.0, 1.0, 11)
    res = Results(t, {"crank.fi": t, "crank.Dfi": 1 + 0 * t, "B.Fx": t ** 2, "extra.x": t})
    ref = Results(t, {"crank.fi": t, "crank.Dfi": 1 + 0 * t, "B.Fx": t ** 2 + 1e-3,
                      "pam.only": t})
    return res, ref


def test_columns_and_variables_of_one_table_only():
    res, ref = tables()
    c = compare(res, ref)
    assert [r.name for r in c.rows] == ["crank.fi", "crank.Dfi", "B.Fx"]
    assert c.only_in_result == ["extra.x"] and c.only_in_reference == ["pam.only"]
    assert c.failed == ["B.Fx"]
    chosen = compare(res, ref, columns=["crank.*"])
    assert chosen.passed and [r.name for r in chosen.rows] == ["crank.fi", "crank.Dfi"]
    assert chosen.only_in_result == [] and chosen.only_in_reference == []
    assert [r.name for r in compare(res, ref, columns="Fx").rows] == ["B.Fx"]
    with pytest.raises(CompareInputError, match=r"'crank\.fj' \(did you mean 'crank\.fi'\?\)"):
        compare(res, ref, columns=["crank.fj"])


def test_markdown_and_csv_tables():
    res, ref = tables()
    c = compare(res, ref)
    md = str(c)
    assert md == c.to_markdown()
    table = [line for line in md.splitlines() if line.startswith("|")]
    assert len(table) == 2 + 3 and table[-1].endswith("| FAIL |")
    assert "only in the result (1, not compared): extra.x" in md
    assert md.splitlines()[-1] == "FAIL: 1 of 3 common variables outside the tolerance: B.Fx"
    rows = list(csv.DictReader(io.StringIO(c.to_csv())))
    assert [r["verdict"] for r in rows] == ["pass", "pass", "fail", "only in result",
                                            "only in reference"]
    fx = c["B.Fx"]
    assert float(rows[2]["max_abs_error"]) == fx.max_abs_error       # full precision
    assert float(rows[2]["scale"]) == fx.scale == 1.0 + 1e-3
    assert rows[0]["max_rel_error"] == "0.0" and rows[0]["interpolation_error"] == ""


# --- bad input -------------------------------------------------------------------------------

def test_input_errors_name_the_file_and_the_fix(tmp_path):
    t = np.linspace(0.0, 1.0, 5)
    good = write(tmp_path / "good.csv", t, {"a.x": t})
    with pytest.raises(CompareInputError, match=r"reference file '.*missing.csv' not found"):
        compare(good, tmp_path / "missing.csv")
    (tmp_path / "not.csv").write_text("time,a.x\n0,1\n", encoding="utf-8")
    with pytest.raises(CompareInputError, match=r"not.csv: no column 't' .*'Temps,t'"):
        compare(good, tmp_path / "not.csv")
    assert compare(good, tmp_path / "not.csv", names={"time": "t"}, columns=["a.x"],
                   atol=2).passed
    other = write(tmp_path / "other.csv", t, {"b.y": t})
    with pytest.raises(CompareInputError, match=r"no variable in common .*--names MAP"):
        compare(good, other)
    (tmp_path / "short.csv").write_text("t,a.x\n0,1\n0.5\n", encoding="utf-8")
    with pytest.raises(CompareInputError, match=r"short.csv, line 3: 1 values, the header has "
                                                r"2 names \(a file with decimal commas"):
        compare(good, tmp_path / "short.csv")
    (tmp_path / "text.csv").write_text("t;a.x\n0;1\n0,5;oops\n", encoding="utf-8")
    with pytest.raises(CompareInputError, match=r"text.csv, line 3, column 'a.x': 'oops' is "
                                                r"not a number"):
        compare(good, tmp_path / "text.csv")
    twice = write(tmp_path / "twice.csv", t, {"m.f": t, "m.f(t)": t})
    with pytest.raises(CompareInputError, match=r"'m.f' and 'm.f\(t\)' both become 'm.f\(t\)'"):
        compare(good, twice)
    back = write(tmp_path / "back.csv", t[::-1], {"a.x": t})
    with pytest.raises(CompareInputError, match=r"back.csv: t is not strictly increasing"):
        compare(back, good)
    late = write(tmp_path / "late.csv", t + 5, {"a.x": t})
    with pytest.raises(CompareInputError, match=r"the times do not overlap"):
        compare(good, late)
    with pytest.raises(CompareInputError, match=r"`rtol` must be a number ≥ 0"):
        compare(good, good, rtol=-1)


# --- command line ----------------------------------------------------------------------------

def test_cli_exit_codes(tmp_path):
    """0 when every variable passes, 1 when one does not, 2 for bad input."""
    t = np.linspace(0.0, 1.0, 11)
    a = write(tmp_path / "a.csv", t, {"a.x": np.sin(t)})
    b = write(tmp_path / "b.csv", t, {"a.x": np.sin(t) + 1e-6})

    def cli(*args):
        return subprocess.run([sys.executable, "-m", "pam2exu", "compare", *map(str, args)],
                              cwd=ROOT, capture_output=True, text=True, encoding="utf-8")

    ok, bad, wrong = cli(a, a), cli(a, b), cli(a, tmp_path / "nope.csv")
    assert ok.returncode == 0 and ok.stdout.rstrip().endswith("PASS: all 1 common variables "
                                                              "within the tolerance")
    assert bad.returncode == 1 and "| a.x | 1e-06 |" in bad.stdout
    assert wrong.returncode == 2 and wrong.stdout == ""
    assert wrong.stderr.startswith(f"pam2exu: compare: reference file '{tmp_path / 'nope.csv'}'"
                                   f" not found")
    assert cli(a, b, "--rtol", "2e-6").returncode == 0


def test_cli_csv_format_and_options(data, tmp_path, capsys):
    folder = data / "compare"
    res = pam2exu.run(folder / "crank.toml").to_csv(tmp_path / "crank.csv")
    code = main(["compare", str(res), str(folder / "crank_pam.csv"), "--names",
                 str(folder / "crank_names.csv"), "--rtol", "1e-5", "--columns", "spring.*",
                 "--format", "csv"])
    out, err = capsys.readouterr()
    assert code == 0
    rows = list(csv.DictReader(io.StringIO(out)))
    assert [r["variable"] for r in rows] == ["spring.Força", "spring.ro", "spring.Dro"]
    assert "rule: a variable passes when" in err and err.rstrip().endswith(
        "PASS: all 3 common variables within the tolerance")
    assert main(["compare", str(res), str(folder / "crank_pam.csv"), "--columns", "Mz"]) == 2
    assert "no variable in common" in capsys.readouterr().err


def test_a_bool_is_not_a_tolerance(tmp_path):
    t = np.linspace(0.0, 1.0, 5)
    good = write(tmp_path / "good.csv", t, {"a.x": t})
    with pytest.raises(CompareInputError, match=r"`rtol` must be a number ≥ 0, not True"):
        compare(good, good, rtol=True)


def test_a_name_holding_a_semicolon_is_read_from_its_quotes(tmp_path):
    """to_csv quotes a name with ';': the separator is still ',' (the ';' is inside quotes),
    so the file compares equal to the table it was written from."""
    res = Results([0.0, 0.5, 1.0], {"a;b.x": [0.1, 0.2, 0.3], "c.y": [1.0, 2.0, 3.0]})
    path = res.to_csv(tmp_path / "semicolon.csv")
    assert path.read_text(encoding="utf-8").splitlines()[0] == 't,"a;b.x",c.y'
    comparison = compare(res, path, rtol=0.0, atol=0.0)
    assert comparison.passed and sorted(v.name for v in comparison.rows) == ["a;b.x", "c.y"]
    assert not comparison.notes                       # not read with ";" as separator


def test_a_column_of_zeros_has_no_relative_error():
    """Issue 22: a column zero to round-off (reference ≤ 1e-17, result 5.12e-15 at most)
    was reported 'max rel error 512 … pass'. Its relative error is not given (nan, '–' in
    the table, empty in CSV), a note names it and says it is judged against atol; it still
    passes (5.12e-15 ≤ atol = 1e-12), and a real error of 1e-6 still fails. A column of
    size 1 keeps its relative error."""
    t = np.linspace(0.0, 1.0, 11)
    noise = 1e-17 * np.cos(7 * t)
    res = Results(t, {"a.y": noise + 5.12e-15 * t, "b.y": 1e-6 * t, "c.x": np.sin(t) + 1e-12 * t})
    ref = Results(t, {"a.y": noise, "b.y": noise, "c.x": np.sin(t)})
    c = compare(res, ref)
    assert c["a.y"].max_abs_error == pytest.approx(5.12e-15, rel=1e-12)
    assert np.isnan(c["a.y"].max_rel_error) and c["a.y"].passed
    assert np.isnan(c["b.y"].max_rel_error) and not c["b.y"].passed
    assert c["c.x"].max_rel_error == pytest.approx(1e-12 / np.sin(1.0), rel=1e-6)
    assert any("no relative error for a.y, b.y: the reference is zero to within atol"
               in n for n in c.notes), c.notes
    line = next(s for s in c.to_markdown().splitlines() if s.startswith("| a.y |"))
    assert line.split("|")[3].strip() == "–"
