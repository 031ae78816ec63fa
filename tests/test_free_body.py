"""Free-body sketches (docs/make_free_body.py): one per element type that reports a
force or a torque, each arrow labelled with the output's PAM name and pointing in its
positive sense.

The sign conventions checked here are written out independently of the module, from
docs/model-format.md ("Output variables") and docs/analyses.md ("Reactions"), which
tests/analyses/test_reactions.py checks against closed forms:
- fixed: Fx, Fy, Mz the fixed solid receives, at its local origin O, global basis;
- revolute: Fx, Fy that solid 1 exerts on solid 2 at the joint, global basis (solid 1
  receives the opposite);
- prismatic: Fnormal along solid 2's line turned +90°, Mz counter-clockwise, at the
  defining point D of solid 2's line;
- pin_slot: Fnormal along the guide's x direction turned +90°, at the pin;
- transmission: Parell counter-clockwise on solid 2, −T·Parell on solid 1, (T−1)·Parell on
  the arm;
- spring: Força > 0 pulls P and Q towards each other;
- torsional_spring: Parell > 0 counter-clockwise on solid 1, clockwise on solid 2;
- angular_actuator: Mz counter-clockwise on solid 2, the opposite on solid 1;
- linear_actuator: Força > 0 pushes P and Q apart, reported at Q with x' from P to Q;
- torsor (applied, no output): Fx, Fy along x, y (axes = "global") or along the solid's
  x', y' (axes = "solid"), M counter-clockwise.
"""
import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pam2exu.elements import ELEMENTS, FORCE
from pam2exu.results.plot import PictureError

ROOT = Path(__file__).resolve().parents[1]


def _make_free_body():
    """docs/make_free_body.py, loaded by its path (docs/ is not a package; as
    tests/test_api_docs.py loads docs/make_api.py)."""
    spec = importlib.util.spec_from_file_location("make_free_body",
                                                  ROOT / "docs" / "make_free_body.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_free_body"] = module      # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


free_body = _make_free_body()
FREE_BODY_TYPES, free_body_sketch = free_body.FREE_BODY_TYPES, free_body.free_body_sketch
PNG = b"\x89PNG\r\n\x1a\n"
PIXELS = (round(free_body.SIZE[0] * free_body.DPI), round(free_body.SIZE[1] * free_body.DPI))
DOCS_IMG = ROOT / "docs" / "img"
#: the torsor reports nothing; its sketch shows its applied loads, C = [Fx, Fy, M]
APPLIED = {"torsor": ["Fx", "Fy", "M"]}


def _force_outputs(cls) -> list[str]:
    return [v.name for v in cls.outputs if v.level == FORCE]


def _reporting_types() -> set[str]:
    """Element types whose class declares a reaction (``wrench``) or a force output."""
    return {t for t, cls in ELEMENTS.items()
            if any(name is not None for name in cls.wrench) or _force_outputs(cls)}


@pytest.fixture(scope="module")
def sketches():
    """type -> (Figure, FreeBody) for every sketch."""
    return {t: free_body.free_body_figure(t) for t in FREE_BODY_TYPES}


# ---- which types ---------------------------------------------------------------------------

def test_every_type_that_reports_a_force_has_a_sketch():
    """A new element type with a reaction or a force output fails here until it has a
    sketch; the only other sketch is the applied torsor's."""
    reporting = _reporting_types()
    assert reporting <= set(FREE_BODY_TYPES), f"no sketch for {reporting - set(FREE_BODY_TYPES)}"
    assert set(FREE_BODY_TYPES) - reporting == set(APPLIED)
    assert len(FREE_BODY_TYPES) == len(set(FREE_BODY_TYPES))
    assert list(FREE_BODY_TYPES) == [t for t in ELEMENTS if t in FREE_BODY_TYPES]


def test_an_unknown_type_is_a_picture_error(tmp_path):
    with pytest.raises(PictureError, match="revolute"):
        free_body_sketch("revolut", tmp_path / "x.png")


# ---- labels --------------------------------------------------------------------------------

@pytest.mark.parametrize("element_type", FREE_BODY_TYPES)
def test_output_arrows_are_labelled_with_exactly_the_force_outputs(sketches, element_type):
    fig, drawn = sketches[element_type]
    cls = ELEMENTS[element_type]
    assert sorted(drawn.labels) == sorted(_force_outputs(cls))
    assert drawn.labels == drawn.outputs
    # the wrench names are force outputs too (a constraint element reports nothing else)
    assert {n for n in cls.wrench if n is not None} <= set(drawn.outputs)
    assert drawn.applied == APPLIED.get(element_type, [])
    # every arrow drawn is one of these, and every label is on the picture
    kinds = {"outputs": drawn.outputs, "others": drawn.others, "applied": drawn.applied}
    for a in [*drawn.arrows, *drawn.turns]:
        assert a.label in kinds[a.kind]
    texts = {t.get_text() for t in fig.axes[0].texts}
    assert set(drawn.outputs + drawn.others + drawn.applied + drawn.dimensions) <= texts
    # what the other bodies receive is written with the output's own name
    for label in drawn.others:
        assert any(name in label for name in drawn.outputs), label
    # the dimensions are the element's position outputs (or its law)
    positions = {v.name for v in cls.outputs if v.level != FORCE}
    assert set(drawn.dimensions) <= positions


# ---- senses --------------------------------------------------------------------------------

def _arrow(drawn, label, on):
    found = [a for a in drawn.arrows if a.label == label and a.on == on]
    assert len(found) == 1, (label, on, drawn.arrows)
    a = found[0]
    d = np.subtract(a.tip, a.tail)
    return np.array(a.tail), d / np.hypot(*d)


def _turn(drawn, label, on):
    found = [t for t in drawn.turns if t.label == label and t.on == on]
    assert len(found) == 1, (label, on, drawn.turns)
    return np.array(found[0].centre), found[0].ccw


def _basis(drawn, names):
    found = [b for b in drawn.bases if b[2] == names]
    assert len(found) == 1, (names, drawn.bases)
    return np.array(found[0][0]), np.array(found[0][1])


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.hypot(*v)


def _turned(v):
    """v turned by +90°."""
    return np.array([-v[1], v[0]])


X, Y = np.array([1.0, 0.0]), np.array([0.0, 1.0])
close = np.testing.assert_allclose


def _fixed(d):
    O = np.array(d.points["O"])
    for label, axis in (("Fx", X), ("Fy", Y)):
        tail, u = _arrow(d, label, "fixed solid")
        close(tail, O)
        close(u, axis, atol=1e-12)
    c, ccw = _turn(d, "Mz", "fixed solid")
    close(c, O)
    assert ccw
    close(_basis(d, ("x", "y"))[1], X)


def _revolute(d):
    tx, ux = _arrow(d, "Fx", "solid 2")
    ty, uy = _arrow(d, "Fy", "solid 2")
    close(tx, ty)
    close(ux, X, atol=1e-12)
    close(uy, Y, atol=1e-12)
    close(_arrow(d, "Fx", "solid 1")[1], -X, atol=1e-12)
    close(_arrow(d, "Fy", "solid 1")[1], -Y, atol=1e-12)
    close(_basis(d, ("x", "y"))[1], X)


def _prismatic(d):
    D = np.array(d.points["D"])
    p, x = _basis(d, ("x'", "y'"))
    close(p, D)
    tail, u = _arrow(d, "Fnormal", "solid 2")
    close(tail, D)
    close(u, _turned(x), atol=1e-12)
    c, ccw = _turn(d, "Mz", "solid 2")
    close(c, D)
    assert ccw


def _pin_slot(d):
    pin = np.array(d.points["pin"])
    p, x = _basis(d, ("x'", "y'"))
    close(p, pin)
    tail, u = _arrow(d, "Fnormal", "pin (solid 2)")
    close(tail, pin)
    close(u, _turned(x), atol=1e-12)


def _transmission(d):
    assert _turn(d, "Parell", "solid 2")[1]
    assert _turn(d, "−T·Parell", "solid 1")[1]
    assert _turn(d, "(T−1)·Parell", "arm")[1]


def _torsor(d):
    for label, axis in (("Fx", X), ("Fy", Y)):
        close(_arrow(d, label, 'axes = "global"')[1], axis, atol=1e-12)
    x = _basis(d, ("x'", "y'"))[1]
    assert abs(x[1]) > 0.1                       # the solid's axes are turned
    close(_arrow(d, "Fx", 'axes = "solid"')[1], x, atol=1e-12)
    close(_arrow(d, "Fy", 'axes = "solid"')[1], _turned(x), atol=1e-12)
    assert _turn(d, "M", 'axes = "global"')[1] and _turn(d, "M", 'axes = "solid"')[1]


def _spring(d):
    P, Q = np.array(d.points["P"]), np.array(d.points["Q"])
    tail, u = _arrow(d, "Força", "solid 1")          # attraction: P pulled towards Q
    close(tail, P)
    close(u, _unit(Q - P), atol=1e-12)
    tail, u = _arrow(d, "Força", "solid 2")          # and Q towards P
    close(tail, Q)
    close(u, _unit(P - Q), atol=1e-12)


def _torsional_spring(d):
    assert _turn(d, "Parell", "solid 1")[1]          # counter-clockwise on solid 1
    assert not _turn(d, "Parell", "solid 2")[1]      # clockwise on solid 2


def _angular_actuator(d):
    assert _turn(d, "Mz", "solid 2")[1]
    assert not _turn(d, "Mz", "solid 1")[1]          # solid 1 receives −Mz


def _linear_actuator(d):
    P, Q = np.array(d.points["P"]), np.array(d.points["Q"])
    p, x = _basis(d, ("x'", "y'"))                 # reported at Q, x' from P to Q
    close(p, Q)
    close(x, _unit(Q - P), atol=1e-12)
    tail, u = _arrow(d, "Força", "solid 2")          # repulsion: Q pushed away from P
    close(tail, Q)
    close(u, x, atol=1e-12)
    tail, u = _arrow(d, "Força", "solid 1")          # and P away from Q
    close(tail, P)
    close(u, -x, atol=1e-12)


SENSES = {f.__name__[1:]: f for f in (_fixed, _revolute, _prismatic, _pin_slot, _transmission,
                                      _torsor, _spring, _torsional_spring, _angular_actuator,
                                      _linear_actuator)}


def test_every_sketch_has_its_sense_check():
    assert set(SENSES) == set(FREE_BODY_TYPES)


@pytest.mark.parametrize("element_type", FREE_BODY_TYPES)
def test_arrows_point_in_the_positive_sense(sketches, element_type):
    SENSES[element_type](sketches[element_type][1])


# ---- files ---------------------------------------------------------------------------------

def _check_png(path: Path) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG
    with Image.open(path) as im:
        im.verify()
    with Image.open(path) as im:
        assert im.size == PIXELS
        rgb = np.asarray(im.convert("RGB"), dtype=int)
    assert (rgb[0, 0] == 255).all()                          # white background
    ink = np.any(rgb < 200, axis=2).mean()                   # pixels that are drawn
    assert 0.02 < ink < 0.5, f"{path.name}: {ink:.1%} of the pixels are drawn"
    assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 20   # colours, not one blot


def test_script_writes_every_sketch(tmp_path, capsys):
    out = tmp_path / "img"
    assert free_body.main([str(out)]) == 0
    written = sorted(p.name for p in out.iterdir())
    assert written == sorted(f"fbd_{t}.png" for t in FREE_BODY_TYPES)
    for name in written:
        _check_png(out / name)
    assert capsys.readouterr().out.split() == [str(out / f"fbd_{t}.png")
                                               for t in FREE_BODY_TYPES]


def test_script_writes_the_sketches_named(tmp_path, monkeypatch):
    """``python docs/make_free_body.py docs/img TYPE``: a new type's sketch alone (the
    drawing itself stubbed: the test above draws every one)."""
    asked = []
    monkeypatch.setattr(free_body, "free_body_sketch",
                        lambda t, path: asked.append((t, path)) or free_body.FreeBody(t))
    assert free_body.main([str(tmp_path), "spring"]) == 0
    assert asked == [("spring", tmp_path / "fbd_spring.png")]


def test_free_body_sketch_returns_what_it_drew(tmp_path):
    drawn = free_body_sketch("prismatic", tmp_path / "p.png")
    assert drawn.path == tmp_path / "p.png" and drawn.type == "prismatic"
    assert drawn.labels == ["Fnormal", "Mz"]
    _check_png(drawn.path)


@pytest.mark.parametrize("element_type", FREE_BODY_TYPES)
def test_docs_have_every_sketch(element_type):
    """docs/img/fbd_<type>.png (regenerate: python docs/make_free_body.py docs/img)."""
    path = DOCS_IMG / f"fbd_{element_type}.png"
    assert path.is_file(), f"missing {path}: run python docs/make_free_body.py docs/img"
    assert path.stat().st_size <= 40_000
    _check_png(path)


def test_an_unknown_image_format_is_a_picture_error(tmp_path):
    with pytest.raises(PictureError, match="suffix"):
        free_body_sketch("spring", tmp_path / "x.abc")
