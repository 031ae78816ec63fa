"""Seeded mutants of the shipped and test models: ``mutant(seed) -> (name, bytes, description)``.

A mutant is one of the model files of ``SOURCES`` with 1 to 3 mutations (``KINDS``) applied:
deleted keys and sections, wrong types, extreme numbers, odd names, dangling and self anchors,
deep nesting, broken TOML, a cp1252 file, absurd analysis settings and law constants, swapped
element types, over-constrained and degenerate elements, and so on; and the keys of the
extensions (issues 13 and 15): the dynamic analysis's ``tolerance``, the solids' initial
rates ``Dx``, ``Dy``, ``Dfi``, ``clearance`` flags on elements, ``[[variation]]`` entries and
``[model] angles``. Everything is drawn from
``random.Random(seed)``: the same seed gives the same bytes, whatever the state of the package
(the generator does not import pam2exu), so a seed reported by a campaign stays reproducible.

The model is parsed with ``tomllib``, mutated as data, written back with the small TOML writer
``dumps`` (which can also write values no Python object parses to: ``Raw`` text, ``Deep``
nesting) and encoded to bytes; byte-level mutations (truncation, garbage, BOM, …) come last.

    python -m tests.fuzz.mutants 17          # print seed 17's description and file
"""
from __future__ import annotations

import copy
import math
import random
import re
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: the model files mutants are made from, relative to the repository's root
SOURCES = (
    "examples/all_elements.toml",
    "examples/four_bar.toml",
    "examples/pam_crank.toml",
    "examples/scotch_yoke.toml",
    "examples/slider_crank.toml",
    "tests/data/every_element.toml",
    "tests/data/parallelogram5.toml",
    "tests/data/compare/crank.toml",
    "examples/clearance/locomotive.toml",
    "examples/clearance/slider_guided_twice.toml",
    "examples/equilibrium/spring_four_bar.toml",
    "examples/dynamics/andrews.toml",
    "tests/fuzz/seeds/spring_four_bar_deg.toml",
)

#: [analysis] settings a source is read with, so that its own analysis stays fast (the
#: clearance examples' 400 steps take about 3 s; Andrews' 0.03 s at 1e-8, 5 s)
SOURCE_SETTINGS = {
    "examples/clearance/locomotive.toml": {"t_end": 2.0, "steps": 16},
    "examples/clearance/slider_guided_twice.toml": {"t_end": 0.5, "steps": 16},
    "examples/dynamics/andrews.toml": {"t_end": 0.003, "tolerance": 1e-5},
}

#: the analyses whose work grows with the interval and the steps beyond the others'
SLOW_TYPES = ("dynamic", "dinamica", "clearance", "joc")
#: the fast campaign's caps (``generate(..., extreme=False)``), which bound each case's work
#: (not its time): a dynamic run over at most DYNAMIC_T_END s in at most DYNAMIC_STEPS steps,
#: a clearance run over at most CLEARANCE_T_END s in at most CLEARANCE_STEPS steps, a
#: tolerance in TOLERANCE_RANGE and initial rates of at most RATE_LIMIT (a dynamic run's steps
#: grow as the rates, the interval and 1/tolerance^(1/3); a clearance run's integration steps
#: grow as the motion over its interval: all_elements.toml over its 1 s takes ~1,750
#: evaluations of the least-norm right-hand side, ~30 s, over 0.05 s ~2 s)
DYNAMIC_T_END, DYNAMIC_STEPS = 0.01, 10
CLEARANCE_T_END, CLEARANCE_STEPS = 0.05, 20
TOLERANCE_RANGE = (1e-8, 1e-3)
RATE_LIMIT = 100.0

#: element types and their keys (besides type and name), as in docs/model-format.md
TYPES = {
    "fixed": ("anc1",),
    "revolute": ("anc1", "anc2"),
    "prismatic": ("anc1", "anc2"),
    "pin_slot": ("anc1", "anc2"),
    "transmission": ("anc1", "anc2", "T", "C", "arm"),
    "torsor": ("anc1", "C", "axes"),
    "spring": ("anc1", "anc2", "C"),
    "torsional_spring": ("anc1", "anc2", "C"),
    "angular_actuator": ("anc1", "anc2", "law", "C"),
    "linear_actuator": ("anc1", "anc2", "law", "C"),
}
ALIASES = ("enllac_fix", "articulacio", "piu_guia", "transmissio", "molla_amortidor_lineal",
           "molla_amortidor_torsional", "actuador_angular", "actuador_lineal")
LAWS = ("polynomial", "harmonic", "ramp", "bezier_c1", "bezier_c2", "polinomica", "harmonica",
        "rampa")
ANCHOR_KEYS = ("anc1", "anc2", "arm")

NAN, INF = float("nan"), float("inf")
BAD_NUMBERS = (NAN, INF, -INF, 1e300, -1e300, 1e308, -1e308, 5e-324, -5e-324, 0.0, -0.0, 0, -1,
               -1.0, 1e-300, 1e200, 10**30, -10**30, 2**63 - 1, 10**400)
LONG_NAME = "x" * 1_000_000
WEIRD_NAMES = ("", " ", "a b", "a,b", 'a"b', "a'b", "a.b", "a=b", "#a", "Ωμέγα", "名前", "😀",
               "tab\there", "new\nline", "nul\x00", "\u202eevil", "a\\b", "-", "*", "[x]", "t",
               "ground", "crank.*", "Força", "a;b", LONG_NAME)
CP1252_NAMES = ("Sòlid", "manovel·la", "biela_ñ", "pistó", "Força", "€uro", "àéíòú", "Çarro",
                "naïve", "Ærø", "ñandú", "guía", "“cotxe”")
FILE_NAMES = ("my model.toml", "mòdel ñ.toml", "model", "model.TOML", "model.txt", "a,b.toml",
              ".toml", "model.toml.toml", "名前.toml", "x" * 200 + ".toml", "model (1).toml")


# --------------------------------------------------------------------------- TOML writer

class Raw:
    """A value written verbatim (e.g. a TOML date, which tomllib reads as a datetime)."""

    def __init__(self, text: str):
        self.text = text

    def __repr__(self):
        return f"Raw({self.text!r})"


class Deep:
    """An array (or inline table) nested ``depth`` levels deep around ``leaf``."""

    def __init__(self, depth: int, leaf=None, table: bool = False):
        self.depth, self.leaf, self.table = depth, leaf, table

    def __repr__(self):
        kind = "inline table" if self.table else "array"
        return f"<{kind} nested {self.depth} deep>"


_BARE = re.compile(r"[A-Za-z0-9_-]+\Z")
_PLAIN = re.compile(r'[^"\\\x00-\x1f\x7f]*\Z')
_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f",
            "\r": "\\r"}


def toml_string(s: str) -> str:
    """A TOML basic string."""
    if _PLAIN.match(s):
        return f'"{s}"'
    out = []
    for ch in s:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_key(k) -> str:
    k = str(k)
    return k if _BARE.match(k) else toml_string(k)


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return toml_string(v)
    if isinstance(v, Raw):
        return v.text
    if isinstance(v, Deep):
        leaf = "" if v.leaf is None else toml_value(v.leaf)
        if v.table:
            return "{ a = " * v.depth + (leaf or "{}") + " }" * v.depth
        return "[" * v.depth + leaf + "]" * v.depth
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        if not v:
            return "{}"
        return "{ " + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()
                                if x is not None) + " }"
    raise TypeError(f"no TOML for {type(v).__name__}")


def _is_table_array(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def dumps(doc: dict) -> str:
    """TOML text of ``doc``: top-level values, then ``[table]``s and ``[[array]]``s, with
    everything below them written inline (``points = { A = [0.1, 0.0] }``); a key whose
    value is None is left out."""
    lines = [f"{toml_key(k)} = {toml_value(v)}" for k, v in doc.items()
             if v is not None and not isinstance(v, dict) and not _is_table_array(v)]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines += ["", f"[{toml_key(k)}]"]
            lines += [f"{toml_key(kk)} = {toml_value(vv)}" for kk, vv in v.items()
                      if vv is not None]
        elif _is_table_array(v):
            for entry in v:
                lines += ["", f"[[{toml_key(k)}]]"]
                lines += [f"{toml_key(kk)} = {toml_value(vv)}" for kk, vv in entry.items()
                          if vv is not None]
    return "\n".join(lines).lstrip("\n") + "\n"


# --------------------------------------------------------------------------- the mutant

_SOURCE_DOCS: dict[str, dict] = {}


def source_doc(source: str) -> dict:
    """The parsed model file (a fresh copy), with its ``SOURCE_SETTINGS``."""
    if source not in _SOURCE_DOCS:
        doc = tomllib.loads((ROOT / source).read_text(encoding="utf-8"))
        doc.get("analysis", {}).update(SOURCE_SETTINGS.get(source, {}))
        _SOURCE_DOCS[source] = doc
    return copy.deepcopy(_SOURCE_DOCS[source])


@dataclass
class Mutant:
    """A mutated model file: ``name``, ``data`` (bytes), what was done (``kinds``, ``notes``)."""

    seed: int
    source: str
    doc: dict
    name: str
    kinds: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    encoding: str = "utf-8"
    header: str = ""                      # text put before the TOML (a comment)
    byte_ops: list = field(default_factory=list)
    data: bytes = b""
    extreme: bool = False                 # valid values a run may take long on allowed
    capped: list[str] = field(default_factory=list)   # what the fast campaign capped

    @property
    def description(self) -> str:
        if not self.notes:
            return f"{self.source} (unchanged)"
        caps = [f"fast: {', '.join(self.capped)}"] if self.capped else []
        return f"{self.source}: " + "; ".join(self.notes + caps)


def short(v, n: int = 48) -> str:
    """repr of a value, cut to about n characters."""
    text = repr(v)
    return text if len(text) <= n else f"{text[:n]}…({len(text)} chars)"


def _list(doc, key) -> list[dict]:
    v = doc.get(key)
    if isinstance(v, dict):
        return [v]
    return [x for x in v if isinstance(x, dict)] if isinstance(v, list) else []


def solids(doc) -> list[dict]:
    return _list(doc, "solid")


def elements(doc) -> list[dict]:
    return _list(doc, "element")


def _label(entry: dict) -> str:
    name = entry.get("name")
    kind = entry.get("type")
    head = "element" if "type" in entry else "solid"
    return f"{head} {short(name, 24)}" + (f" ({short(kind, 24)})" if kind is not None else "")


def _points(doc, key="points") -> list[tuple[str, str]]:
    out = []
    for s in solids(doc):
        if isinstance(s.get("name"), str) and isinstance(s.get(key), dict):
            out += [(s["name"], p) for p in s[key]]
    return out


def _anchor_solid(anchor) -> str | None:
    return anchor.split(".")[0] if isinstance(anchor, str) else None


def _fixed_solids(doc) -> list[str]:
    return [e.get("anc1") for e in elements(doc)
            if e.get("type") in ("fixed", "enllac_fix") and isinstance(e.get("anc1"), str)]


def _moving_solids(doc) -> list[str]:
    fixed = _fixed_solids(doc)
    return [s["name"] for s in solids(doc) if isinstance(s.get("name"), str)
            and s["name"] not in fixed]


def _revolutes(doc) -> list[dict]:
    return [e for e in elements(doc) if e.get("type") in ("revolute", "articulacio")
            and isinstance(e.get("anc1"), str) and isinstance(e.get("anc2"), str)]


def _walk(node, path=""):
    """(parent, key, path, value) of every value below ``node``."""
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for k, v in items:
        if isinstance(node, dict):
            where = f"{path}.{short(k, 24) if not _BARE.match(str(k)) else k}" if path else str(k)
        else:
            label = f" {short(v.get('name'), 24)}" if isinstance(v, dict) and "name" in v else ""
            where = f"{path}[{k + 1}{label}]"
        yield node, k, where, v
        if isinstance(v, (dict, list)):
            yield from _walk(v, where)


def _slots(doc, pred=lambda v: True, keys=None) -> list:
    out = [s for s in _walk(doc) if pred(s[3])]
    if keys is not None:
        out = [s for s in out if s[1] in keys]
    return out


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _unique(doc, base: str) -> str:
    taken = {e.get("name") for e in solids(doc) + elements(doc) if isinstance(e.get("name"), str)}
    name, k = base, 1
    while name in taken:
        k += 1
        name = f"{base}{k}"
    return name


def _add_element(doc, entry: dict) -> dict:
    if not isinstance(doc.get("element"), list):
        doc["element"] = elements(doc)
    entry = {"type": entry.pop("type"), "name": _unique(doc, entry.pop("name")), **entry}
    doc["element"].append(entry)
    return entry


def _analysis(doc) -> dict:
    if not isinstance(doc.get("analysis"), dict):
        doc["analysis"] = {}
    return doc["analysis"]


def _rename(doc, entry: dict, new: str, propagate: bool) -> str:
    """Give a solid or element a new name; with ``propagate``, the anchors follow."""
    old = entry.get("name")
    entry["name"] = new
    if not propagate or not isinstance(old, str) or "type" in entry:
        return ""
    for e in elements(doc):
        for key in ANCHOR_KEYS:
            a = e.get(key)
            if isinstance(a, str) and (a == old or a.startswith(old + ".")):
                e[key] = new + a[len(old):]
    return " (anchors renamed too)"


def _rename_point(doc, solid: str, old: str, new: str, key="points") -> None:
    for s in solids(doc):
        if s.get("name") == solid and isinstance(s.get(key), dict):
            s[key] = {(new if k == old else k): v for k, v in s[key].items()}
    for e in elements(doc):
        for k in ANCHOR_KEYS:
            if e.get(k) == f"{solid}.{old}":
                e[k] = f"{solid}.{new}"


class _Skip(Exception):
    """The mutation does not apply to this document."""


# --------------------------------------------------------------------------- mutation kinds

def m_delete_key(rng, m):
    slots = _slots(m.doc)
    slots = [s for s in slots if isinstance(s[0], dict) and s[0] is not m.doc]
    if not slots:
        raise _Skip
    parent, key, where, _ = rng.choice(slots)
    del parent[key]
    return f"deleted {where}"


def m_delete_section(rng, m):
    doc = m.doc
    options = ["[model]", "[analysis]", "every [[solid]]", "every [[element]]", "one [[solid]]",
               "one [[element]]", "the fixed links", "a solid's points", "a solid's lines",
               "all but the first solid"]
    what = rng.choice(options)
    if what == "[model]":
        doc.pop("model", None)
    elif what == "[analysis]":
        doc.pop("analysis", None)
    elif what == "every [[solid]]":
        doc.pop("solid", None)
    elif what == "every [[element]]":
        doc.pop("element", None)
    elif what == "one [[solid]]" and solids(doc) and isinstance(doc.get("solid"), list):
        victim = rng.choice(doc["solid"])
        doc["solid"].remove(victim)
        what = f"[[solid]] {short(victim.get('name'))}"
    elif what == "one [[element]]" and isinstance(doc.get("element"), list) and doc["element"]:
        victim = rng.choice(doc["element"])
        doc["element"].remove(victim)
        what = f"[[element]] {short(victim.get('name'))}"
    elif what == "the fixed links" and isinstance(doc.get("element"), list):
        doc["element"] = [e for e in doc["element"]
                          if not (isinstance(e, dict) and e.get("type") in ("fixed", "enllac_fix"))]
    elif what in ("a solid's points", "a solid's lines"):
        key = "points" if "points" in what else "lines"
        having = [s for s in solids(doc) if key in s]
        if not having:
            raise _Skip
        victim = rng.choice(having)
        del victim[key]
        what = f"{key} of {_label(victim)}"
    elif what == "all but the first solid" and isinstance(doc.get("solid"), list):
        doc["solid"] = doc["solid"][:1]
    else:
        raise _Skip
    return f"deleted {what}"


WRONG = ([], [1.0, 2.0], {}, {"a": 1.0}, True, False, "abc", "1.0", "", 0, 1.5, -3,
         Raw("1979-05-27T07:32:00Z"), Raw("1979-05-27"), Raw("07:32:00"), [[]], ["x"],
         [True, False], [[1.0, 2.0]], {"point": [0.0, 0.0]}, ["crank.A", "rod.A"])
FOCUS = ("name", "type", "anc1", "anc2", "arm", "law", "C", "T", "axes", "steps", "t_end",
         "outputs", "gravity", "mass", "inertia", "cog", "points", "lines", "x", "y", "fi",
         "point", "angle")


def m_wrong_type(rng, m):
    slots = _slots(m.doc, keys=FOCUS) if rng.random() < 0.6 else []
    slots = slots or [s for s in _slots(m.doc) if s[0] is not m.doc] or _slots(m.doc)
    if not slots:
        raise _Skip
    parent, key, where, old = rng.choice(slots)
    choices = [w for w in WRONG if type(w) is not type(old) or isinstance(old, (list, dict))]
    new = copy.deepcopy(rng.choice(choices))
    parent[key] = new
    return f"{where} = {short(new)} (was {short(old)})"


def m_bad_number(rng, m):
    slots = _slots(m.doc, _is_number)
    if not slots:
        raise _Skip
    parent, key, where, old = rng.choice(slots)
    new = rng.choice(BAD_NUMBERS)
    parent[key] = new
    return f"{where} = {short(new)} (was {short(old)})"


def m_duplicate_name(rng, m):
    named = [e for e in solids(m.doc) + elements(m.doc) if "name" in e]
    if len(named) < 2:
        raise _Skip
    a, b = rng.sample(named, 2)
    variant = rng.choice(["copy", "solid and element", "same case-folded"])
    if variant == "solid and element" and solids(m.doc) and elements(m.doc):
        a, b = rng.choice(solids(m.doc)), rng.choice(elements(m.doc))
        if rng.random() < 0.5:
            a, b = b, a
    new = a.get("name")
    if variant == "same case-folded" and isinstance(new, str):
        new = new.upper() if new != new.upper() else new.lower()
    label = _label(b)
    b["name"] = new
    return f"{label} renamed {short(new)}, as {_label(a)}"


def m_weird_name(rng, m):
    new = rng.choice(WEIRD_NAMES)
    propagate = rng.random() < 0.6
    target = rng.choice(["solid", "element", "point", "line", "model"])
    if target == "model":
        if not isinstance(m.doc.get("model"), dict):
            m.doc["model"] = {}
        m.doc["model"]["name"] = new
        return f"[model] name = {short(new)}"
    if target in ("point", "line"):
        pts = _points(m.doc, target + "s")
        if pts:
            solid, old = rng.choice(pts)
            if not propagate:
                for s in solids(m.doc):
                    if s.get("name") == solid:
                        s[target + "s"] = {(new if k == old else k): v
                                           for k, v in s[target + "s"].items()}
            else:
                _rename_point(m.doc, solid, old, new, target + "s")
            return (f"{target} {short(old)} of solid {short(solid)} renamed {short(new)}"
                    + (" (anchors renamed too)" if propagate else ""))
        target = "solid"
    pool = solids(m.doc) if target == "solid" else elements(m.doc)
    if not pool:
        raise _Skip
    entry = rng.choice(pool)
    label = _label(entry)
    extra = _rename(m.doc, entry, new, propagate)
    return f"{label} renamed {short(new)}{extra}"


def m_dangling_anchor(rng, m):
    anchored = [e for e in elements(m.doc) if any(k in e for k in ANCHOR_KEYS)]
    if not anchored:
        raise _Skip
    e = rng.choice(anchored)
    key = rng.choice([k for k in ANCHOR_KEYS if k in e])
    pts = _points(m.doc) or [("ground", "O")]
    s, p = rng.choice(pts)
    lines = _points(m.doc, "lines")
    other = f"{lines[0][0]}.{lines[0][1]}" if lines else f"{s}.rail"
    new = rng.choice(["nosuch", f"{s}.nosuch", f"nosuch.{p}", f"{s}.", f".{p}", f"{s}.{p}.extra",
                      "", ".", f"{s}..{p}", f" {s}.{p}", f"{s}.{p} ", f"{s.upper()}.{p}",
                      other, f"{s}.{p}" if "line" not in str(e.get("type")) else other])
    old = e[key]
    e[key] = new
    return f"{_label(e)} {key} = {short(new)} (was {short(old)})"


def m_self_anchor(rng, m):
    both = [e for e in elements(m.doc)
            if isinstance(e.get("anc1"), str) and isinstance(e.get("anc2"), str)]
    if not both:
        pts = _points(m.doc) or [("ground", "O")]
        s, p = pts[0]
        e = _add_element(m.doc, {"type": "revolute", "name": "self", "anc1": f"{s}.{p}",
                                 "anc2": f"{s}.{p}"})
        return f"added {_label(e)} with both anchors {s}.{p}"
    e = rng.choice(both)
    variant = rng.choice(["same anchor", "same solid", "solid alone"])
    solid = _anchor_solid(e["anc1"])
    if variant == "same anchor":
        e["anc2"] = e["anc1"]
    elif variant == "same solid":
        others = [p for s, p in _points(m.doc) + _points(m.doc, "lines") if s == solid]
        e["anc2"] = f"{solid}.{rng.choice(others)}" if others else solid
    else:
        e["anc1"] = e["anc2"] = solid
    return f"{_label(e)} anchors on one solid: anc1 = {short(e['anc1'])}, anc2 = {short(e['anc2'])}"


def m_deep_nesting(rng, m):
    depth = rng.choice([600, 600, 1000, 3000, 100, 50])
    deep = Deep(depth, rng.choice([None, 1.0, "x"]), table=rng.random() < 0.25)
    slots = _slots(m.doc, keys=("C", "cog", "name", "steps", "outputs", "points", "anc1",
                                "gravity", "x", "angle"))
    slots = slots or _slots(m.doc)
    if not slots:
        m.doc["deep"] = deep
        return f"deep = {deep!r}"
    parent, key, where, _ = rng.choice(slots)
    parent[key] = deep
    return f"{where} = {deep!r}"


def _truncate(frac):
    return lambda data: data[:int(len(data) * frac)]


def _insert(pos, chunk):
    return lambda data: data[:int(len(data) * pos)] + chunk + data[int(len(data) * pos):]


def _replace_line_end(new):
    return lambda data: data.replace(b"\n", new)


def m_broken_toml(rng, m):
    variant = rng.choice(["truncated", "garbage bytes", "one bad byte", "BOM", "empty",
                          "duplicate table", "duplicate key", "unterminated string",
                          "CRLF", "lone CR", "only a comment", "NUL bytes"])
    if variant == "truncated":
        frac = rng.random()
        m.byte_ops.append(_truncate(frac))
        return f"truncated at {frac:.0%}"
    if variant == "garbage bytes":
        pos, chunk = rng.random(), rng.randbytes(rng.randint(1, 40))
        m.byte_ops.append(_insert(pos, chunk))
        return f"{len(chunk)} random bytes inserted at {pos:.0%}"
    if variant == "one bad byte":
        pos, byte = rng.random(), rng.choice([b"\x00", b"\xff", b"\x80", b"\xc3", b"\x1b", b"\x7f"])
        m.byte_ops.append(lambda d: d[:int(len(d) * pos)] + byte + d[int(len(d) * pos) + 1:])
        return f"byte {byte!r} at {pos:.0%}"
    if variant == "BOM":
        m.byte_ops.append(lambda d: b"\xef\xbb\xbf" + d)
        return "UTF-8 byte order mark at the start"
    if variant == "empty":
        m.byte_ops.append(lambda d: b"")
        return "empty file"
    if variant == "duplicate table":
        m.byte_ops.append(lambda d: d + b"\n[analysis]\nsteps = 3\n\n[model]\nname = 'again'\n")
        return "[analysis] and [model] appended again"
    if variant == "duplicate key":
        m.byte_ops.append(lambda d: b"title = 1\ntitle = 2\n" + d)
        return "a key given twice"
    if variant == "unterminated string":
        pos = rng.random()
        m.byte_ops.append(_insert(pos, b'\nname = "abc\n'))
        return f"unterminated string at {pos:.0%}"
    if variant == "CRLF":
        m.byte_ops.append(_replace_line_end(b"\r\n"))
        return "CRLF line ends"
    if variant == "lone CR":
        m.byte_ops.append(_replace_line_end(b"\r"))
        return "CR line ends"
    if variant == "only a comment":
        m.byte_ops.append(lambda d: b"# nothing here\n")
        return "a file with only a comment"
    m.byte_ops.append(lambda d: d.replace(b" = ", b" =\x00 ", 1))
    return "NUL byte after the first '='"


def m_cp1252(rng, m):
    k = rng.randint(1, 3)
    names = rng.sample(CP1252_NAMES, k)
    done = []
    for new in names:
        target = rng.choice(["solid", "element", "point"])
        if target == "point" and _points(m.doc):
            solid, old = rng.choice(_points(m.doc))
            _rename_point(m.doc, solid, old, new)
            done.append(f"point {solid}.{old} → {new}")
            continue
        pool = solids(m.doc) if target == "solid" else elements(m.doc)
        pool = pool or solids(m.doc) or elements(m.doc)
        if not pool:
            continue
        entry = rng.choice(pool)
        old = entry.get("name")
        _rename(m.doc, entry, new, propagate=True)
        done.append(f"{short(old, 24)} → {new}")
    m.header = "# Anàlisi cinemàtica — exportat de PAM (Sòlid 0: referència)\n"
    m.encoding = "cp1252"
    return "encoded in cp1252 with a Catalan comment" + (f", renamed {', '.join(done)}" if done
                                                         else "")


def m_encoding(rng, m):
    enc = rng.choice(["utf-16", "utf-16-le", "latin-1", "utf-32"])
    m.header = "# Sòlid, Força, Anàlisi\n"
    m.encoding = enc
    return f"encoded in {enc}"


STEPS = (1, 2, 0, -1, 10**30, 2**63 - 1, 2**31, 2**53, 1e30, 1.0, 100.5, True, "100", 3,
         -(2**63), 10**400)
T_ENDS = (1e7, 1e300, 5e-324, 1e-300, 0.0, -1.0, INF, NAN, 1e308, 1e-9, 1e-15, 10**30, "1.0")


def m_steps(rng, m):
    new = rng.choice(STEPS)
    _analysis(m.doc)["steps"] = new
    return f"steps = {short(new)}"


def m_t_end(rng, m):
    new = rng.choice(T_ENDS)
    _analysis(m.doc)["t_end"] = new
    return f"t_end = {short(new)}"


def m_law_constants(rng, m):
    with_c = [e for e in elements(m.doc) if "C" in e or "law" in e]
    if not with_c:
        raise _Skip
    e = rng.choice(with_c)
    variant = rng.choice(["one extreme", "all extreme", "length", "law", "C1 = C2", "C1 > C2"])
    c = e.get("C")
    c = list(c) if isinstance(c, list) else [c if _is_number(c) else 0.0]
    c += [0.0] * (4 - len(c))
    if variant == "one extreme":
        i = rng.randrange(len(c))
        c[i] = rng.choice([1e308, -1e308, 5e-324, -5e-324, 1e300, NAN, INF, -INF, 1e200])
        e["C"] = c
        return f"{_label(e)} C[{i + 1}] = {short(c[i])}"
    if variant == "all extreme":
        v = rng.choice([1e308, 5e-324, -1e308, 1e300])
        e["C"] = [v] * len(c)
        return f"{_label(e)} C = [{v!r}, …]"
    if variant == "length":
        new = rng.choice([[], [1.0], [0.0, 1.0, 2.0, 3.0, 4.0, 5.0], 1.0, [[0.0]]])
        e["C"] = new
        return f"{_label(e)} C = {short(new)}"
    if variant == "law":
        new = rng.choice(LAWS + ("cubic", "", "RAMP", "sine"))
        e["law"] = new
        return f"{_label(e)} law = {new!r}"
    law = rng.choice(["ramp", "bezier_c1", "bezier_c2"])
    e["law"] = law
    e["C"] = [0.5, 0.5, 0.0, 1.0] if variant == "C1 = C2" else [0.8, 0.2, 0.0, 1.0]
    if rng.random() < 0.3:
        e["C"][:2] = [5e-324, 5e-324] if variant == "C1 = C2" else [5e-324, 0.0]
    return f"{_label(e)} law = {law!r}, C = {e['C']!r}"


def m_type_swap(rng, m):
    els = [e for e in elements(m.doc) if "type" in e]
    if not els:
        raise _Skip
    if len(els) >= 2 and rng.random() < 0.5:
        a, b = rng.sample(els, 2)
        a["type"], b["type"] = b["type"], a["type"]
        return f"types of {short(a.get('name'))} and {short(b.get('name'))} swapped"
    e = rng.choice(els)
    old = e["type"]
    new = rng.choice(list(TYPES) + list(ALIASES))
    e["type"] = new
    extra = ""
    if new in TYPES and rng.random() < 0.5:     # keep only the keys the new type has
        for key in [k for k in e if k not in ("type", "name") and k not in TYPES[new]]:
            del e[key]
        extra = " (other keys dropped)"
    return f"element {short(e.get('name'))} type {short(old)} → {new!r}{extra}"


def m_fixed_and_jointed(rng, m):
    moving = [s for s in _moving_solids(m.doc)
              if any(_anchor_solid(e.get(k)) == s for e in elements(m.doc) for k in ANCHOR_KEYS)]
    if rng.random() < 0.2 or not moving:
        fixed = _fixed_solids(m.doc)
        target = fixed[0] if fixed else (moving[0] if moving else "ground")
    else:
        target = rng.choice(moving)
    e = _add_element(m.doc, {"type": rng.choice(["fixed", "enllac_fix"]), "name": "extra_fix",
                             "anc1": target})
    return f"added {_label(e)} on {short(target)}"


def _hinged_pair(doc, rng):
    """(solid1, solid2, arm): two solids hinged to a common one by revolute joints."""
    partners: dict[str, list[str]] = {}
    for e in _revolutes(doc):
        a, b = _anchor_solid(e["anc1"]), _anchor_solid(e["anc2"])
        partners.setdefault(a, []).append(b)
        partners.setdefault(b, []).append(a)
    arms = [arm for arm, p in partners.items() if len(set(p)) >= 2]
    if not arms:
        return None
    arm = rng.choice(sorted(arms))
    one, two = rng.sample(sorted(set(partners[arm])), 2)
    return one, two, arm


def m_transmission_zero(rng, m):
    value = rng.choice([0.0, 0.0, 0, -0.0, 5e-324])
    trans = [e for e in elements(m.doc) if e.get("type") in ("transmission", "transmissio")]
    if trans:
        e = rng.choice(trans)
        e["T"] = value
        return f"{_label(e)} T = {value!r}"
    pair = _hinged_pair(m.doc, rng)
    if pair is None:
        moving = _moving_solids(m.doc) or ["ground"]
        pair = (moving[0], moving[-1], None)
    entry = {"type": "transmission", "name": "gear0", "anc1": pair[0], "anc2": pair[1],
             "T": value}
    if pair[2] is not None and rng.random() < 0.5:
        entry["arm"] = pair[2]
    e = _add_element(m.doc, entry)
    return f"added {_label(e)} {pair[0]} → {pair[1]} with T = {value!r}"


def m_zero_length_actuator(rng, m):
    lin = [e for e in elements(m.doc) if e.get("type") in ("linear_actuator", "actuador_lineal")]
    variant = rng.choice(["same point", "zero law", "coincident points", "replaces motor"])
    if lin and variant in ("same point", "zero law"):
        e = rng.choice(lin)
        if variant == "same point":
            e["anc2"] = e.get("anc1")
            return f"{_label(e)} anc2 = anc1 = {short(e.get('anc1'))}"
        e["law"], e["C"] = "polynomial", [0.0, 0.0, 0.0, 0.0]
        return f"{_label(e)} law: length 0 at all times"
    revs = _revolutes(m.doc)
    motors = [e for e in elements(m.doc) if e.get("type") in ("angular_actuator",
                                                              "actuador_angular")]
    if variant == "replaces motor" and motors:
        e = rng.choice(motors)
        solid = _anchor_solid(e.get("anc2")) or "ground"
        pts = [p for s, p in _points(m.doc) if s == solid]
        anchor = f"{solid}.{pts[0]}" if pts else solid
        e.update({"type": "linear_actuator", "anc1": anchor, "anc2": anchor})
        e.setdefault("law", "polynomial")
        return f"{_label(e)} replaced by a linear actuator from {anchor} to itself"
    if revs:
        r = rng.choice(revs)
        a1, a2 = r["anc1"], r["anc2"]
    else:
        pts = _points(m.doc) or [("ground", "O")]
        a1 = a2 = "{}.{}".format(*pts[0])
    e = _add_element(m.doc, {"type": "linear_actuator", "name": "cyl0", "anc1": a1, "anc2": a2,
                             "law": "polynomial", "C": [0.0, 0.0, 0.0, 0.0]})
    return f"added {_label(e)} of length 0 between {short(a1)} and {short(a2)}"


def m_zero_length_spring(rng, m):
    springs = [e for e in elements(m.doc) if e.get("type") in ("spring", "molla_amortidor_lineal")]
    variant = rng.choice(["existing", "same point", "coincident points"])
    c = rng.choice([[1.0, 100.0, 0.0, 1.0], [0.0, 100.0, 0.0, 0.0], [0.0, 100.0, 0.1, 0.5]])
    if variant == "existing" and springs:
        e = rng.choice(springs)
        e["anc2"] = e.get("anc1")
        return f"{_label(e)} anc2 = anc1 = {short(e.get('anc1'))}"
    revs = _revolutes(m.doc)
    if variant == "coincident points" and revs:
        r = rng.choice(revs)
        a1, a2 = r["anc1"], r["anc2"]
    else:
        pts = _points(m.doc) or [("ground", "O")]
        a1 = a2 = "{}.{}".format(*rng.choice(pts))
    e = _add_element(m.doc, {"type": "spring", "name": "k0", "anc1": a1, "anc2": a2, "C": c})
    return f"added {_label(e)} between {short(a1)} and {short(a2)}, C = {c}"


def m_cog_far(rng, m):
    pool = solids(m.doc)
    if not pool:
        raise _Skip
    s = rng.choice(pool)
    s["cog"] = list(rng.choice([[1e200, 0.0], [1e200, 1e200], [-1e200, 5e-324], [0.0, 1e300],
                                [1e308, 1e308], [1e154, 1e154]]))
    extra = ""
    if rng.random() < 0.5:
        s["mass"] = rng.choice([1.0, 1e300, 5e-324])
        extra = f", mass = {s['mass']!r}"
    return f"{_label(s)} cog = {s['cog']!r}{extra}"


def m_unknown_key(rng, m):
    where = rng.choice(["model", "solid", "element", "analysis", "top table", "top value",
                        "points"])
    key, value = rng.choice([("foo", 1), ("colour", "red"), ("anc3", "ground"), ("Mass", 1.0),
                             ("solver", {"tolerance": 1e-3}), ("NAME", "x"), ("", 1),
                             ("ñ", 2), ("a.b", 3)])
    if where == "model":
        target = m.doc.setdefault("model", {})
    elif where == "analysis":
        target = _analysis(m.doc)
    elif where in ("solid", "element", "points"):
        pool = solids(m.doc) if where != "element" else elements(m.doc)
        target = rng.choice(pool) if pool else None
        if where == "points" and target is not None:
            target = target.get("points") if isinstance(target.get("points"), dict) else None
            value = [0.0, 0.0]
    elif where == "top table":
        key, target, value = rng.choice(["extra", "solver", "Model", "solids"]), m.doc, {"a": 1}
    else:
        target = m.doc
    if not isinstance(target, dict):
        target, where = m.doc, "top value"
    target[key] = value
    return f"unknown key {key!r} = {short(value)} in {where}"


OUTPUTS = (["nosuch"], [], ["*"], ["*.*"], [""], ["[x"], ["crank.*", "crank.*"], "crank.*", [1],
           [["a"]], ["t"], ["**"], ["Fx"], [".fi"], ["?"], ["x" * 10000], ["*.Fx", "nosuch.*"],
           ["ground.x"], ["Df(t)"], ["*(t)"], ["[!a]*"])


def m_outputs(rng, m):
    new = copy.deepcopy(rng.choice(OUTPUTS))
    _analysis(m.doc)["outputs"] = new
    return f"outputs = {short(new)}"


def m_enum_value(rng, m):
    target = rng.choice(["analysis type", "law", "axes", "element type"])
    new = rng.choice(["nosuch", "", " kinematic", "KINEMATIC", "Kinematic", "quasi-static",
                      "cinematica", "dynamic", "assembly\n", "revolute ", "Revolute", "local",
                      "GLOBAL", "global", "solid", "ramp", "kinetostatic", "ensamblatge",
                      "clearance", "equilibrium", "dinamica", "joc", "equilibri", "Dynamic"])
    if target == "analysis type":
        _analysis(m.doc)["type"] = new
        return f"[analysis] type = {new!r}"
    key = {"law": "law", "axes": "axes", "element type": "type"}[target]
    having = [e for e in elements(m.doc) if key in e] or elements(m.doc)
    if not having:
        raise _Skip
    e = rng.choice(having)
    e[key] = new
    return f"{_label(e)} {key} = {new!r}"


def m_gravity(rng, m):
    new = rng.choice([-9.81, NAN, INF, -INF, 1e308, 0.0, 5e-324, -0.0, 1e300, "9.81", True,
                      [0.0, -9.81], 10**400])
    if not isinstance(m.doc.get("model"), dict):
        m.doc["model"] = {}
    m.doc["model"]["gravity"] = new
    return f"gravity = {short(new)}"


def m_geometry(rng, m):
    variant = rng.choice(["point", "line", "point named as a line", "points not a table",
                          "coincident points"])
    pts, lines = _points(m.doc), _points(m.doc, "lines")
    by_name = {s["name"]: s for s in solids(m.doc) if isinstance(s.get("name"), str)}
    if variant == "point" and pts:
        s, p = rng.choice(pts)
        new = copy.deepcopy(rng.choice([[0.0], [1.0, 2.0, 3.0], [], {"x": 0.0, "y": 0.0}, "0,0",
                                        [NAN, 0.0], [1e308, 1e308], [1e200, -1e200], [True, 0]]))
        by_name[s]["points"][p] = new
        return f"point {s}.{p} = {short(new)}"
    if variant == "line" and lines:
        s, p = rng.choice(lines)
        new = copy.deepcopy(rng.choice([{"point": [0.0, 0.0]}, {"angle": 0.0}, [0.0, 0.0],
                                        {"point": [0.0, 0.0], "angle": 0.0, "extra": 1},
                                        {"point": [0.0, 0.0], "angle": NAN},
                                        {"point": [0.0, 0.0], "angle": 1e300}, 0.0,
                                        {"point": [0.0], "angle": 0.0}]))
        by_name[s]["lines"][p] = new
        return f"line {s}.{p} = {short(new)}"
    if variant == "point named as a line" and lines:
        s, p = rng.choice(lines)
        if not isinstance(by_name[s].get("points"), dict):
            by_name[s]["points"] = {}
        by_name[s]["points"][p] = [0.05, 0.0]
        return f"solid {s} has a point and a line named {p!r}"
    if variant == "coincident points" and pts:
        s, p = rng.choice(pts)
        by_name[s]["points"] = {q: [0.0, 0.0] for q in by_name[s]["points"]}
        return f"every point of solid {s} at its origin"
    pool = solids(m.doc)
    if not pool:
        raise _Skip
    s = rng.choice(pool)
    key = rng.choice(["points", "lines"])
    new = rng.choice([[], "x", [[0.0, 0.0]], 1.0])
    s[key] = new
    return f"{_label(s)} {key} = {short(new)}"


def m_many_copies(rng, m):
    k = rng.choice([2, 3, 10, 40])
    if k == 40 and not m.extreme:
        # 40 free solids make the equilibrium's descent take 30–50 s to give up (200
        # proximal steps, each one an Exudyn system of 40 solids): extreme campaigns only
        k = 10
    if rng.random() < 0.7 and elements(m.doc) and isinstance(m.doc.get("element"), list):
        e = rng.choice(elements(m.doc))
        for i in range(k - 1):
            c = copy.deepcopy(e)
            c["name"] = f"{e.get('name')}_copy{i + 1}" if isinstance(e.get("name"), str) else i
            m.doc["element"].append(c)
        return f"{_label(e)} {k} times (renamed copies)"
    pool = solids(m.doc)
    if not pool or not isinstance(m.doc.get("solid"), list):
        raise _Skip
    s = rng.choice(pool)
    for i in range(k - 1):
        c = copy.deepcopy(s)
        c["name"] = f"{s.get('name')}_copy{i + 1}"
        m.doc["solid"].append(c)
    return f"{_label(s)} {k} times, unconnected copies"


def m_perturb(rng, m):
    """Plausible but unusual values: a few numbers scaled, negated, zeroed or nudged."""
    slots = _slots(m.doc, _is_number)
    slots = [sl for sl in slots if sl[1] not in ("steps",)]
    if not slots:
        raise _Skip
    notes = []
    for parent, key, where, old in rng.sample(slots, min(len(slots), rng.randint(1, 3))):
        how = rng.choice(["scale", "negate", "zero", "nudge"])
        factor, nudge = rng.choice([10.0, 0.1, 1e3, 1e-3, 1e6, 1e-6, 2.0, 0.5]), rng.gauss(0, 0.1)
        try:
            if how == "scale":
                new = old * factor
            elif how == "nudge":
                new = old + nudge
            else:
                new = -old if how == "negate" else 0.0
        except OverflowError:          # a huge int from an earlier mutation
            new = -old
        parent[key] = new
        notes.append(f"{where} = {short(new, 24)} (was {short(old, 24)})")
    return ", ".join(notes)


def m_initial_guess(rng, m):
    """The initial guesses (x, y, fi) of the moving solids scrambled: assembly from afar."""
    moving = [s for s in solids(m.doc) if s.get("name") in _moving_solids(m.doc)]
    if not moving:
        raise _Skip
    spread = rng.choice([0.01, 0.1, 1.0, 10.0, 1e3])
    chosen = rng.sample(moving, rng.randint(1, len(moving)))
    for s in chosen:
        for key in ("x", "y", "fi"):
            base = s.get(key, 0.0) if _is_number(s.get(key, 0.0)) else 0.0
            s[key] = base + rng.uniform(-spread, spread) * (math.pi if key == "fi" else 1.0)
    return (f"x, y, fi of {', '.join(short(s.get('name'), 20) for s in chosen)} moved by up "
            f"to {spread:g}")


def m_file_name(rng, m):
    m.name = rng.choice(FILE_NAMES)
    return f"file named {short(m.name)}"


# ---- the extensions' keys (shared/spec/clearance.md, shared/spec/dynamics.md, angles) -----

#: [analysis] tolerance: invalid values (a clean error), and valid ones within the fast
#: campaign's TOLERANCE_RANGE (its ends, and the loosest allowed, 1e-2)
TOLERANCES = (0, 0.0, -0.0, -1e-6, -1, NAN, INF, -INF, "nan", "NaN", "1e-6", "", True,
              [1e-6], {"value": 1e-6}, 10**400, 0.011, 1.0, 1e300, 1e-2, 1e-3, 1e-4, 1e-6,
              1e-8, Raw("1979-05-27"))
#: valid tolerances a dynamic run may take long on (``generate(..., extreme=True)`` only)
EXTREME_TOLERANCES = (1e-10, 1e-12, 1e-15, 1e-100, 1e-300, 5e-324)
RATES = (0.1, -2.0, 10.0, 0.0, -0.0, NAN, INF, -INF, 1e300, 1e13, 10**400, "1.0", True, [1.0],
         {"x": 1.0})
EXTREME_RATES = (1e3, 1e6, 1e12, -1e12)
CLEARANCE_FLAGS = (True, True, False, "true", 1, 0, "yes", NAN, [True], {"on": True})
VARIATION_KEYS = ("anchor", "dx", "dy", "dangle", "w", "wx", "wy", "wangle", "tau", "fixed_dx",
                  "fixed_dy", "fixed_dangle")
VARIATION_VALUES = (1e-4, -3e-4, 0.0, 2.0, NAN, INF, -INF, 1e300, -1e300, 5e-324, 1e-300,
                    10**400, "1e-4", True, [1e-4], -1.0, 1e6)
ANGLE_UNITS = ("deg", "deg", "rad", "DEG", "degrees", "grad", "", " deg", 1, True, ["deg"],
               NAN, "°")
CLEARANCE_TYPES = ("revolute", "articulacio", "pin_slot", "piu_guia", "prismatic")


def m_tolerance(rng, m):
    pool = TOLERANCES + (EXTREME_TOLERANCES if m.extreme else ())
    new = copy.deepcopy(rng.choice(pool))
    _analysis(m.doc)["tolerance"] = new
    if rng.random() < 0.3:
        _analysis(m.doc)["type"] = rng.choice(["dynamic", "dinamica"])
        return f"tolerance = {short(new)}, type = 'dynamic'"
    return f"tolerance = {short(new)}"


def m_initial_rates(rng, m):
    pool = solids(m.doc)
    if not pool:
        raise _Skip
    notes = []
    for s in rng.sample(pool, rng.randint(1, len(pool))):
        key = rng.choice(["Dx", "Dy", "Dfi", "Dfi", "dfi", "DDfi", "Dz"])
        new = copy.deepcopy(rng.choice(RATES + (EXTREME_RATES if m.extreme else ())))
        s[key] = new
        notes.append(f"{_label(s)} {key} = {short(new)}")
    if rng.random() < 0.3:
        _analysis(m.doc)["type"] = "dynamic"
        notes.append("type = 'dynamic'")
    return ", ".join(notes)


def m_clearance(rng, m):
    els = elements(m.doc)
    if not els:
        raise _Skip
    variant = rng.choice(["one joint", "one joint", "every joint", "any element", "flag value",
                          "none", "analysis"])
    joints = [e for e in els if e.get("type") in CLEARANCE_TYPES]
    if variant == "one joint" and joints:
        e = rng.choice(joints)
        e["clearance"] = True
        return f"{_label(e)} clearance = true"
    if variant == "every joint" and joints:
        for e in joints:
            e["clearance"] = True
        return f"clearance = true on all {len(joints)} joints"
    if variant == "none":
        flagged = [e for e in els if "clearance" in e]
        for e in flagged:
            del e["clearance"]
        return f"clearance flags removed from {len(flagged)} elements"
    if variant == "analysis":
        _analysis(m.doc)["type"] = rng.choice(["clearance", "joc"])
        return f"[analysis] type = {_analysis(m.doc)['type']!r}"
    e = rng.choice(els)
    new = copy.deepcopy(rng.choice(CLEARANCE_FLAGS))
    e["clearance"] = new
    return f"{_label(e)} clearance = {short(new)}"


def _variations(doc) -> list:
    if not isinstance(doc.get("variation"), list):
        doc["variation"] = _list(doc, "variation")
    return doc["variation"]


def m_variation(rng, m):
    variant = rng.choice(["add", "add", "value", "delete key", "unknown key", "duplicate",
                          "bare solid", "dangle on a point", "not a table", "delete all"])
    pts, lines = _points(m.doc), _points(m.doc, "lines")
    if variant == "not a table":
        new = copy.deepcopy(rng.choice([1, "ground.O", [1, 2], {"anchor": "ground.O"}, [[]]]))
        m.doc["variation"] = new
        return f"variation = {short(new)}"
    if variant == "delete all":
        m.doc.pop("variation", None)
        return "every [[variation]] deleted"
    vs = _variations(m.doc)
    if variant in ("add", "bare solid", "dangle on a point") or not vs:
        kind = "line" if lines and (rng.random() < 0.4 or not pts) else "point"
        if not pts and not lines:
            raise _Skip
        s, p = rng.choice(lines if kind == "line" else pts)
        entry = {"anchor": f"{s}.{p}", "dx": rng.choice([1e-4, -3e-4, 0.0, 1e-2]),
                 "dy": rng.choice([2e-4, 0.0, -1e-3])}
        if kind == "line" and rng.random() < 0.6:
            entry["dangle"] = rng.choice([2e-3, -1e-2, 0.0])
        for key in rng.sample(["w", "wx", "wy", "wangle", "tau"], rng.randint(0, 3)):
            entry[key] = rng.choice([0.8, 1.9, 0.3, 0.0, 5.0])
        if variant == "bare solid":
            entry["anchor"] = s
        elif variant == "dangle on a point":
            entry["dangle"] = 1e-3
        vs.append(entry)
        return f"[[variation]] {short(entry, 120)}"
    v = rng.choice(vs)
    if not isinstance(v, dict):
        raise _Skip
    if variant == "value":
        key = rng.choice(VARIATION_KEYS)
        new = copy.deepcopy(rng.choice(VARIATION_VALUES) if key != "anchor" else rng.choice(
            ["nosuch.P", "", ".", "ground", "ground.nosuch", 1.0, ["ground.O"]]))
        v[key] = new
        return f"[[variation]] {short(v.get('anchor'), 24)} {key} = {short(new)}"
    if variant == "delete key" and v:
        key = rng.choice(list(v))
        del v[key]
        return f"[[variation]] {short(v.get('anchor'), 24)}: {key} deleted"
    if variant == "unknown key":
        key = rng.choice(["dfi", "omega", "Tau", "dz", ""])
        v[key] = 1.0
        return f"[[variation]] {short(v.get('anchor'), 24)}: unknown key {key!r}"
    vs.append(copy.deepcopy(v))
    return f"[[variation]] {short(v.get('anchor'), 24)} given twice"


def m_angles(rng, m):
    new = copy.deepcopy(rng.choice(ANGLE_UNITS))
    if not isinstance(m.doc.get("model"), dict):
        m.doc["model"] = {}
    m.doc["model"]["angles"] = new
    return f"[model] angles = {short(new)}"


#: [analysis] backend values: mostly the natural backend (the second formulation, which must
#: solve what Exudyn solves), and names a user may get wrong
BACKEND_VALUES = ("natural", "natural", "natural", "exudyn", "Natural", "nat", "", 3, ["natural"])


def m_backend(rng, m):
    new = copy.deepcopy(rng.choice(BACKEND_VALUES))
    _analysis(m.doc)["backend"] = new
    return f"[analysis] backend = {short(new)}"


def _fast(m) -> list[str]:
    """The fast campaign's caps on the mutant's valid numbers (``SLOW_TYPES``'s interval and
    steps, the tolerance, the initial rates); the notes of what changed."""
    notes = []
    an = m.doc.get("analysis")
    if isinstance(an, dict):
        kind = an.get("type")
        kind = kind.strip().lower() if isinstance(kind, str) else kind
        caps = []
        if kind in ("dynamic", "dinamica"):
            caps = [("t_end", DYNAMIC_T_END), ("steps", DYNAMIC_STEPS)]
        elif kind in ("clearance", "joc"):
            caps = [("t_end", CLEARANCE_T_END), ("steps", CLEARANCE_STEPS)]
        for key, cap in caps:
            v = an.get(key)                   # missing: the defaults, 1 s in 100 steps
            valid = _is_number(v) and v <= (1e9 if key == "t_end" else 10**7)
            if v is None or (valid and v > cap):
                an[key] = cap
                notes.append(f"{key} {short(v, 24)} capped to {cap:g}")
        tol = an.get("tolerance")
        low, high = TOLERANCE_RANGE
        if _is_number(tol) and 0 < tol < low:
            an["tolerance"] = low
            notes.append(f"tolerance {tol!r} capped to {low:g}")
    for s in solids(m.doc):
        for key in ("Dx", "Dy", "Dfi"):
            v = s.get(key)
            if _is_number(v) and RATE_LIMIT < abs(v) <= 1e12:
                s[key] = math.copysign(RATE_LIMIT, v)
                notes.append(f"{_label(s)} {key} {v!r} capped to {s[key]:g}")
    return notes


#: every mutation kind: name -> function(rng, mutant) -> note
KINDS = {
    "delete_key": m_delete_key,
    "delete_section": m_delete_section,
    "wrong_type": m_wrong_type,
    "bad_number": m_bad_number,
    "duplicate_name": m_duplicate_name,
    "weird_name": m_weird_name,
    "dangling_anchor": m_dangling_anchor,
    "self_anchor": m_self_anchor,
    "deep_nesting": m_deep_nesting,
    "broken_toml": m_broken_toml,
    "cp1252": m_cp1252,
    "encoding": m_encoding,
    "steps": m_steps,
    "t_end": m_t_end,
    "law_constants": m_law_constants,
    "type_swap": m_type_swap,
    "fixed_and_jointed": m_fixed_and_jointed,
    "transmission_zero": m_transmission_zero,
    "zero_length_actuator": m_zero_length_actuator,
    "zero_length_spring": m_zero_length_spring,
    "cog_far": m_cog_far,
    "unknown_key": m_unknown_key,
    "outputs": m_outputs,
    "enum_value": m_enum_value,
    "gravity": m_gravity,
    "geometry": m_geometry,
    "many_copies": m_many_copies,
    "perturb": m_perturb,
    "initial_guess": m_initial_guess,
    "file_name": m_file_name,
    "tolerance": m_tolerance,
    "initial_rates": m_initial_rates,
    "clearance": m_clearance,
    "variation": m_variation,
    "angles": m_angles,
    "backend": m_backend,
}
#: how often each kind is drawn, relative to 1 (byte-level kinds hide the others' effects)
WEIGHTS = {"broken_toml": 0.5, "encoding": 0.3, "file_name": 0.5, "deep_nesting": 0.6}


def generate(seed: int, n_mutations: int | None = None, source: str | None = None,
             extreme: bool = False) -> Mutant:
    """The mutant of ``seed``: its source, 1–3 mutations (``n_mutations`` to choose; 0 gives
    the source model as written by ``dumps``), name, bytes and description.

    ``extreme``: valid values that make a run long may stay (tolerances down to 5e-324,
    initial rates up to 1e12, a dynamic run over 1e7 s …); without it, ``_fast`` caps them
    (the fast campaign, whose cases each stay within the runner's time limit)."""
    rng = random.Random(seed)
    src = rng.choice(SOURCES)
    if source is not None:
        src = source
    n = rng.choice((1, 1, 1, 2, 2, 3))
    if n_mutations is not None:
        n = n_mutations
    m = Mutant(seed, src, source_doc(src), Path(src).name, extreme=extreme)
    kinds = list(KINDS)
    weights = [WEIGHTS.get(k, 1.0) for k in kinds]
    for _ in range(n):
        kind = rng.choices(kinds, weights)[0]
        try:
            note = KINDS[kind](rng, m)
        except _Skip:
            note = "not applicable here"
        m.kinds.append(kind)
        m.notes.append(f"{kind}: {note}")
    if not extreme and n:
        m.capped = _fast(m)
    text = m.header + dumps(m.doc)
    data = text.encode(m.encoding, errors="replace")
    for op in m.byte_ops:
        data = op(data)
    m.data = data
    return m


def mutant(seed: int, n_mutations: int | None = None) -> tuple[str, bytes, str]:
    """(file name, file bytes, description) of the mutant of ``seed`` (see ``generate``)."""
    m = generate(seed, n_mutations)
    return m.name, m.data, m.description


def main(argv=None) -> int:
    seeds = [int(a) for a in (argv if argv is not None else sys.argv[1:])] or [0]
    for seed in seeds:
        m = generate(seed)
        print(f"# seed {seed}: {m.name}: {m.description}")
        sys.stdout.write(m.data.decode("utf-8", errors="backslashreplace")[:20000])
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
