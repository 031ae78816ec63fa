"""Write docs/natural-coordinates.md, natural coordinates on the shipped four-bar, from the code.

    python docs/make_natural.py            # (re)write docs/natural-coordinates.md
    python docs/make_natural.py --check    # exit 1 when the page differs from what it writes

Every table, equation and number of the page comes from the natural-coordinate backend
(``pam2exu.backend.natural.Formulation``) applied to examples/four_bar.toml at its assembled
t = 0 configuration (``pam2exu.run(..., analysis="assembly")``), and the element table from
the ``natural`` docstrings of ``pam2exu.elements.ELEMENTS``; only the prose is written here.
``compute()`` returns the unrounded numbers the tables print (tests/test_natural_docs.py checks
them against independent computations). Numbers are printed to 6 significant digits; values
below 1e-12 in size, round-off of the solvers, are printed as 0, so that the page is the same
on every machine.

Docs tooling beside docs/make_api.py: pam2exu never imports it. Run from a clone, it puts the
repository root on ``sys.path``.
"""
from __future__ import annotations

import argparse
import inspect
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "docs"):     # run from a clone without installing; docs/page.py
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

import pam2exu  # noqa: E402
from page import write_or_check  # noqa: E402  (docs/page.py)
from pam2exu.backend.natural import Formulation  # noqa: E402
from pam2exu.backend.natural import terms as terms_module  # noqa: E402
from pam2exu.backend.natural.forms import ONE, Expr, Vec  # noqa: E402
from pam2exu.elements import ELEMENTS, Element  # noqa: E402
from pam2exu.kinematics import column  # noqa: E402
from pam2exu.laws import LAWS, Law  # noqa: E402

MODEL_PATH = "examples/four_bar.toml"
OUTPUT = ROOT / "docs" / "natural-coordinates.md"
#: significant digits of the printed numbers
DIGITS = 6
#: numbers smaller than this in size are printed as 0 (round-off of the solvers)
ZERO = 1e-12
#: the time of the worked configuration [s]
T0 = 0.0
MINUS = "−"
PRIME = "′"


# ---- numbers ----------------------------------------------------------------------------------

def num(x: float, digits: int = DIGITS) -> str:
    """A number as printed on the page: 6 significant digits, '−' for minus, 0 below ZERO."""
    x = float(x)
    if abs(x) < ZERO:
        return "0"
    text = f"{x:.{digits}g}"
    if "e" in text:
        mant, exp = text.split("e")
        text = f"{mant}e{int(exp)}"
    return text.replace("-", MINUS)


def parse_num(text: str) -> float:
    """The inverse of ``num`` ('·', an entry outside the sparsity pattern, is 0)."""
    text = text.strip()
    return 0.0 if text in ("·", "") else float(text.replace(MINUS, "-"))


def _short(x: float, digits: int = 4) -> str | None:
    """x written with at most ``digits`` significant digits if that is x (to 1e-12), else None."""
    text = f"{x:.{digits}g}"
    return text if abs(float(text) - x) <= 1e-12 * abs(x) else None


def _is_integer(x: float) -> bool:
    return abs(x - round(x)) <= 1e-12 * max(1.0, abs(x))


# ---- expressions as text ----------------------------------------------------------------------

def _sum(terms: list[tuple[float, str]]) -> str:
    """Σ c·text as 'a − 2 b + 3' (text '' is the constant 1)."""
    out = []
    for c, text in terms:
        sign = MINUS if c < 0 else "+"
        c = abs(c)
        if not text:
            body = num(c)
        elif abs(c - 1.0) <= 1e-12:
            body = text
        else:
            body = f"{num(c)} {text}"
        out.append((sign, body))
    if not out:
        return "0"
    first = (MINUS if out[0][0] == MINUS else "") + out[0][1]
    return " ".join([first] + [f"{s} {b}" for s, b in out[1:]])


def _factored(terms: list[tuple[float, str]]) -> str:
    """``_sum`` with a common factor taken out when every non-constant term has the same
    size c ≠ 1: '10 (a − b)', or '(a − b)/0.35' when 1/c is a short number."""
    terms = [(c, t) for c, t in terms if abs(c) >= ZERO]
    sizes = {round(abs(c), 12) for c, t in terms if t}
    if len(sizes) != 1:
        return _sum(terms)
    c = abs(next(c for c, t in terms if t))
    if abs(c - 1.0) <= 1e-12:
        return _sum(terms)
    inner = [(k / c, t) for k, t in terms]
    negative = inner[0][0] < 0 and len(inner) > 1 and all(k < 0 for k, t in inner if t)
    if negative:                                 # '−(a + b)' reads better than '−a − b'
        inner = [(-k, t) for k, t in inner]
    body = _sum(inner)
    grouped = f"({body})" if len(inner) > 1 else body
    sign = MINUS if negative else ""
    if _is_integer(c):
        return f"{sign}{num(c)} {grouped}"
    short = _short(1.0 / c)
    if short is not None:
        return f"{sign}{grouped}/{short}"
    return f"{sign}{num(c)} {grouped}"


def _linear_terms(linear: dict, names: list[str], positive_first: bool = False):
    """[(c, name)] of a linear form {index: c} (ONE for the constant, last)."""
    variables = sorted((i for i in linear if i != ONE), key=lambda i: (
        positive_first and linear[i] < 0, i))
    out = [(linear[i], names[i]) for i in variables if abs(linear[i]) >= ZERO]
    if abs(linear.get(ONE, 0.0)) >= ZERO:
        if positive_first and out and out[0][0] < 0 and linear[ONE] > 0:
            out.insert(0, (linear[ONE], ""))      # '0.4 − B.x' rather than '−B.x + 0.4'
        else:
            out.append((linear[ONE], ""))
    return out


def linear(e: Expr | dict, names: list[str]) -> str:
    """A linear form as text, a common factor taken out: '(B.x − A.x)/0.35'."""
    lin = e.linear() if isinstance(e, Expr) else e
    return _factored(_linear_terms(lin, names, positive_first=True))


def _squares(products: dict, scale: float):
    """The quadratic part of Σ c z_a z_b (with its linear and constant terms) as a sum of
    squares d (z_k + Σ l_j z_j + l_0)², by symmetric elimination in the coordinates' order;
    (squares, constant, other products) or None when a pivot vanishes (a bilinear form)."""
    quad = sorted({i for (a, b) in products if a != ONE and b != ONE for i in (a, b)})
    if not quad:
        return None
    order = quad + [ONE]
    where = {v: k for k, v in enumerate(order)}
    S = np.zeros((len(order), len(order)))
    rest = {}
    for (a, b), c in products.items():
        if a in where and b in where:
            i, j = where[a], where[b]
            if i == j:
                S[i, i] += c
            else:
                S[i, j] += c / 2
                S[j, i] += c / 2
        else:                                    # a linear term of a coordinate not squared
            rest[(a, b)] = c
    tol = ZERO * scale
    squares = []
    for k in range(len(quad)):
        d = S[k, k]
        if abs(d) <= tol:
            if np.any(np.abs(S[k, k + 1:]) > tol):
                return None
            continue
        row = S[k, k:] / d
        squares.append((d, {order[k + j]: row[j] for j in range(len(row))
                            if abs(row[j]) > ZERO}))
        S[k:, k:] -= d * np.outer(row, row)
    return squares, S[-1, -1], rest


def _trig(kind: str, angle: str, alpha: float) -> tuple[float, str]:
    """(sign, text) of sin or cos(angle + α), quarter turns written out:
    cos(x + π/2) = −sin x, …"""
    quarter = alpha / (0.5 * math.pi)
    if abs(quarter - round(quarter)) < 1e-12:
        k = int(round(quarter)) % 4
        shift = {("sin", 0): (1, "sin"), ("sin", 1): (1, "cos"), ("sin", 2): (-1, "sin"),
                 ("sin", 3): (-1, "cos"), ("cos", 0): (1, "cos"), ("cos", 1): (-1, "sin"),
                 ("cos", 2): (-1, "cos"), ("cos", 3): (1, "sin")}[kind, k]
        return shift[0], f"{shift[1]}({angle})"
    return 1, f"{kind}({angle} {'+' if alpha > 0 else MINUS} {num(abs(alpha))})"


def _product(*factors: str) -> str:
    return "·".join(f for f in factors if f)


def _expanded(products: dict, names: list[str]) -> list[tuple[float, str]]:
    """[(c, 'a·b')] of Σ c z_a z_b, the constant as (c, '')."""
    out = []
    for (a, b), c in sorted(products.items(), key=lambda kv: (ONE in kv[0], kv[0])):
        factors = [names[i] for i in (a, b) if i != ONE]
        if len(factors) == 2 and a == b:
            factors = [f"{factors[0]}²"]
        out.append((c, _product(*factors)))
    return out


def _sine_terms(sines: dict, names: list[str]) -> list[tuple[float, str]]:
    out = []
    for (a, b, alpha), c in sorted(sines.items()):
        sign, trig = _trig("sin", names[b], alpha)
        out.append((sign * c, _product(names[a] if a != ONE else "", trig)))
    return out


def expression(e: Expr, names: list[str]) -> tuple[str, float]:
    """(text, constant) of an expression: its squares completed where it is a sum of
    squares ('(A.x − B.x)² + (A.y − B.y)²'), else its terms; the constant left over is
    returned apart (the caller moves it to the right-hand side)."""
    scale = max([abs(c) for c in e.products.values()] + [1.0])
    const = 0.0
    terms: list[tuple[float, str]] = []
    found = _squares(e.products, scale)
    if found is not None:
        squares, const, rest = found
        for d, form in squares:
            lin = _linear_terms(form, names)
            if len(lin) == 1 and abs(lin[0][0] - 1.0) <= 1e-12 and lin[0][1]:
                terms.append((d, f"{lin[0][1]}²"))
            else:
                terms.append((d, f"({_sum(lin)})²"))
        terms += _expanded(rest, names)
    else:
        products = dict(e.products)
        const = products.pop((ONE, ONE), 0.0)
        terms += _expanded(products, names)
    if abs(const) <= ZERO * scale:
        const = 0.0
    terms += _sine_terms(e.sines, names)
    return _factored(terms), const


def kind_of(e: Expr) -> str:
    """'linear', 'quadratic' or 'trigonometric' (an angle tied to a vector)."""
    if e.sines:
        return "trigonometric"
    return "linear" if e.is_linear else "quadratic"


def target_text(target, power: int, const: float = 0.0) -> str:
    """The right-hand side: a number, or f(t) / f(t)² for a law (minus the constant the
    left-hand side held)."""
    if isinstance(target, Law):
        law = "f(t)" if power == 1 else "f(t)²"
        return law if not const else f"{law} {MINUS if const > 0 else '+'} {num(abs(const))}"
    return num(float(target) ** power - const)


def equation(e: Expr, target, power: int, names: list[str]) -> str:
    """'(A.x − B.x)² + (A.y − B.y)² = 0.1225'."""
    text, const = expression(e, names)
    return f"{text} = {target_text(target, power, const)}"


def gamma_text(e: Expr, target, power: int, names: list[str]) -> str:
    """γ of one equation, written out: g''(t) − ż ᵀ (∂²Φ/∂z²) ż (module doc of terms)."""
    primed = [f"{n}{PRIME}" for n in names]
    quad = Expr({k: c for k, c in e.products.items() if ONE not in k})
    parts = []
    if isinstance(target, Law):
        parts.append("f″(t)" if power == 1 else "2 (f′(t)² + f(t) f″(t))")
    if quad.products:
        text, _ = expression(quad, primed)
        parts.append(f"{MINUS}2 ({text})" if " " in text else f"{MINUS}2 {text}")
    trig = []
    for (a, b, alpha), c in sorted(e.sines.items()):
        # c z_a sin(z_b + α): γ gets −2 c ż_a ż_b cos(z_b + α) + c z_a ż_b² sin(z_b + α)
        s1, cos_ = _trig("cos", names[b], alpha)
        s2, sin_ = _trig("sin", names[b], alpha)
        if a != ONE:
            trig.append((-2 * c * s1, _product(primed[a], primed[b], cos_)))
        trig.append((c * s2, _product(names[a] if a != ONE else "", f"{primed[b]}²", sin_)))
    if trig:
        parts.append(_sum(trig))
    if not parts:
        return "0"
    text = parts[0]
    for p in parts[1:]:
        text += f" {MINUS} {p[1:]}" if p.startswith(MINUS) else f" + {p}"
    return text


def vector(vec: Vec, names: list[str], pairs: list[tuple[int, int, str]]) -> str:
    """A linear 2-vector as points and vectors: 'B − A', '(0.4, 0) − B', 'A + 0.5 Ω u'."""
    lx, ly = vec.x.linear(), vec.y.linear()
    terms = []
    used = set()
    for ix, iy, symbol in pairs:
        xx, xy, yx, yy = lx.get(ix, 0.0), lx.get(iy, 0.0), ly.get(ix, 0.0), ly.get(iy, 0.0)
        if not any(abs(v) >= ZERO for v in (xx, xy, yx, yy)):
            continue
        if abs(xx - yy) > ZERO or abs(xy + yx) > ZERO:
            return f"({linear(vec.x, names)}, {linear(vec.y, names)})"
        used |= {ix, iy}
        if abs(xx) >= ZERO:
            terms.append((xx, symbol))
        if abs(yx) >= ZERO:
            terms.append((yx, f"Ω{symbol}"))
    if any(i not in used for i in (*lx, *ly) if i != ONE):
        return f"({linear(vec.x, names)}, {linear(vec.y, names)})"
    terms.sort(key=lambda t: t[0] < 0)          # 'B − A' rather than '−A + B'
    const = (lx.get(ONE, 0.0), ly.get(ONE, 0.0))
    if any(abs(c) >= ZERO for c in const) or not terms:
        point = (1.0, f"({num(const[0])}, {num(const[1])})")
        terms = [point] + terms if terms and terms[0][0] < 0 else terms + [point]
    return _sum(terms)


# ---- the worked example -----------------------------------------------------------------------

@dataclass
class Worked:
    """The four-bar in natural coordinates at t = T0, every number the page prints unrounded.

    ``q0`` x, y, fi of the assembly; ``z0``, ``zd0``, ``zdd0`` its natural coordinates and
    their rates (Φ_z ż = g', Φ_z z̈ = γ); ``jacobian`` Φ_z (m, nz); ``rhs`` g'; ``gamma`` γ;
    ``mass`` the constant mass matrix; ``names`` the symbols of the coordinates.
    """

    model: object
    mech: object
    form: Formulation
    names: list
    pairs: list
    q0: np.ndarray
    z0: np.ndarray
    zd0: np.ndarray
    zdd0: np.ndarray
    jacobian: np.ndarray
    rhs: np.ndarray
    gamma: np.ndarray
    mass: np.ndarray


def _points_of(form: Formulation, model, vec: Vec) -> list[str]:
    """The named points of the model that are the basic point ``vec`` ('crank.A')."""
    out = []
    for i, solid in enumerate(model.solids):
        for name, local in solid.points.items():
            key = (i, tuple(float(v) for v in local))
            if key in form.basic and form.basic[key] == vec:
                out.append(f"{solid.name}.{name}")
    return out


def symbols(form: Formulation, mech) -> tuple[list[str], list[tuple[int, int, str]]]:
    """(a short symbol per coordinate, [(x index, y index, symbol)] of the points and
    vectors): a basic point is named after the revolute joints that share it ('A'), the
    other coordinates keep their names ('crank.fi', 'slider.u')."""
    names = [c.name for c in form.coordinates]
    pairs = []
    k = 0
    while k < len(names):
        c = form.coordinates[k]
        if c.kind in ("point", "vector") and c.name.endswith(".x"):
            base = c.name[:-2]
            vec = Vec(Expr.coordinate(k), Expr.coordinate(k + 1))
            joints = [el.name for el in mech.elements if el.type == "revolute"
                      and all(form.basic.get((r.solid, tuple(r.local))) == vec
                              for r in el.refs)]
            symbol = "=".join(joints) if joints else base
            names[k], names[k + 1] = f"{symbol}.x", f"{symbol}.y"
            pairs.append((k, k + 1, symbol))
            k += 2
        else:
            k += 1
    return names, pairs


def assembled_q(path, mech) -> np.ndarray:
    """x, y, fi of every solid at the assembled t = 0 configuration."""
    res = pam2exu.run(path, analysis="assembly")
    q = np.empty(mech.nq)
    for i, s in enumerate(mech.solids):
        for k, var in enumerate(("x", "y", "fi")):
            q[column(i, k)] = res[f"{s.name}.{var}"][0]
    return q


def compute(path=None) -> Worked:
    """The four-bar (or the model at ``path``) in natural coordinates at t = 0."""
    path = ROOT / MODEL_PATH if path is None else Path(path)
    model = pam2exu.load(path)
    mech = model.mechanism()
    form = Formulation(mech)
    names, pairs = symbols(form, mech)
    q0 = assembled_q(path, mech)
    z0 = form.from_q(q0[None])[0]
    t = np.array([T0])
    terms = form.terms
    J = terms.dense(terms.jacobian(z0[None]))[0]
    rhs = terms.velocity_rhs(t)[0]
    zd = np.linalg.solve(J, rhs)
    gamma = terms.gamma(t, z0[None], zd[None])[0]
    zdd = np.linalg.solve(J, gamma)
    return Worked(model, mech, form, names, pairs, q0, z0, zd, zdd, J, rhs, gamma,
                  form.mass_matrix())


# ---- Markdown -----------------------------------------------------------------------------

def cell(text: str) -> str:
    return str(text).replace("|", "\\|")


def table(header: list[str], rows: list[list[str]], align: str | None = None) -> list[str]:
    """A Markdown table; ``align``: one character per column, 'l' or 'r'."""
    align = align or "l" * len(header)
    rule = ["---:" if a == "r" else "---" for a in align]
    out = ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "|".join(rule) + "|"]
    out += ["| " + " | ".join(cell(c) for c in row) + " |" for row in rows]
    return out + [""]


def first_paragraph(doc: str | None) -> str:
    """The docstring's first paragraph on one line, RST ``code`` as Markdown `code`."""
    lines = []
    for line in (doc or "").strip().splitlines():
        if not line.strip():
            break
        lines.append(line.strip())
    return re.sub(r"``(.+?)``", r"`\1`", " ".join(lines))


def _vec(local) -> str:
    return f"({num(local[0])}, {num(local[1])})"


def _what(w: Worked, k: int) -> str:
    """What coordinate k is, in the model's words."""
    c = w.form.coordinates[k]
    if c.kind == "angle":
        return f"the angle fi of {c.name.rsplit('.', 1)[0]}"
    if c.kind == "vector":
        return f"unit vector along the x axis of {c.name.split('.')[0]}"
    ix, iy, _ = next(p for p in w.pairs if k in p[:2])
    points = _points_of(w.form, w.model, Vec(Expr.coordinate(ix), Expr.coordinate(iy)))
    axis = "x" if k == ix else "y"
    return f"{axis} of " + (" = ".join(points) if points else f"the origin of {c.name.split('.')[0]}")


# ---- the page ----------------------------------------------------------------------------------

INTRO = """\
pam2exu solves the positions with one of two backends. The default translates each element
into Exudyn items, which describe every solid by the *reference-point coordinates* x, y, fi
of its frame. The second, `--backend natural` (and the other half of
[`pam2exu verify`](verify.md)), writes the same mechanism in *natural coordinates* (Unda and
García de Jalón, 1985; García de Jalón and Bayo, *Kinematic and Dynamic Simulation of
Multibody Systems*, 1994) and solves them with pam2exu's own Newton method. This page
explains that formulation on one worked example, the four-bar of
[`examples/four_bar.toml`](../examples/four_bar.toml): its coordinates, its equations, their
Jacobian, the exact acceleration terms and the constant mass matrix; then how every element
type is converted, how x, y, fi come back, the forward dynamics, the static equilibrium
and the inverse dynamics it solves (every analysis runs on this backend), and how to read `pam2exu verify`.

Every table, equation and number below is generated from the code
(`pam2exu/backend/natural/`, `Element.natural` of each element type) by
`python docs/make_natural.py`; `tests/test_natural_docs.py` fails when the page is not what
the code gives, and checks its numbers against independent computations."""

WHAT = """\
Reference-point coordinates give every solid three numbers, the position x, y of its frame's
origin and its angle fi. A point s of the solid (local coordinates) is then
r = (x, y) + R(fi) s, so a revolute joint, r_i(s_i) = r_j(s_j), is two equations in sines
and cosines of the angles: the Jacobian changes with every angle, the acceleration terms are
centripetal terms fi′² R(fi) s, and the mass matrix depends on fi unless the frame's origin
is the centre of mass.

Natural coordinates instead take the global coordinates of points and of vectors:

* **Basic points.** The points that revolute joints join: one pair (x, y) shared by all the
  solids a joint pins together. A revolute is then no equation at all, only a shared point.
  A point of the ground is a constant, not a coordinate.
* **Unit vectors.** A solid with fewer than two basic points gets a unit vector fixed to it
  (along its local x axis), and, with none, its origin as a basic point too.
* **Angles (mixed coordinates).** Where an element needs a solid's absolute angle (an angular
  actuator, a transmission), the angle fi is a coordinate too, tied to the solid's vector by
  one equation.

Each moving solid thus has a *base point* p (local s_p) and a *base vector* v = R(fi) d: from
its first basic point to its farthest other one (d their local difference), or its unit vector
(d = (1, 0)). Every point of the solid is a constant linear combination of them,

    r(s) = p + a v + b Ω v,     (a, b) = (d·w, d×w) / |d|²,   w = s − s_p,

where Ω v = (−v_y, v_x) is v turned 90° counter-clockwise. So a solid needs only these
equations, its *rigid-body equations*:

* |v|² = |d|²: the distance between its two basic points, or the unit vector's length
  (quadratic);
* P_k − r(s_k) = 0 for each further basic point P_k (two linear equations each).

**No solid can mirror.** Two points fix a solid only up to a reflection about the line
through them; a third point written through distances (|P₃ − P₁| and |P₃ − P₂| constant)
would still allow the mirrored triangle. Written as r(s) = p + a v + b Ω v, with Ω a
counter-clockwise turn, a point keeps its side of v: the mirror image, with −b, is not a
solution of the equations.

What this buys: every equation is linear or quadratic in the coordinates z (the angle ties
are the one exception, a sine), so the Jacobian is linear in z, the acceleration terms γ are
exact and short, and the mass matrix is constant."""


def _model_section(w: Worked) -> list[str]:
    out = ["## The worked example: a four-bar", ""]
    rows = []
    for i, s in enumerate(w.model.solids):
        pts = ", ".join(f"{n} {_vec(p)}" for n, p in s.points.items())
        rows.append([s.name, pts, num(s.mass), num(s.inertia), _vec(s.cog),
                     " ".join(num(w.q0[column(i, k)]) for k in range(3))])
    out.append(f"[`{MODEL_PATH}`](../{MODEL_PATH}) ('{w.model.name}') has these solids "
               "(points and centre of mass in the solid's own frame; x, y, fi the "
               "assembled configuration at t = 0, from `pam2exu.run(path, "
               "analysis=\"assembly\")`):")
    out.append("")
    out += table(["solid", "points [m]", "m [kg]", "I_G [kg·m²]", "cog [m]",
                  "x [m], y [m], fi [rad] at t = 0"], rows, "llrrll")
    rows = [[el.name, el.type, ", ".join(str(getattr(el, a)) for a in ("anc1", "anc2")
                                        if getattr(el, a, None))]
            for el in w.mech.elements]
    out += ["and these elements:", ""]
    out += table(["element", "type", "anchors"], rows)
    return out


def _coordinates_section(w: Worked) -> list[str]:
    f = w.form
    out = ["### Its natural coordinates", "",
           (f"{f.nz} coordinates instead of the {w.mech.nq} x, y, fi of the reference-point "
            "description. The symbol is what the equations below call a coordinate: a basic "
            "point takes the name of the revolute joint that is it; the coordinate's own name "
            "in `Formulation.coordinates` (the point (0.1, 0) of the crank: `crank(0.1,0).x`) "
            "is in the second column. Values at the assembled t = 0 configuration "
            "(`Formulation.from_q`), and the rates the backend's own linear solves give "
            "there (next sections):"), ""]
    rows = []
    for k, c in enumerate(f.coordinates):
        rows.append([f"z{k + 1}", w.names[k], c.name, c.kind, _what(w, k), num(w.z0[k]),
                     num(w.zd0[k]), num(w.zdd0[k])])
    out += table(["", "symbol", "coordinate", "kind", "is", "z", "ż", "z̈"], rows,
                 "lllllrrr")
    ground = [f"{s.name}.{n} = {_vec(f._ground_point(i, p))}"
              for i, s in enumerate(w.model.solids) if i in f.grounds
              for n, p in s.points.items()]
    out += [(f"The ground's points are constants: {', '.join(ground)} (m). "
             "Units: points in m, unit vectors without unit, angles in rad; ż per second, "
             "z̈ per second squared."), ""]
    return out


def _frames_section(w: Worked) -> list[str]:
    f = w.form
    out = ["### Base point and base vector of each solid", "",
           ("`Formulation.frames`: for each solid the base point p (at local s_p), the base "
            "vector v = R(fi) d, and whether its angle is a coordinate. The ground's "
            "are constants:"), ""]
    rows = []
    for i, fr in enumerate(f.frames):
        s = w.mech.solids[i]
        if fr.fixed_angle is not None:
            angle = f"constant, {num(fr.fixed_angle)}"
        elif fr.angle is not None:
            angle = f"coordinate {w.names[fr.angle]}"
        else:
            angle = "atan2 of v (below)"
        rows.append([s.name, vector(fr.p, w.names, w.pairs), _vec(fr.sp),
                     vector(fr.v, w.names, w.pairs), _vec(fr.d),
                     num(fr.d[0] ** 2 + fr.d[1] ** 2), angle])
    out += table(["solid", "p", "s_p [m]", "v", "d [m]", "|d|² [m²]", "fi"], rows,
                 "lllllrl")
    out += [("Every named point of a solid is then r(s) = p + a v + b Ω v, with (a, b) from "
             "its local s (`Frame.point`): the table gives them and the point's position at "
             "t = 0."), ""]
    rows = []
    for i, s in enumerate(w.model.solids):
        fr = f.frames[i]
        for name, local in s.points.items():
            a, b = ab(fr, local)
            where = w_point(w, i, local)
            p, v = vector(fr.p, w.names, w.pairs), vector(fr.v, w.names, w.pairs)
            if i in f.grounds:
                formula = "constant"
            else:
                v_ = v if len(v.split()) == 1 else f"({v})"
                parts = [(c, t) for c, t in ((a, v_), (b, f"Ω{v_}")) if abs(c) >= ZERO]
                if p != "(0, 0)" or not parts:
                    parts.insert(0, (1.0, p))
                formula = _sum(parts)
            rows.append([f"{s.name}.{name}", _vec(local), num(a), num(b), formula,
                         _vec(where)])
    out += table(["point", "s [m]", "a", "b", "r(s) = p + a v + b Ω v", "at t = 0 [m]"],
                 rows, "llrrll")
    return out


def ab(frame, local) -> tuple[float, float]:
    """(a, b) = (d·w, d×w) / |d|², w = s − s_p: the point s of a solid in its frame."""
    wx, wy = local[0] - frame.sp[0], local[1] - frame.sp[1]
    dx, dy = frame.d
    n2 = dx * dx + dy * dy
    return (dx * wx + dy * wy) / n2, (dx * wy - dy * wx) / n2


def w_point(w: Worked, solid: int, local) -> np.ndarray:
    """The point ``local`` of a solid at z0, from its linear form."""
    vec = w.form.frames[solid].point(local)
    return w.form.matrix(vec) @ w.z0 + w.form.constants(vec)


def _names(names: list[str]) -> str:
    """'A', 'A and B', 'A, B and C'."""
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _equations_section(w: Worked) -> list[str]:
    f = w.form
    shared, grounded = [], []
    for el in w.mech.elements:
        if el.type == "revolute":
            vec = f.basic[(el.ref1.solid, tuple(el.ref1.local))]
            (grounded if vec.x.is_linear and set(vec.x.linear()) <= {ONE} else shared).append(
                el.name)
    joints = (f" The revolutes have no equation: {_names(shared)} "
              f"{'is a shared basic point' if len(shared) == 1 else 'are shared basic points'}"
              + (f", {_names(grounded)} {'is a' if len(grounded) == 1 else 'are'} constant "
                 f"point{'' if len(grounded) == 1 else 's'} of the ground" if grounded else "")
              + ".") if shared or grounded else ""
    out = ["### Its equations", "",
           (f"{f.m} equations Φ(z, t) = 0 in {f.nz} coordinates (`Formulation.labels`, "
            "`Terms`): the rigid-body equations of each moving solid, the tie of each angle "
            "coordinate, then the elements' own equations in the model's order." + joints),
           ""]
    rows = []
    for k, (label, e, target, power) in enumerate(f._rows):
        rows.append([str(k + 1), label, equation(e, target, power, w.names), kind_of(e)])
    out += table(["", "what", "equation", "kind"], rows)
    laws = []
    for el in w.mech.elements:
        if hasattr(el, "time_law"):
            law = el.time_law()
            doc = first_paragraph(LAWS[law.name][0].__doc__).rstrip(".")
            laws.append(f"'{el.name}' follows the {law.name} law {doc}, C = "
                        f"[{', '.join(num(c) for c in law.C)}]")
    if laws:
        out += [f"f(t) is the actuator's time law: {'; '.join(laws)}.", ""]
    for k, label in enumerate(f.labels):
        if label.startswith("angle of"):
            i = next(i for i, fr in enumerate(f.frames)
                     if fr.angle is not None and label == f"angle of '{w.mech.solids[i].name}'")
            fr = f.frames[i]
            out += [(f"Row {k + 1} is the *angle tie* of {w.names[fr.angle]}: "
                     "v × e(fi) / |d| = 0, e(fi) = (cos fi, sin fi), so that the base vector "
                     f"v = {vector(fr.v, w.names, w.pairs)} points along fi (or exactly "
                     "against it: the tie cannot tell them apart, Newton's method keeps the "
                     "one it starts nearest). The actuator's equation is then linear, "
                     f"{w.names[fr.angle]} = f(t)."), ""]
    return out


def _jacobian_section(w: Worked) -> list[str]:
    f = w.form
    pattern = set(zip(f.terms.rows.tolist(), f.terms.cols.tolist()))
    rank = np.linalg.matrix_rank(w.jacobian)
    cond = np.linalg.cond(w.jacobian)
    out = ["### The Jacobian at t = 0", "",
           ("Φ_z (`Terms.jacobian`, data on the fixed sparsity pattern `rows`, `cols`; "
            "`Terms.dense` fills the matrix) at the assembled configuration. Its entries are "
            "linear in z (the angle tie's: sines and cosines of the angle); `·` marks "
            "entries outside the pattern, zero at every configuration."), ""]
    rows = []
    for r in range(f.m):
        rows.append([str(r + 1), f.labels[r]] + [
            num(w.jacobian[r, c]) if (r, c) in pattern else "·" for c in range(f.nz)])
    out += table(["", "equation"] + w.names, rows, "ll" + "r" * f.nz)
    out += [(f"Size {f.m} × {f.nz}, rank {rank}, condition number {num(cond, 3)}. The "
             f"reference-point Jacobian of the same four-bar is {w.mech.n_equations} × "
             f"{w.mech.nq}: [`examples/natural_jacobian.py`](../examples/natural_jacobian.py) "
             "prints the two side by side."), ""]
    return out


def _rates_section(w: Worked) -> list[str]:
    f = w.form
    out = ["### Velocities and accelerations at t = 0", "",
           ("Velocities solve Φ_z ż = g′(t) (`Terms.velocity_rhs`: the law's rate for an "
            "actuator's row, zero elsewhere), accelerations Φ_z z̈ = γ (`Terms.gamma`). "
            "γ is exact, the second time derivative of Φ with the z̈ terms taken out "
            f"(′ = d/dt; section [The exact γ](#the-exact-velocity-term-γ)):"), ""]
    rows = []
    for k, (label, e, target, power) in enumerate(f._rows):
        rows.append([str(k + 1), label, num(w.rhs[k]), gamma_text(e, target, power, w.names),
                     num(w.gamma[k])])
    out += table(["", "equation", "g′ at t = 0", "γ", "γ at t = 0"], rows, "llrlr")
    out += ["The solutions ż, z̈ are the last columns of the coordinates' table.", ""]
    return out


def _mass_section(w: Worked) -> list[str]:
    f = w.form
    out = ["### Its constant mass matrix", "",
           ("`Formulation.mass_matrix()`: T = ½ żᵀ M ż for every velocity ż, M the same at "
            "every configuration (formula in [its section](#the-constant-mass-matrix)). "
            "Per solid, the numbers it is made of:"), ""]
    rows = []
    for i, fr in enumerate(f.frames):
        s = w.mech.solids[i]
        if i in f.grounds:
            continue
        g = (float(s.cog[0]), float(s.cog[1]))
        a, b = ab(fr, g)
        jp = float(s.inertia) + float(s.mass) * ((g[0] - fr.sp[0]) ** 2
                                                 + (g[1] - fr.sp[1]) ** 2)
        rows.append([s.name, num(s.mass), num(s.inertia), _vec(g), _vec(fr.sp), num(a),
                     num(b), num(jp), num(fr.d[0] ** 2 + fr.d[1] ** 2)])
    out += table(["solid", "m [kg]", "I_G [kg·m²]", "s_G [m]", "s_p [m]", "a_G", "b_G",
                  "J_p [kg·m²]", "|d|² [m²]"], rows, "lrrllrrrr")
    out += [("and M, summed over the solids (kg for the point coordinates; a row and a "
             "column of zeros for the angle coordinate, which carries no mass: the solid's motion "
             "is in its points):"), ""]
    rows = [[w.names[r]] + [num(w.mass[r, c]) for c in range(f.nz)] for r in range(f.nz)]
    out += table(["M"] + w.names, rows, "l" + "r" * f.nz)
    T = 0.5 * w.zd0 @ w.mass @ w.zd0
    out += [(f"At t = 0 the four-bar's kinetic energy is T = ½ żᵀ M ż = {num(T)} J (the "
             "same as from m, I_G and the velocities of the centres of mass, Σ ½ m |v_G|² + "
             "½ I_G ω²: `tests/test_natural_docs.py` checks it solid by solid)."), ""]
    return out


def _elements_section() -> list[str]:
    out = ["## How each element type is converted", "",
           ("Each element type declares its equations in natural coordinates in one method, "
            "`Element.natural(nc)`, from the linear forms of its points, directions and "
            "angles (`nc.point`, `nc.direction`, `nc.angle`); the table gives the first "
            "paragraph of each docstring, and the number of equations the same element "
            "has in reference-point coordinates. Force elements declare no equation; their "
            "forces, for the backend's static check (`Element.natural_loads`), are in the "
            "last column."), ""]
    rows = []
    for type_, cls in ELEMENTS.items():
        if cls.natural is Element.natural:
            natural = "no equation (a force element)"
        else:
            natural = first_paragraph(inspect.getdoc(cls.natural))
        loads = ("" if cls.natural_loads is Element.natural_loads
                 else first_paragraph(inspect.getdoc(cls.natural_loads)))
        rows.append([f"`{type_}`", cls.summary, str(cls.equations), natural, loads or "–"])
    out += table(["type", "what it means", "x, y, fi equations", "in natural coordinates",
                  "forces (static check)"], rows, "llrll")
    out += [("A revolute joins points only where it can (`Formulation._basic_points`: "
             f"“{first_paragraph(Formulation._basic_points.__doc__)}”). "
             "Points and directions being linear in z, an element's equation is a dot "
             "product of two linear forms: linear when one of them is constant (a slot in "
             "the ground), quadratic otherwise."), ""]
    return out


def _gamma_section() -> list[str]:
    doc = inspect.getdoc(terms_module) or ""
    lines = doc.splitlines()
    start = next(k for k, line in enumerate(lines) if line.strip().startswith("Φ "))
    block = []
    for line in lines[start:]:
        if not line.strip():
            break
        block.append(line.strip())
    return ["## The exact velocity term γ", "",
            ("Every equation is a sum of terms c z_a z_b (z_ONE = 1 makes linear terms and "
             "constants) and c z_a sin(z_b + α) (an angle tie), minus g(t) = f(t) or f(t)² for "
             "an actuator's law f. Differentiating twice in time,"), "",
            "    d²/dt² (c z_a z_b) = c (z̈_a z_b + z_a z̈_b) + 2 c ż_a ż_b,", "",
            ("the z̈ terms are Φ_z z̈ and the rest is what goes to the right-hand side: for a "
             "quadratic constraint γ = g″ − 2 Σ c ż_a ż_b, exactly, with no approximation and "
             "no stabilisation term. `Terms` evaluates, for all time steps at once:"), "",
            "```text", *block, "```", "",
            ("(−ż ᵀ ∂²Φ/∂z² ż, the terms module's docstring). For a rigid-body equation "
             "|P₂ − P₁|² = L² this is γ = −2 |Ṗ₂ − Ṗ₁|²: the centripetal term of "
             "reference-point coordinates in one product, with no angle in it."), ""]


def _pose_section(w: Worked) -> list[str]:
    f = w.form
    K = f.pose_forms()
    out = ["## How x, y, fi come back", "",
           ("The analyses and the results speak x, y, fi. The origin of a solid is its point "
            "r(0), and cos fi, sin fi are (d·v, d×v) / |d|² (`Frame.cos_sin`): all four are "
            "linear in z, one matrix K with (x, y, cos fi, sin fi) = K [z; 1] "
            "(`Formulation.pose_forms`). For the four-bar:"), ""]
    rows = []
    for i, fr in enumerate(f.frames):
        row = [w.mech.solids[i].name]
        for k in range(4):
            lin = {(ONE if c == f.nz else c): K[4 * i + k, c] for c in range(f.nz + 1)
                   if abs(K[4 * i + k, c]) >= ZERO}
            row.append(linear(lin, w.names) if lin else "0")
        if fr.fixed_angle is not None:
            row.append(f"constant {num(fr.fixed_angle)}")
        elif fr.angle is not None:
            row.append(f"the coordinate {w.names[fr.angle]}")
        else:
            row.append("atan2(sin fi, cos fi), unwrapped")
        rows.append(row)
    out += table(["solid", "x", "y", "cos fi", "sin fi", "fi"], rows)
    out += [("fi is the angle coordinate where the solid has one, the constant of the ground, "
             "and otherwise atan2(sin fi, cos fi), unwrapped over the time steps so that it is "
             "continuous (never wrapped to (−π, π]: a crank that turns twice ends near 4π), "
             "its first value in the whole turn nearest the model's fi. Velocities and "
             "accelerations follow the same way (`Natural.to_rates`): ẋ, ẏ and the rates "
             "of cos fi, sin fi are K ż and K z̈, and ω = (c ṡ − s ċ)/(c² + s²) with c, s "
             "= cos fi, sin fi."), ""]
    return out


def _mass_formula_section() -> list[str]:
    doc = inspect.getdoc(Formulation.mass_matrix) or ""
    formula = [line for line in doc.splitlines() if not line.startswith("``solids``")]
    return ["## The constant mass matrix", "",
            ("A point of a solid moves as ṙ(s) = ṗ + a v̇ + b Ω v̇ (a, b constant), and its "
             "angular velocity is ω = (v × v̇)/|v|² with |v| = |d|. The kinetic energy "
             "½ m |v_G|² + ½ I_G ω² is therefore a constant quadratic form in ż; with P, V "
             "the constant matrices of ṗ = P ż and v̇ = V ż (`Formulation.matrix`), "
             "`Formulation.mass_matrix` sums, solid by solid:"), "",
            "```text", *formula, "```", "",
            ("(v̇ ⊥ Ω v̇, so |a_G v̇ + b_G Ω v̇|² = (a_G² + b_G²) |v̇|², and "
             "(a_G² + b_G²) |d|² = |s_G − s_p|².) It does not depend on the configuration: "
             "there are no velocity-dependent inertia terms in natural coordinates. The "
             "solids are constrained by the rigid-body equations, so M alone is singular "
             "where a coordinate carries no mass (an angle coordinate, a massless solid); "
             "the equations of motion pair it with Φ_z."), ""]


DYNAMICS = """\
## Forward dynamics in natural coordinates

The `dynamic` analysis on this backend (`--backend natural`,
`pam2exu/backend/natural/dynamics.py`) integrates the equations of motion with the constant
M above:

```text
M z̈ + Φ_zᵀ μ = Q(z, ż, t),   Φ(z, t) = 0
[M   Φ_zᵀ] [z̈]   [Q]
[Φ_z  0  ] [μ] = [γ]          (index 1: Φ_z z̈ = γ, the γ of the table above)
```

Q is the virtual work of the loads on z: a force F at the point s of a solid is (F, a F −
b Ω F) on its base point and base vector, a moment M is M Ω v / |v|² on v (`Loads`), so
Q_z = Σ Pᵀ Q_p + Vᵀ Q_v; gravity acts at fixed (a, b) and is a constant vector, the springs
and dampers are evaluated at each state (a damper's rate from ż). scipy's DOP853 integrates
y = (z, ż) (Radau if a run would take more than 20,000 steps: a stiff model). Index 1 alone
lets the constraints drift, so after every accepted step, and at every output time (from the
method's dense output), the state is projected back onto Φ = 0 (least-norm Gauss–Newton) and
Φ_z ż = g′. The accuracy is on demand: runs at rtol = atol = 0.1 · tolerance, then 16 times
smaller, until two successive runs differ by at most tolerance · (1 + |value|) on every
x, y, fi and rate; the finer one is kept. A run that would need more than 2,097,152 steps
stops; so does one whose pace over its first 1,000, 2,000, 4,000 … steps would need 64
times that to reach the end of the interval. That is an interval far longer than the
motion's time scale, such as one meant in milliseconds. The message gives the time
reached and the pace. The analysis does the rest (law breakpoints'
impulses, accelerations, reactions), as for Exudyn, so `pam2exu verify MODEL -a dynamic`
compares two independent integrations (rule in [verify.md](verify.md))."""

STATICS = """\
## Static equilibrium in natural coordinates

The `equilibrium` analysis on this backend (`pam2exu/backend/natural/statics.py`) balances
the same Q, at rest (no dampers), against the constraints:

```text
Q(z) − Φ_zᵀ λ = 0,   Φ(z, t) = 0            (a stationary point of V on Φ = 0: Q = −∂V/∂z)
[H    Φ_zᵀ] [Δz]   [Q − k Aᵀ W g]
[Φ_z  0   ] [λ ] = [−Φ          ],   H = −∂Q/∂z + k Aᵀ W A + Σ λ_i ∂²Φ_i/∂z²
```

Newton's iteration on these conditions, ∂Q/∂z by central differences and the constraints'
curvature exact, is what the analysis's descent calls (`Backend.static_equilibrium`, the
same call Exudyn's static solver answers): proximal steps with springs tying x, y, fi of
every solid to the last step (k on x and y, k L² on fi; x, y, fi are A z + c when every
solid has an angle coordinate, g = A z + c − q_s, W = diag(1, 1, L²)), then the equilibrium
without them. The angles the torsional springs read are atan2 of each solid's vector, so Q
is the exact gradient of −V everywhere in z. The analysis then checks stability with the
reduced tangent stiffness in x, y, fi, as for Exudyn, so `pam2exu verify MODEL` on an
equilibrium model compares two independent equilibria (rule in [verify.md](verify.md))."""

INVERSE = """\
## Inverse dynamics in natural coordinates

The `kinetostatic` analysis on this backend takes its reactions and actuator forces from
the natural coordinates (`pam2exu/backend/natural/inverse.py` and `reactions.py`, what
`Natural.reactions` answers when the analysis asks: `Backend.gives_reactions`), not from the
reference-point pass the Exudyn backend's runs use. So does the `quasi_static` analysis:
its equilibrium Cqᵀ λ = −Q_applied is the inverse dynamics of its configurations at rest
(ż = z̈ = 0: no inertia force, and a damper at rest applies none).

Each solid's base point and base vector are ζ_b = (p, v) = A_b z + c_b, and its kinetic
energy a constant quadratic form in ζ̇_b, so what its joints apply to it has no velocity
term:

```text
W_b = M_b ζ̈_b − Q_b,   M_b = [[m I, m G], [m Gᵀ, J_p / |d|² I]],   G = a_G I + b_G Ω
Σ A_bᵀ M_b A_b = M                                         (the constant mass matrix above)
M z̈ + Φ_zᵀ μ = Q   ⇔   Φ_zᵀ μ = −Σ A_bᵀ W_b                (μ of least norm if redundant)
```

(Q_b: gravity, the torsors, the spring-dampers, as in the forward dynamics.) The reactions
follow from μ and each solid's equilibrium:

- an element with equations (prismatic, pin_slot, transmission, the actuators) applies
  −(∂Φ_el/∂ζ̂_s)ᵀ μ_el to solid s, its rows written in each solid's own frame variables
  ζ̂_s = (p_s, v_s, fi_s): a force on p, a moment from v and fi;
- a revolute whose two points share a basic point P has no equation: the force it applies
  to solid s is what is left at s's own copy of P's coordinates, A_sᵀ W_s plus the forces of
  s's rigid-body rows and of the element rows through s's frame (per-body equilibrium at
  the shared basic point); at a ground point, which has no coordinate, it is what s's wrench
  balance leaves; several solids at one point share it by the point's incidence;
- a fixed link gives what its held solid's balance leaves.

Where constraints are redundant, the self-stresses (μ in the null space of Φ_zᵀ, without
load) are added in the combination that makes the reported components least in norm: the
reference-point pass's choice, so both backends report the same reactions. Everything is an
array over the steps, the solids' constants arrays over the solids. The forces equal the
reference-point pass's to round-off (`tests/backend/test_natural_inverse.py`: the four-bar,
the slider-crank, `examples/all_elements.toml`, a redundant parallelogram and a six-bar,
every force column within 1e-9, measured 7e-14; the quasi-static runs of the same models at
rest, measured 5e-14), so `pam2exu verify MODEL -a kinetostatic` (or `-a quasi_static`) now
compares forces from two formulations as well. A revolute whose points could not share a basic point,
a solid pinned to the ground at two points, or an element between ground solids alone is
left to the reference-point pass (`res.info["reactions_from"]` says which computed them)."""

VERIFY = """\
## Reading `pam2exu verify`

`pam2exu verify MODEL` runs one analysis on both backends, the Exudyn translation in
reference-point coordinates (the reference) and the natural coordinates of this page, and
compares every output variable within a tolerance derived from the solvers' tolerances and the
mechanism's condition number. The two formulations share no equations: a model on which they
agree is translated correctly by both. Where they differ, positions point at an element's
equations (its `natural` method against its `constraint`), differences only in the rates at a
backend's velocity or acceleration terms (here: g′ and γ above). How to run it, the table
column by column, the tolerance rule and what it catches are in [verify.md](verify.md).

```bash
pam2exu verify examples/four_bar.toml --steps 20
pam2exu run examples/four_bar.toml --backend natural -a assembly
```"""

SIDE = """\
## Side by side with the reference-point Jacobian

[`examples/natural_jacobian.py`](../examples/natural_jacobian.py) assembles the four-bar and
prints both Jacobians at t = 0 with named rows and columns: the reference-point Cq
({m} × {nq}: the fixed link's three rows, two per revolute, one for the motor; three columns
x, y, fi per solid) and the natural Φ_z above; their sizes and ranks; and the velocities of
both, solved at t = 0 and compared as x, y, fi rates (`Natural.to_rates`). It draws the two
matrices beside the mechanism with its basic points.

```bash
python examples/natural_jacobian.py -o natural_jacobian.png
```

From Python, the formulation of any model:

```python
import numpy as np
import pam2exu
from pam2exu.backend.natural import Formulation

mech = pam2exu.load("examples/four_bar.toml").mechanism()
form = Formulation(mech)
res = pam2exu.run("examples/four_bar.toml", analysis="assembly")
q0 = np.array([res[f"{{s.name}}.{{v}}"][0] for s in mech.solids for v in ("x", "y", "fi")])
z0 = form.from_q(q0[None])                          # (1, nz) natural coordinates
J = form.terms.dense(form.terms.jacobian(z0))[0]     # Φ_z, (m, nz)
print([c.name for c in form.coordinates], form.labels)
assert np.abs(form.terms.residual(np.array([0.0]), z0)).max() < 1e-12
assert np.linalg.matrix_rank(J) == form.nz == {nz}
```"""


def render(w: Worked | None = None) -> str:
    """The whole of docs/natural-coordinates.md."""
    w = compute() if w is None else w
    out = ["# Natural coordinates", "",
           ("<!-- Generated by docs/make_natural.py from the code: do not edit by hand. Run "
            "`python docs/make_natural.py` after changing the natural-coordinate backend or an "
            "element's `natural` method. -->"), "", INTRO, ""]
    out += ["## What natural coordinates are", "", WHAT, ""]
    out += _model_section(w)
    out += _coordinates_section(w)
    out += _frames_section(w)
    out += _equations_section(w)
    out += _jacobian_section(w)
    out += _rates_section(w)
    out += _mass_section(w)
    out += _elements_section()
    out += _gamma_section()
    out += _pose_section(w)
    out += _mass_formula_section()
    out += [DYNAMICS, ""]
    out += [STATICS, ""]
    out += [INVERSE, ""]
    out += [VERIFY, ""]
    out += [SIDE.format(m=w.mech.n_equations, nq=w.mech.nq, nz=w.form.nz), ""]
    text = "\n".join(out)
    return re.sub(r"\n{3,}", "\n\n", text).rstrip("\n") + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Write docs/natural-coordinates.md from the code.")
    p.add_argument("--check", action="store_true",
                   help="exit 1 when docs/natural-coordinates.md is not what this script writes")
    args = p.parse_args(argv)
    return write_or_check(OUTPUT, render(), args.check, OUTPUT.name,
                          "it is not what the code gives", "python docs/make_natural.py")


if __name__ == "__main__":
    sys.exit(main())
