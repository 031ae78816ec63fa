"""docs/natural-coordinates.md: it is what docs/make_natural.py writes, and its numbers and
equations are right.

The page's tables are parsed back from the Markdown and checked against computations that
do not go through the code that printed them:

* coordinates and named points: the points x + R(fi) s of Exudyn's assembly, and their
  velocities and accelerations from the Exudyn backend's kinematic run (native pass);
* the Jacobian: central differences of ``Terms.residual``;
* γ: minus the second central difference of Φ along ż (żᵀ Φ_zz ż), plus the law's f″;
* the mass matrix: Σ ½ m |v_G|² + ½ I_G ω² of each solid, from its m, I_G and cog, for random
  rigid velocities;
* the equations, γ and the pose forms as printed: evaluated as text (a small translator to
  Python below) at random z, ż against ``Terms`` and ``pose_forms``.
"""
from __future__ import annotations

import importlib.util
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu.kinematics import column

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "natural-coordinates.md"
MODEL = ROOT / "examples" / "four_bar.toml"


def _load_generator():
    spec = importlib.util.spec_from_file_location("make_natural",
                                                  ROOT / "docs" / "make_natural.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module            # its dataclass looks its module up
    spec.loader.exec_module(module)
    return module


make_natural = _load_generator()


@pytest.fixture(scope="module")
def worked():
    return make_natural.compute()


@pytest.fixture(scope="module")
def text():
    return PAGE.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def exudyn_run():
    """The four-bar's first step on the Exudyn backend: x, y, fi and their rates at t = 0."""
    return pam2exu.run(MODEL, analysis="kinematic", steps=1, backend="exudyn")


# ---- reading the page ----------------------------------------------------------------------

def table_after(text: str, heading: str, skip: int = 0) -> tuple[list[str], list[list[str]]]:
    """(header, rows) of the (skip+1)-th Markdown table after the heading line."""
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.strip() == heading)
    found = []
    while k < len(lines) and len(found) <= skip:
        if lines[k].startswith("|"):
            block = []
            while k < len(lines) and lines[k].startswith("|"):
                block.append([c.strip().replace("\\|", "|")
                              for c in re.split(r"(?<!\\)\|", lines[k])[1:-1]])
                k += 1
            found.append(block)
        k += 1
    block = found[skip]
    return block[0], block[2:]


def number(cell: str) -> float:
    return make_natural.parse_num(cell)


def pair(cell: str) -> np.ndarray:
    """'(0.1, −0.3)' -> array."""
    return np.array([number(v) for v in cell.strip("()").split(",")])


#: printed numbers have 6 significant digits
PRINTED = 6e-6


def close_printed(printed: float, exact: float, scale: float = 0.0) -> bool:
    return abs(printed - exact) <= PRINTED * max(abs(exact), scale) + 1e-12


# ---- (a) the page is generated -----------------------------------------------------------

def test_page_is_what_the_generator_writes(worked, text):
    assert text == make_natural.render(worked), \
        "docs/natural-coordinates.md is stale: run `python docs/make_natural.py` and commit it"


def test_generator_is_deterministic(worked):
    page = make_natural.render(worked)
    assert page == make_natural.render(worked)
    assert " at 0x" not in page and str(ROOT) not in page


def test_check_option_reports_a_stale_page(tmp_path, monkeypatch, capsys, worked):
    page = tmp_path / "natural-coordinates.md"
    monkeypatch.setattr(make_natural, "OUTPUT", page)
    monkeypatch.setattr(make_natural, "compute", lambda path=None: worked)
    page.write_text(make_natural.render(worked).replace("0.1225", "0.1226"), encoding="utf-8")
    assert make_natural.main(["--check"]) == 1
    assert "is stale" in capsys.readouterr().err
    assert make_natural.main([]) == 0
    assert make_natural.main(["--check"]) == 0


def test_page_links_and_sections(text):
    assert "[verify.md](verify.md)" in text
    assert "../examples/natural_jacobian.py" in text
    for heading in ("## What natural coordinates are", "## How each element type is converted",
                    "## The exact velocity term γ", "## How x, y, fi come back",
                    "## The constant mass matrix", "## Reading `pam2exu verify`"):
        assert heading in text
    anchors = {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
               for h in re.findall(r"^#+ (.+)$", text, re.M)}
    links = re.findall(r"\]\(#([^)]+)\)", text)
    assert links and [link for link in links if link not in anchors] == []


def test_every_element_type_has_a_row(text):
    _, rows = table_after(text, "## How each element type is converted")
    assert [r[0].strip("`") for r in rows] == list(pam2exu.ELEMENTS)
    for row in rows:
        assert row[3] and not row[3].startswith("Declare"), row


# ---- (b) the numbers ---------------------------------------------------------------------

def _local_point(q, solid: int, local) -> np.ndarray:
    x, y, fi = (q[column(solid, k)] for k in range(3))
    c, s = math.cos(fi), math.sin(fi)
    return np.array([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])


def _point_rates(run, model, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, acceleration at t = 0 of the model point 'solid.P' from the native
    pass: r = x + R s, v = ẋ + ω Ω R s, a = ẍ + α Ω R s − ω² R s."""
    solid, point = name.split(".")
    s = model[solid].points[point]
    get = lambda v: float(run[f"{solid}.{v}"][0])      # noqa: E731
    fi, w, a = get("fi"), get("Dfi"), get("DDfi")
    Rs = np.array([math.cos(fi) * s[0] - math.sin(fi) * s[1],
                   math.sin(fi) * s[0] + math.cos(fi) * s[1]])
    perp = np.array([-Rs[1], Rs[0]])
    return (np.array([get("x"), get("y")]) + Rs, np.array([get("Dx"), get("Dy")]) + w * perp,
            np.array([get("DDx"), get("DDy")]) + a * perp - w * w * Rs)


def test_coordinates_table_against_the_exudyn_run(text, exudyn_run):
    """z, ż, z̈ of each basic point are those of every model point it is, from the Exudyn
    backend's x, y, fi and rates; the angle coordinate is the crank's fi."""
    model = pam2exu.load(MODEL)
    header, rows = table_after(text, "### Its natural coordinates")
    assert header[-3:] == ["z", "ż", "z̈"] and len(rows) == 5
    checked = 0
    for row in rows:
        printed = [number(c) for c in row[-3:]]
        what = row[4]
        if row[3] == "angle":
            solid = what.rsplit(" ", 1)[1]
            exact = [float(exudyn_run[f"{solid}.{v}"][0]) for v in ("fi", "Dfi", "DDfi")]
        else:
            axis, _, names = what.partition(" of ")
            k = "xy".index(axis)
            values = [_point_rates(exudyn_run, model, n) for n in names.split(" = ")]
            assert len(values) == 2                     # each joint point is on two solids
            for other in values[1:]:
                for u, v in zip(values[0], other):
                    np.testing.assert_allclose(u, v, rtol=0, atol=1e-9)
            exact = [v[k] for v in values[0]]
        scales = (0.4, 0.4 * 2 * math.pi, 0.4 * (2 * math.pi) ** 2)   # L, L ω, L ω²
        for p, e, s in zip(printed, exact, scales):
            assert close_printed(p, e, s), (row, p, e)
        checked += 1
    assert checked == 5


def test_named_points_table(text, exudyn_run, worked):
    """Each named point's (a, b) make a d + b Ω d = s − s_p (d, s_p from the frames table),
    and its position at t = 0 is x + R(fi) s of the assembly."""
    model = pam2exu.load(MODEL)
    _, frames = table_after(text, "### Base point and base vector of each solid")
    frame = {r[0]: (pair(r[2]), pair(r[4])) for r in frames}
    _, rows = table_after(text, "### Base point and base vector of each solid", skip=1)
    assert len(rows) == sum(len(s.points) for s in model.solids)
    for row in rows:
        solid, point = row[0].split(".")
        s, a, b = pair(row[1]), number(row[2]), number(row[3])
        sp, d = frame[solid]
        w = a * d + b * np.array([-d[1], d[0]])
        np.testing.assert_allclose(w, s - sp, rtol=0, atol=PRINTED * 0.4)
        exact = _point_rates(exudyn_run, model, row[0])[0]
        assert all(close_printed(p, e, 0.4) for p, e in zip(pair(row[5]), exact)), row


def test_jacobian_is_the_derivative_of_the_residual(text, worked):
    """Central differences of Φ (exact for the quadratic rows, O(h²) for the angle tie)."""
    terms, z0, t = worked.form.terms, worked.z0, np.array([0.0])
    h = 1e-6
    fd = np.empty_like(worked.jacobian)
    for k in range(len(z0)):
        e = np.zeros_like(z0)
        e[k] = h
        fd[:, k] = (terms.residual(t, (z0 + e)[None])[0]
                    - terms.residual(t, (z0 - e)[None])[0]) / (2 * h)
    scale = np.abs(fd).max()
    np.testing.assert_allclose(worked.jacobian, fd, rtol=0, atol=1e-8 * scale)
    header, rows = table_after(text, "### The Jacobian at t = 0")
    assert header[2:] == worked.names
    page = np.array([[number(c) for c in row[2:]] for row in rows])
    assert page.shape == fd.shape
    np.testing.assert_allclose(page, fd, rtol=PRINTED, atol=1e-8 * scale)
    dots = np.array([[c == "·" for c in row[2:]] for row in rows])
    assert dots.any() and np.all(np.abs(fd[dots]) < 1e-9 * scale)


def test_gamma_is_minus_the_second_derivative_along_the_velocity(text, worked):
    """γ = g″ − żᵀ Φ_zz ż, the second term as the second central difference of Φ along ż,
    g″ the motor law's f″ (the only row with a law); and ż solves Φ_z ż = g′."""
    terms, z0, zd, t = worked.form.terms, worked.z0, worked.zd0, np.array([0.0])
    h = 1e-3
    phi = lambda z: terms.residual(t, z[None])[0]                     # noqa: E731
    second = (phi(z0 + h * zd) - 2 * phi(z0) + phi(z0 - h * zd)) / h**2
    motor = worked.mech.elements[-1].time_law()
    g2 = np.zeros_like(second)
    g2[-1] = motor(0.0)[2]
    gamma = g2 - second
    scale = np.abs(gamma).max()
    np.testing.assert_allclose(worked.gamma, gamma, rtol=0, atol=1e-7 * scale)
    _, rows = table_after(text, "### Velocities and accelerations at t = 0")
    assert [number(r[-1]) for r in rows] == pytest.approx(gamma, rel=PRINTED, abs=1e-9 * scale)
    assert [number(r[2]) for r in rows] == pytest.approx([0, 0, 0, 0, motor(0.0)[1]])
    np.testing.assert_allclose(worked.jacobian @ zd, worked.rhs, atol=1e-12)


def _rigid_velocity(worked, solid: int, rng) -> tuple[np.ndarray, float, np.ndarray]:
    """A random rigid velocity (v_origin, ω) of one solid at the assembly, and ż with the
    velocities it gives that solid's basic points (other coordinates random: they do not
    enter this solid's share of M); its angle coordinate, if any, is ω. A solid pinned to
    the ground turns about that point (a constant of the formulation)."""
    f = worked.form
    q = worked.q0
    origin = _local_point(q, solid, (0.0, 0.0))
    v0, w = rng.normal(size=2), rng.normal()
    zd = rng.normal(size=f.nz)
    own = f.own.get(solid, [])
    for loc, vec in own:
        if set(vec.x.linear()) <= {-1}:                # a ground point: at rest
            r = _local_point(q, solid, loc) - origin
            v0 = -w * np.array([-r[1], r[0]])
    for loc, vec in own:
        lin = vec.x.linear()
        if set(lin) <= {-1}:
            continue                                   # a ground point: a constant
        r = _local_point(q, solid, loc) - origin
        ix, iy = next(iter(lin)), next(iter(vec.y.linear()))
        zd[ix], zd[iy] = v0 + w * np.array([-r[1], r[0]])
    if f.frames[solid].angle is not None:
        zd[f.frames[solid].angle] = w
    return v0, w, zd


def test_mass_matrix_gives_the_kinetic_energy(text, worked):
    """For random rigid velocities of each solid, ½ żᵀ M_i ż = ½ m |v_G|² + ½ I_G ω² to
    1e-13 (v_G = v_O + ω Ω R(fi) s_G; m, I_G, s_G from the model file); M = Σ M_i; the page's
    table is M to its 6 digits; at t = 0 the whole mechanism's T is that of the native
    velocities."""
    import tomllib
    data = tomllib.loads(MODEL.read_text(encoding="utf-8"))
    rng = np.random.default_rng(12)
    f = worked.form
    total = np.zeros_like(worked.mass)
    for i, solid in enumerate(data["solid"]):
        if i in f.grounds:
            continue
        Mi = f.mass_matrix(solids=[i])
        total += Mi
        m, inertia, cog = solid["mass"], solid["inertia"], solid["cog"]
        fi = worked.q0[column(i, 2)]
        Rg = np.array([math.cos(fi) * cog[0] - math.sin(fi) * cog[1],
                       math.sin(fi) * cog[0] + math.cos(fi) * cog[1]])
        for _ in range(5):
            v0, w, zd = _rigid_velocity(worked, i, rng)
            vG = v0 + w * np.array([-Rg[1], Rg[0]])
            T = 0.5 * m * vG @ vG + 0.5 * inertia * w * w
            assert 0.5 * zd @ Mi @ zd == pytest.approx(T, rel=1e-13, abs=0), solid["name"]
    np.testing.assert_allclose(total, worked.mass, rtol=0, atol=1e-15)
    header, rows = table_after(text, "### Its constant mass matrix", skip=1)
    assert header[1:] == worked.names
    page = np.array([[number(c) for c in row[1:]] for row in rows])
    np.testing.assert_allclose(page, worked.mass, rtol=PRINTED, atol=1e-12)


def test_kinetic_energy_at_t0_is_the_native_one(text, worked, exudyn_run):
    """T = ½ żᵀ M ż printed on the page equals Σ ½ m |v_G|² + ½ I_G ω² of the Exudyn run."""
    model = pam2exu.load(MODEL)
    T = 0.0
    for s in model.solids:
        if s.mass or s.inertia:
            fi, w = float(exudyn_run[f"{s.name}.fi"][0]), float(exudyn_run[f"{s.name}.Dfi"][0])
            g = s.cog
            Rg = np.array([math.cos(fi) * g[0] - math.sin(fi) * g[1],
                           math.sin(fi) * g[0] + math.cos(fi) * g[1]])
            vG = np.array([float(exudyn_run[f"{s.name}.Dx"][0]),
                           float(exudyn_run[f"{s.name}.Dy"][0])]) + w * np.array([-Rg[1], Rg[0]])
            T += 0.5 * s.mass * vG @ vG + 0.5 * s.inertia * w * w
    assert 0.5 * worked.zd0 @ worked.mass @ worked.zd0 == pytest.approx(T, rel=1e-10)
    printed = re.search(r"T = ½ żᵀ M ż = (\S+) J", text).group(1)
    assert close_printed(number(printed), T)


# ---- (c) the equations as printed --------------------------------------------------------

def to_python(expression: str, names: list[str]) -> str:
    """A printed expression as Python: symbols to z[k] (zd[k] when primed), '·' and implied
    products to '*', '²' to '**2', '−' to '-', sin/cos to math's."""
    out = expression.replace("−", "-").replace("·", "*").replace("²", "**2")
    out = out.replace("f″(t)", "ddf").replace("f(t)", "f")
    for k in sorted(range(len(names)), key=lambda k: -len(names[k])):
        out = out.replace(f"{names[k]}′", f"zd[{k}]").replace(names[k], f"z[{k}]")
    out = re.sub(r"(\d|\))\s+(?=[z(a-z])", r"\1*", out)       # '10 (…)', '2 z[0]'
    return out


def evaluate(expression: str, names, z, zd=None, f=0.0, ddf=0.0) -> float:
    return eval(to_python(expression, names), {"sin": math.sin, "cos": math.cos},  # noqa: S307
                {"z": z, "zd": zd, "f": f, "ddf": ddf})


def test_the_translator_can_fail():
    names = ["A.x", "crank.fi"]
    assert evaluate("10 (A.x·sin(crank.fi) − 2)", names, [0.5, 0.3]) == \
        pytest.approx(10 * (0.5 * math.sin(0.3) - 2))
    assert evaluate("−2 (A.x′² + crank.fi′)", names, [0, 0], [3.0, 1.0]) == pytest.approx(-20)
    assert evaluate("(A.x − 0.4)/0.3", names, [1.0, 0]) == pytest.approx(2.0)


def test_printed_equations_are_the_residual(text, worked):
    """Left side − right side of every printed equation = Terms.residual at random z, t
    (f(t) the motor's law), to the printed digits."""
    rng = np.random.default_rng(3)
    _, rows = table_after(text, "### Its equations")
    law = worked.mech.elements[-1].time_law()
    for _ in range(5):
        z, t = rng.normal(size=worked.form.nz), rng.uniform(0, 1)
        phi = worked.form.terms.residual(np.array([t]), z[None])[0]
        f = float(law(t)[0])
        for row, value in zip(rows, phi):
            left, right = row[2].split(" = ")
            got = (evaluate(left, worked.names, z, f=f)
                   - evaluate(right, worked.names, z, f=f))
            assert got == pytest.approx(value, rel=1e-5, abs=1e-5), row


def test_printed_gamma_is_terms_gamma(text, worked):
    rng = np.random.default_rng(4)
    _, rows = table_after(text, "### Velocities and accelerations at t = 0")
    law = worked.mech.elements[-1].time_law()
    for _ in range(5):
        z, zd, t = rng.normal(size=worked.form.nz), rng.normal(size=worked.form.nz), 0.3
        gamma = worked.form.terms.gamma(np.array([t]), z[None], zd[None])[0]
        for row, value in zip(rows, gamma):
            got = evaluate(row[3], worked.names, z, zd, ddf=float(law(t)[2]))
            assert got == pytest.approx(value, rel=1e-5, abs=1e-5), row


def test_printed_pose_forms_are_k(text, worked):
    """x, y, cos fi, sin fi as printed = K [z; 1] (``pose_forms``) at random z; and K at
    the assembly gives x, y, cos fi, sin fi of the assembly."""
    K = worked.form.pose_forms()
    pose = K @ np.r_[worked.z0, 1.0]
    for i in range(len(worked.mech.solids)):
        x, y, fi = (worked.q0[column(i, k)] for k in range(3))
        np.testing.assert_allclose(pose[4 * i:4 * i + 4], [x, y, math.cos(fi), math.sin(fi)],
                                   atol=1e-12)
    rng = np.random.default_rng(5)
    _, rows = table_after(text, "## How x, y, fi come back")
    for _ in range(3):
        z = rng.normal(size=worked.form.nz)
        pose = K @ np.r_[z, 1.0]
        for i, row in enumerate(rows):
            got = [evaluate(c, worked.names, z) for c in row[1:5]]
            np.testing.assert_allclose(got, pose[4 * i:4 * i + 4], rtol=1e-5, atol=1e-5)


def test_formatter_completes_squares_and_falls_back():
    """The formatter on its own: a sum of squares, a bilinear form (no squares), a sine."""
    from pam2exu.backend.natural.forms import Expr, Vec
    names = ["P.x", "P.y", "Q.x", "Q.y", "fi"]
    P = Vec(Expr.coordinate(0), Expr.coordinate(1))
    Q = Vec(Expr.coordinate(2), Expr.coordinate(3))
    gap = Q - P
    assert make_natural.equation(gap.dot(gap), 4.0, 1, names) == \
        "(P.x − Q.x)² + (P.y − Q.y)² = 4"
    assert make_natural.equation(P.dot(Q.perp()), 0.0, 1, names) == "−P.x·Q.y + P.y·Q.x = 0"
    tie = P.aligned(4, 0.0)
    assert make_natural.equation(tie, 0.0, 1, names) == "P.x·sin(fi) − P.y·cos(fi) = 0"
    assert make_natural.vector(Q - P, names, [(0, 1, "P"), (2, 3, "Q")]) == "Q − P"
    assert make_natural.vector(P.perp() * 2.0 + Vec.constant((1, 0)), names,
                               [(0, 1, "P"), (2, 3, "Q")]) == "2 ΩP + (1, 0)"
