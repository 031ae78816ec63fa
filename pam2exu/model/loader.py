"""Reading a model file (TOML, the format of docs/model-format.md)."""
from __future__ import annotations

import tomllib
from pathlib import Path

from .. import registry
from ..elements import ALIASES, ELEMENTS, misplaced_clearance
from ..errors import ModelError, Problem, closest, echo
from ..limits import shown
from .analysis import Analysis
from .model import Model
from .solid import Solid
from .variation import KEYS as _VARIATION_KEYS
from .variation import Variation

_MODEL_KEYS = ("name", "gravity", "angles")
_SOLID_KEYS = ("name", "x", "y", "fi", "mass", "inertia", "cog", "points", "lines", "Dx", "Dy",
               "Dfi")
_ANALYSIS_KEYS = ("type", "t_end", "steps", "outputs", "backend", *registry.OPTIONS)
_TABLES = ("model", "solid", "element", "variation", "analysis")


def load(path: str | Path) -> Model:
    """Read a model file; raises ModelError naming the file and every problem in it.

    The file is TOML with the tables ``[model]`` (name, gravity), ``[[solid]]``,
    ``[[element]]``, ``[[variation]]`` (the clearance analysis's dimension variations) and
    ``[analysis]`` (type, t_end, steps, outputs, backend); the format is
    docs/model-format.md. Every problem is collected before the error is raised; mobility
    is checked later, by ``run``.

    Parameters
    ----------
    path : str or Path
        The model file (UTF-8).

    Returns
    -------
    Model
        The model, validated (``problems()`` is empty), with ``source`` set to ``path``.

    Raises
    ------
    ModelError
        The file cannot be read, is not valid TOML, or has problems: unknown tables or
        keys, unknown element types, bad values or anchors, repeated names, bad
        ``[analysis]`` settings. The message names the file and lists every problem.

    Examples
    --------
    >>> import pam2exu
    >>> model = pam2exu.load("examples/slider_crank.toml")          # doctest: +SKIP
    >>> model.analysis.type, [s.name for s in model.solids]         # doctest: +SKIP
    ('kinetostatic', ['ground', 'crank', 'rod', 'slider'])
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ModelError(f"cannot read the model file: {exc.strerror or exc}", str(path)) \
            from None
    model = loads(decode(raw, str(path)), source=str(path))
    model.encoding = "cp1252" if _cp1252(raw) else "utf-8"
    return model


def _cp1252(raw: bytes) -> bool:
    """The bytes are not UTF-8 (so ``decode`` read them as Windows-1252)."""
    try:
        raw.decode("utf-8-sig")
        return False
    except UnicodeDecodeError:
        return True


def decode(raw: bytes, source: str) -> str:
    """A model file's text: UTF-8 (with or without BOM), else Windows-1252.

    Windows editors and PAM's exports save Windows-1252 ("ANSI"): its accented letters
    (``Força``, ``molla_amortidor``) are read as they are meant. UTF-16 or UTF-32 text
    (``wide_encoding``), and bytes that are neither, are a ModelError that says to save the
    file as UTF-8.
    """
    wide = wide_encoding(raw)
    if wide:
        raise ModelError(f"the file is {wide} text (Notepad's \"Unicode\"), which pam2exu does "
                         "not read: save the file as UTF-8 (Notepad: File > Save as, Encoding: "
                         "UTF-8)", source)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as utf8:
        try:
            return raw.decode("cp1252")
        except UnicodeDecodeError:
            raise ModelError(
                f"the file is not text in UTF-8 or Windows-1252 (byte 0x{raw[utf8.start]:02x} at "
                f"position {utf8.start}): save it as UTF-8 text", source) from None


#: byte-order marks of the encodings of 2 and 4 bytes a character (UTF-32's first: FF FE 00 00
#: begins with UTF-16's FF FE)
_WIDE_BOMS = ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
              (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))


def wide_encoding(raw: bytes) -> str | None:
    """"UTF-16" or "UTF-32" when the bytes are text in that encoding, else None.

    Known by the byte-order mark, or without one by NUL bytes (which no UTF-8 or
    Windows-1252 text has): 2 or 4 bytes a character put a NUL beside every ASCII letter.

    Examples
    --------
    >>> wide_encoding("[model]".encode("utf-16")), wide_encoding("[model]".encode("utf-16-le"))
    ('UTF-16', 'UTF-16')
    >>> wide_encoding("[model]".encode("utf-32-be")), wide_encoding("[model]".encode("utf-8-sig"))
    ('UTF-32', None)
    """
    for bom, name in _WIDE_BOMS:
        if raw.startswith(bom):
            return name
    head = raw[:4096]
    if b"\x00" not in head:
        return None
    return "UTF-32" if head.count(b"\x00") > 0.6 * len(head) else "UTF-16"


def loads(text: str, source: str = "<string>") -> Model:
    """Parse a model from TOML text (see ``load``).

    Parameters
    ----------
    text : str
        The model, in the TOML format of a model file.
    source : str
        Where the text comes from, named in error messages and used as ``Model.source``;
        its stem is the model's name when ``[model]`` has none.

    Returns
    -------
    Model
        The model, validated (``problems()`` is empty).

    Raises
    ------
    ModelError
        The text is not valid TOML, or the model has problems (as for ``load``).

    Examples
    --------
    >>> model = loads('''
    ... [model]
    ... name = "pendulum"
    ...
    ... [[solid]]
    ... name = "ground"
    ...
    ... [[solid]]
    ... name = "bar"
    ... mass = 1.0
    ... points = { O = [0.0, 0.0] }
    ...
    ... [[element]]
    ... type = "enllac_fix"
    ... anc1 = "ground"
    ...
    ... [analysis]
    ... type = "assembly"
    ... ''')
    >>> model.name, model.gravity, [e.type for e in model.elements]
    ('pendulum', 9.81, ['fixed'])
    >>> loads("solid = [{ name = 'a', mas = 1.0 }]", source="demo.toml")
    Traceback (most recent call last):
    ...
    pam2exu.errors.ModelError: demo.toml: [[solid]] #1 'a': unknown key 'mas' (did you ...
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"not valid TOML: {exc}", source) from None
    except RecursionError:
        raise ModelError("not valid TOML for a model: arrays or tables are nested too deeply "
                         "(no model value is nested more than three levels)", source) from None

    problems: list[Problem] = []
    for key in data:
        if key not in _TABLES:
            problems.append(Problem(f"[{echo(key)[1:-1]}]", f"unknown table{closest(key, _TABLES)}; "
                                                f"a model has {', '.join(_TABLES)}"))
    head = _table(data, "model", problems)
    _unknown_keys(head, _MODEL_KEYS, "[model]", problems)
    model = Model(name=head.get("name", Path(source).stem), gravity=head.get("gravity", 9.81),
                  source=source, angles=head.get("angles", "rad"))
    for k, entry in enumerate(_array(data, "solid", problems), start=1):
        where = f"[[solid]] #{k}" + (f" '{shown(entry['name'])}'" if "name" in entry else "")
        _unknown_keys(entry, _SOLID_KEYS, where, problems)
        if "name" not in entry:
            problems.append(Problem(where, "'name' is missing"))
        keys = {key: v for key, v in entry.items() if key in _SOLID_KEYS}
        keys.setdefault("name", f"solid{k}")
        model.add_solid(Solid(**keys, position=k))
    for k, entry in enumerate(_array(data, "element", problems), start=1):
        where = f"[[element]] #{k}" + (f" '{shown(entry['name'])}'" if "name" in entry else "")
        kind = entry.get("type")
        if kind is None:
            problems.append(Problem(where, f"'type' is missing; one of {', '.join(ELEMENTS)}"))
            continue
        cls = ELEMENTS.get(ALIASES.get(kind, kind)) if isinstance(kind, str) else None
        if cls is None:
            problems.append(Problem(where, f"unknown element type {echo(kind)}"
                                           f"{closest(kind, [*ELEMENTS, *ALIASES])}; known types: "
                                           f"{', '.join(ELEMENTS)}"))
            continue
        keys = {key: v for key, v in entry.items() if key != "type" and key in cls.keys()}
        added = model.add(cls(**keys, position=k))      # names it <type><n> when unnamed
        if "clearance" in entry and "clearance" not in cls.keys():
            problems.append(Problem(added.where, misplaced_clearance(cls.type)))
        _unknown_keys({key: v for key, v in entry.items() if key != "clearance"}, cls.keys(),
                      added.where, problems)
    for k, entry in enumerate(_array(data, "variation", problems), start=1):
        added = model.add_variation(Variation(
            **{key: v for key, v in entry.items() if key in _VARIATION_KEYS}, position=k))
        _unknown_keys(entry, _VARIATION_KEYS, added.where, problems)
    table = _table(data, "analysis", problems)
    _unknown_keys(table, _ANALYSIS_KEYS, "[analysis]", problems)
    model.analysis = Analysis(**{k: v for k, v in table.items() if k in _ANALYSIS_KEYS})
    problems += model.problems()
    if problems:
        raise ModelError(problems, source)
    model.issue_warnings()
    return model


def _table(data, key, problems) -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        problems.append(Problem(f"[{key}]", f"must be a table [{key}], not a value"))
        return {}
    return value


def _array(data, key, problems) -> list[dict]:
    value = data.get(key, [])
    if isinstance(value, dict):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        problems.append(Problem(f"[[{key}]]", f"must be an array of tables [[{key}]]"))
        return []
    return value


def _unknown_keys(entry: dict, allowed, where, problems) -> list[str]:
    bad = [key for key in entry if key not in allowed]
    for key in bad:
        problems.append(Problem(where, f"unknown key {echo(key)}{closest(key, allowed)}; "
                                       f"allowed keys: {', '.join(allowed)}"))
    return bad
