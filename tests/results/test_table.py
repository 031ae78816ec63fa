"""The Results table: named columns, CSV of the contract, NumPy without copies, selection."""
import csv
import sys

import numpy as np
import pytest

import pam2exu
from pam2exu.errors import ModelError
from pam2exu.results import Results, reading, select_columns, table_csv
from pam2exu.results.reading import load_table

COLUMNS = ["crank.x", "crank.fi", "guide.Fx", "motor.f(t)", "spring.Força", "rod.Fx"]


def table():
    t = np.linspace(0.0, 1.0, 5)
    return Results(t, {c: np.arange(5) * (i + 1) + 1 / 3 for i, c in enumerate(COLUMNS)},
                   units={"crank.x": "m"}, analysis="kinematic", model="m")


def test_columns_and_views():
    res = table()
    assert res.columns == COLUMNS
    np.testing.assert_array_equal(res.t, np.linspace(0.0, 1.0, 5))
    arr = res.to_numpy()
    assert arr.shape == (5, 1 + len(COLUMNS))
    assert np.shares_memory(arr, res["crank.fi"])        # no copies
    np.testing.assert_array_equal(arr[:, 2], res["crank.fi"])
    with pytest.raises(KeyError, match="did you mean 'crank.fi'"):
        res["crank.fj"]


def test_csv_round_trip_full_precision_utf8(tmp_path):
    res = table()
    path = res.to_csv(tmp_path / "r.csv")
    with open(path, encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["t", *COLUMNS]                    # 'Força' kept as UTF-8
    values = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(values, res.to_numpy())  # bit for bit
    assert not (tmp_path / "r.csv.part").exists()


# --- CSV: every float64 back bit for bit -------------------------------------------------

def bits(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float).view(np.uint64)


def hard_values() -> np.ndarray:
    """Floats that shortest-digit printers and parsers get wrong when they are wrong."""
    rng = np.random.default_rng(20240610)
    random = rng.integers(0, 2**64, 3000, dtype=np.uint64, endpoint=False).view(float)
    subnormal = (rng.integers(1, 2**52, 300, dtype=np.uint64)
                 | (rng.integers(0, 2, 300, dtype=np.uint64) << np.uint64(63))).view(float)
    powers = np.concatenate([10.0 ** np.arange(-323, 309), 2.0 ** np.arange(-1074, 1024)])
    special = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072009e-308, 2.2250738585072014e-308,
               1e308, -1e308, sys.float_info.max, -sys.float_info.max, 0.1 + 0.2, 0.3, 1 / 3,
               2 / 3, np.pi, -np.e, 1.0, -2.0, 2.0**53, 2.0**53 + 2, 2.0**63, 2.0**64, 1e15,
               1e16, 1e21, 1e22, 1e23, 123456789.0, 9007199254740993.0, 4.294967294e9,
               1.8531501765868567e21, -3.347727380279489e33, 2.98023223876953125e-8,
               9.5e-5, 1e-5, 0.001, 100000.0, 1234567890123456789.0]
    with np.errstate(over="ignore"):
        near = np.nextafter(np.repeat(special, 2), np.tile([-np.inf, np.inf], len(special)))
    values = np.concatenate([random, subnormal, powers, special, near])
    return values[np.isfinite(values)]


def square(values: np.ndarray, columns: int = 7) -> Results:
    """A table of the values, row after row (t is a column like the others)."""
    values = np.resize(values, (-(-len(values) // columns), columns))
    return Results(values[:, 0], {f"c{j}.x": values[:, j] for j in range(1, columns)})


def read_by_hand(path) -> np.ndarray:
    """Python's float() on each cell: a reader that shares no code with pam2exu's."""
    with open(path, encoding="utf-8", newline="") as fh:
        return np.array([[float(cell) for cell in row] for row in list(csv.reader(fh))[1:]])


def test_csv_hard_values_read_back_bit_for_bit(tmp_path):
    """Random bit patterns, subnormals, ±0, the extremes, every power of 10 and of 2."""
    res = square(hard_values())
    path = res.to_csv(tmp_path / "hard.csv")
    own = reading._read_own(path)                 # read_csv's fast reader, checked
    assert own is not None
    np.testing.assert_array_equal(bits(own.to_numpy()), bits(res.to_numpy()))
    back = pam2exu.read_csv(path)
    assert back.columns == res.columns
    np.testing.assert_array_equal(bits(back.to_numpy()), bits(res.to_numpy()))
    np.testing.assert_array_equal(bits(read_by_hand(path)), bits(res.to_numpy()))
    general = load_table(path, "results", {})      # compare's reader, not read_csv's own
    np.testing.assert_array_equal(bits(general.values), bits(res.to_numpy().T[1:]))


def test_csv_keeps_the_sign_of_zero(tmp_path):
    """-0.0 is written -0 and read back -0.0 (scipy's reader alone would give +0.0)."""
    res = Results([-0.0, 0.0, 1.0], {"a.x": [0.0, -0.0, -0.0], "b.y": [-0.0, 1.0, 0.0]})
    path = res.to_csv(tmp_path / "zeros.csv")
    assert path.read_text(encoding="utf-8").splitlines()[1:] == ["-0,0,-0", "0,-0,1",
                                                                 "1,-0,0"]
    np.testing.assert_array_equal(np.signbit(pam2exu.read_csv(path).to_numpy()),
                                  np.signbit(res.to_numpy()))


def test_csv_writes_the_shortest_digits(tmp_path):
    res = Results([0.0, 1.0], {"a.x": [0.1 + 0.2, -0.0], "a.y": [1e-5, 2.0**53]})
    text = res.to_csv(tmp_path / "r.csv").read_text(encoding="utf-8")
    assert text == "t,a.x,a.y\n0,3.0000000000000004e-1,1e-5\n1,-0,9.007199254740992e15\n"


def test_csv_non_finite_values_read_back(tmp_path):
    values = np.array([[0.0, np.nan, np.inf], [1.0, -np.inf, -np.nan]])
    res = Results(values[:, 0], {"a.x": values[:, 1], "a.y": values[:, 2]})
    path = res.to_csv(tmp_path / "r.csv")
    for back in (pam2exu.read_csv(path).to_numpy(), read_by_hand(path)):
        np.testing.assert_array_equal(back, values)          # nan where nan, ±inf exactly


@pytest.mark.parametrize("rows, columns", [(1, 1), (1, 4), (2, 2), (3, 3), (40, 5)])
def test_csv_small_and_square_tables(tmp_path, rows, columns):
    """A square symmetric array is no special case (Matrix Market would write half of it)."""
    values = np.add.outer(np.arange(rows), np.arange(columns)) / 7.0
    res = square(values.ravel(), columns)
    back = pam2exu.read_csv(res.to_csv(tmp_path / "r.csv"))
    np.testing.assert_array_equal(bits(back.to_numpy()), bits(values))


def test_csv_in_blocks_is_the_same_file(tmp_path, monkeypatch):
    """Rows are formatted a block at a time (bounded memory): the blocks join seamlessly."""
    res = square(hard_values()[:500])
    whole = res.to_csv(tmp_path / "whole.csv").read_bytes()
    monkeypatch.setattr(table_csv, "BLOCK", 20)          # 2 rows of 7 values a block
    assert res.to_csv(tmp_path / "blocks.csv").read_bytes() == whole
    back = pam2exu.read_csv(tmp_path / "blocks.csv")
    np.testing.assert_array_equal(bits(back.to_numpy()), bits(res.to_numpy()))


def test_csv_of_a_run_reads_back_bit_for_bit(examples, tmp_path):
    res = pam2exu.run(examples / "four_bar.toml", analysis="kinetostatic", steps=60)
    path = res.to_csv(tmp_path / "four_bar.csv")
    back = pam2exu.read_csv(path)
    assert back.columns == res.columns
    np.testing.assert_array_equal(bits(back.to_numpy()), bits(res.to_numpy()))
    np.testing.assert_array_equal(bits(read_by_hand(path)), bits(res.to_numpy()))
    table = pam2exu.compare(res, path, rtol=0.0, atol=0.0)
    assert table.passed and all(row.max_abs_error == 0.0 for row in table.rows)


NAMES = ["a,b.x", 'q"uo.y', '"lead.x', "semi;colon.x", "Força.Fx", "émbolo.f(t)", "ü ñ.Dfi"]


def test_csv_names_with_commas_quotes_and_accents_read_back(tmp_path):
    res = Results([0.0, 0.5], {name: [k, -k / 3] for k, name in enumerate(NAMES)})
    path = res.to_csv(tmp_path / "names.csv")
    with open(path, encoding="utf-8", newline="") as fh:
        assert next(csv.reader(fh)) == ["t", *NAMES]       # quoted as CSV readers expect
    back = pam2exu.read_csv(path)
    assert back.columns == NAMES
    np.testing.assert_array_equal(bits(back.to_numpy()), bits(res.to_numpy()))


@pytest.mark.parametrize("edit", [
    lambda text: text.replace("\n", "\r\n"),                        # CRLF
    lambda text: "# written by hand\n" + text,                       # a comment line
    lambda text: text.replace("e-1", "E-1"),                          # other digits
    lambda text: text.replace(",", ", "),                             # blanks
    lambda text: text + "\n",                                        # a blank last line
    lambda text: text.replace(",-0,", ",-0.0,"),
    lambda text: text.replace("1,-0,2", "1,-0,2,"),                   # a trailing separator
], ids=["crlf", "comment", "E", "blanks", "blank line", "-0.0", "trailing ,"])
def test_csv_edited_by_hand_is_read_the_general_way(tmp_path, edit):
    """read_csv reads its own files fast, and any other text as compare does."""
    res = Results([0.0, 1.0, 2.0], {"a.x": [0.3, -0.0, 1.5], "b.y": [1e-300, 2.0, 1 / 3]})
    own = res.to_csv(tmp_path / "own.csv")
    other = tmp_path / "other.csv"
    other.write_text(edit(own.read_text(encoding="utf-8")), encoding="utf-8")
    assert other.read_bytes() != own.read_bytes()
    assert reading._read_own(own) is not None
    assert reading._read_own(other) is None
    expected = load_table(other, "results", {})
    back = pam2exu.read_csv(other)
    np.testing.assert_array_equal(bits(back.t), bits(expected.t))
    np.testing.assert_array_equal(bits(back.to_numpy()[:, 1:].T), bits(expected.values))


def test_csv_fast_reader_agrees_with_the_general_one_on_damaged_files(tmp_path):
    """300 seeded random edits of a to_csv file (bytes deleted, inserted, replaced): read_csv's
    fast reader takes a file only when it reads what compare's reader reads, bit for bit."""
    import random
    rng = random.Random(10)
    res = Results([0.0, 0.5, 1.0], {"a.x": [0.3, -0.0, 1e-300], "b,c.y": [np.inf, 2.0, 1 / 3],
                                    "d.Fx": [-1.5e21, 5e-324, 7.0]})
    own = res.to_csv(tmp_path / "own.csv").read_bytes()
    alphabet = b"0123456789.-+eE,\n \r#nNaAiIfF\";%\t"
    path, taken = tmp_path / "damaged.csv", 0
    for _ in range(300):
        text = bytearray(own)
        for _ in range(rng.randint(1, 3)):
            k, op = rng.randrange(len(text)), rng.random()
            if op < 1 / 3:
                del text[k]
            elif op < 2 / 3:
                text.insert(k, rng.choice(alphabet))
            else:
                text[k] = rng.choice(alphabet)
        path.write_bytes(bytes(text))
        fast = reading._read_own(path)
        if fast is None:
            continue
        taken += 1
        fast_table = load_table(fast, "results", {})
        try:
            general = load_table(path, "results", {})
        except pam2exu.CompareInputError:      # compare takes a ';' or tab in a name
            header = text.split(b"\n")[0]     # for the separator; read_csv does not
            assert b";" in header or b"\t" in header
            continue
        assert fast_table.names == general.names
        np.testing.assert_array_equal(bits(fast_table.t), bits(general.t))
        np.testing.assert_array_equal(bits(fast_table.values), bits(general.values))
    assert 10 < taken < 150          # edits that keep a valid file, e.g. a digit for a digit


def test_csv_written_with_17_digits_still_reads_back(tmp_path):
    """Files of earlier versions (np.savetxt, %.17g)."""
    res = square(hard_values()[:700])
    path = tmp_path / "old.csv"
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(",".join(["t", *res.columns]) + "\n")
        np.savetxt(fh, res.to_numpy(), delimiter=",", fmt="%.17g")
    np.testing.assert_array_equal(bits(pam2exu.read_csv(path).to_numpy()), bits(res.to_numpy()))


def test_csv_failure_leaves_the_old_file_and_no_part_file(tmp_path, monkeypatch):
    path = tmp_path / "r.csv"
    path.write_text("the old file\n", encoding="utf-8")
    res = square(np.arange(70.0))
    blocks = []

    def fail_on_the_second(values):
        if blocks:
            raise OSError("disk full")
        blocks.append(values)
        return b"1,2,3,4,5,6,7\n" * len(values)

    monkeypatch.setattr(table_csv, "BLOCK", 14)
    monkeypatch.setattr(table_csv, "csv_block", fail_on_the_second)
    with pytest.raises(OSError, match="disk full"):
        res.to_csv(path)
    assert blocks                                          # it failed half way
    assert path.read_text(encoding="utf-8") == "the old file\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]


def test_csv_replaces_an_existing_file(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("x" * 10_000, encoding="utf-8")
    res = Results([0.0], {"a.x": [2.5]})
    assert res.to_csv(str(path)) == path
    assert path.read_text(encoding="utf-8") == "t,a.x\n0,2.5\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]


@pytest.mark.parametrize("patterns, expected", [
    (["crank.*"], ["crank.x", "crank.fi"]),
    (["*.Fx"], ["guide.Fx", "rod.Fx"]),
    (["Fx"], ["guide.Fx", "rod.Fx"]),                     # bare name = every *.Fx
    (["f(t)", "crank.fi"], ["crank.fi", "motor.f(t)"]),
    (["spring.Força"], ["spring.Força"]),
    (None, COLUMNS),
])
def test_output_patterns(patterns, expected):
    assert select_columns(COLUMNS, patterns) == expected


def test_pattern_matching_nothing_is_a_model_error():
    with pytest.raises(ModelError, match=r"'Fy' matches no variable.*\n.*did you mean 'crank.fi'"):
        select_columns(COLUMNS, ["Fy", "crank.fj"])


def test_run_outputs_selects_and_computes_only_those(examples):
    res = pam2exu.run(examples / "slider_crank.toml", analysis="kinematic", steps=20,
                      outputs=["slider.x", "Df(t)"])
    assert res.columns == ["slider.x", "motor.Df(t)"]
    assert res.units == {"t": "s", "slider.x": "m", "motor.Df(t)": "rad/s"}
    assert len(res) == 21


def test_the_analysis_is_a_name_and_its_declaration():
    """``analysis`` is the name (what files and summaries say), ``analysis_type`` the
    registry's declaration of that name (a Catalan name too); given the declaration, the
    table keeps its name; a table that does not know (read from CSV) has None."""
    from pam2exu.registry import ANALYSES
    res = Results([0.0], {"a.x": [1.0]}, analysis=ANALYSES["clearance"])
    assert res.analysis == "clearance" and res.analysis_type is ANALYSES["clearance"]
    assert res.select(["a.x"]).analysis_type is ANALYSES["clearance"]
    catalan = Results([0.0], {"a.x": [1.0]}, analysis="cinematica")
    assert catalan.analysis == "cinematica" and catalan.analysis_type is ANALYSES["kinematic"]
    assert Results([0.0], {"a.x": [1.0]}).analysis_type is None
