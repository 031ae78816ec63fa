"""The model: solids, elements and analysis settings, built in Python or loaded from TOML.

``Model.problems()`` collects every problem before any numerics; ``Model.mechanism()``
returns the validated, resolved form the translation and the analyses work on.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

from .. import limits, registry
from ..elements import ALIASES, ELEMENTS, Element, misplaced_clearance
from ..errors import ModelError, Problem, VariationWarning, closest, echo, warn_outside
from ..limits import is_number as _number
from .angles import angles_problem
from .mechanism import Mechanism
from .solid import Scope, Solid, solid_problems
from .variation import KEYS as VARIATION_KEYS
from .variation import Variation, variation_problems

#: the loosest integration tolerance of the dynamic analysis (its error per unit of value)
MAX_TOLERANCE = 1e-2


@dataclass
class Analysis:
    """What to run: ``type``, the interval [0, ``t_end``] in ``steps`` intervals, ``outputs``.

    The ``[analysis]`` table of a model file, ``Model.analysis`` in Python: the defaults of
    ``run``, whose arguments override them for one run. Values are checked by
    ``problems`` (called by ``Model.problems`` and by ``run``), not here.

    Parameters
    ----------
    type : str
        ``'assembly'``, ``'quasi_static'``, ``'kinematic'`` or ``'kinetostatic'``
        (``pam2exu.registry.ANALYSES``); PAM's Catalan names (``'ensamblatge'``,
        ``'quasi_estatica'``, ``'cinematica'``, ``'cinetostatica'``) are read as these.
    t_end : float
        End of the interval [0, t_end] [s], > 0 (not used by an assembly, which solves
        t = 0 only).
    steps : int
        Number of intervals, ≥ 1: results have steps + 1 rows at t_k = k t_end / steps.
    outputs : list of str, optional
        Names or patterns of the columns to compute and keep (``crank.fi``, ``crank.*``,
        ``*.Fx`` or a bare ``Fx``); None keeps every column of the analysis.
    backend : str
        What solves the positions: ``'exudyn'`` (the default; ``pam2exu.registry.BACKENDS``
        lists the backends).
    tolerance : float
        Accuracy required of the ``dynamic`` analysis's time integration: its error at
        most tolerance · (1 + |value|) on every coordinate and rate, SI units;
        0 < tolerance ≤ 1e-2 [-]. Other analyses ignore it.

    Examples
    --------
    >>> Analysis("kinematic", t_end=0.0, steps=10).problems()
    ['t_end must be a positive number of seconds, got 0.0']
    """

    type: str = "kinematic"
    t_end: float = 1.0
    steps: int = 100
    outputs: list[str] | None = None
    backend: str = registry.DEFAULT_BACKEND
    tolerance: float = 1e-8

    #: keys beyond the contract's [analysis] table (docs/model-format.md says so)
    EXTENSIONS = ("backend", "tolerance")

    def __post_init__(self):
        self._canonical_type()

    def _canonical_type(self) -> None:
        """A Catalan analysis name becomes the contract's."""
        kind = registry.analysis_type(self.type) if isinstance(self.type, str) else None
        if kind is not None:
            self.type = kind.name

    def problems(self) -> list[str]:
        """What is wrong with these settings, one message each (empty when they are sound).

        Returns
        -------
        list of str
            Messages without a place (``Model.problems`` puts them under
            ``"[analysis]"``).
        """
        out = []
        self._canonical_type()
        if not isinstance(self.type, str) or self.type not in registry.ANALYSES:
            names = list(registry.ANALYSES)
            aliases = [a.alias for a in registry.ANALYSES.values()]
            out.append(f"unknown analysis type {echo(self.type)}"
                       f"{closest(str(self.type), names + aliases)}; known types: "
                       f"{', '.join(names)} (Catalan: {', '.join(aliases)})")
        if not isinstance(self.backend, str) or self.backend not in registry.BACKENDS:
            names = list(registry.BACKENDS)
            out.append(f"unknown backend {echo(self.backend)}{closest(str(self.backend), names)}; "
                       f"known backends: {', '.join(names)}")
        low, high = limits.T_END
        if not _number(self.t_end) or self.t_end <= 0:
            out.append(f"t_end must be a positive number of seconds, got {echo(self.t_end)}")
        elif not low <= self.t_end <= high:
            out.append(f"t_end = {self.t_end:g} s is out of range: it must lie between "
                       f"{low:g} s and {high:g} s")
        if isinstance(self.steps, bool) or not isinstance(self.steps, int) or self.steps < 1:
            out.append(f"steps must be a positive whole number, got {echo(self.steps)}")
        elif self.steps > limits.SOLVE_STEPS:
            out.append(f"steps = {self.steps} is more than pam2exu runs: one run solves the "
                       f"positions at most {limits.SOLVE_STEPS:,} times, once a step at least. "
                       "Use fewer steps (every row is exact, whatever the step), or split "
                       "the interval into several runs, each over a shorter t_end")
        if self.outputs is not None and (
                not isinstance(self.outputs, (list, tuple))
                or not all(isinstance(o, str) for o in self.outputs)):

            out.append("outputs must be a list of names or patterns, e.g. [\"crank.*\", \"Fx\"]")
        if not _number(self.tolerance) or not 0 < self.tolerance <= MAX_TOLERANCE:
            out.append(f"tolerance must be a number in (0, {MAX_TOLERANCE:g}], the error "
                       f"allowed per unit of a coordinate or rate, got {echo(self.tolerance)}")
        return out


class Model:
    """A PAM model: solids, elements and the analysis to run.

    Build it in Python with ``add_solid``, ``add`` (and ``add_variation``, for the clearance
    analysis), or read it from a file with ``load``; run it with ``pam2exu.run``.
    ``add_solid`` and ``add`` reject unknown keys and element
    types at once; values, anchors and names are checked by ``problems``, ``validate``,
    ``mechanism`` and ``run``, which report every problem at once. ``model[name]`` is the
    solid or element of that name (``KeyError`` when there is none).

    Parameters
    ----------
    name : str
        The model's name, shown in results, pictures and messages.
    gravity : float
        Magnitude of the gravitational acceleration, along −y [m/s²], ≥ 0 (0: none).
        Used by the quasi_static and kinetostatic analyses.
    source : str, optional
        The model file, named in error messages (set by ``load``).
    angles : str
        The unit of every angle and angular rate the model gives: ``"rad"`` (the default)
        or ``"deg"`` (``[model] angles``, an extension of the format): the solids' ``fi``,
        lines' ``angle``, a transmission's ``C``, a torsional spring's ``C3``, an angular
        actuator's law constants in the unit of f, a variation's ``dangle``; the results
        of ``run`` are then in degrees too (``model/angles.py``).

    Attributes
    ----------
    name : str
        As the parameter.
    gravity : float
        As the parameter [m/s²].
    source : str or None
        As the parameter.
    solids : list of Solid
        The solids, in the order they were added (the order of the coordinates).
    elements : list of Element
        The elements (``pam2exu.ELEMENTS`` classes), in the order they were added.
    analysis : Analysis
        The default analysis settings (``[analysis]`` of a file): kinematic, t_end = 1 s,
        100 steps, every output.
    variations : list of Variation
        The dimension variations (``[[variation]]``), in the order they were added; read by
        the clearance analysis only.

    Examples
    --------
    >>> m = Model("pendulum", gravity=9.81)
    >>> m.add_solid("ground", points={"O": [0, 0]})              # doctest: +ELLIPSIS
    Solid(...)
    >>> m.add_solid("bar", mass=1.0, points={"O": [0, 0]})       # doctest: +ELLIPSIS
    Solid(...)
    >>> m.add("fixed", anc1="ground").name
    'fixed1'
    >>> m.add("revolute", name="O", anc1="ground.O", anc2="bar.O").type
    'revolute'
    >>> m["bar"].mass
    1.0
    >>> [str(p) for p in m.problems()]
    []
    """

    def __init__(self, name: str = "model", gravity: float = 9.81, source: str | None = None,
                 angles: str = "rad"):
        self.name = name
        self.gravity = gravity
        self.source = source
        self.angles = angles
        #: how the model file was read: "utf-8", or "cp1252" (Windows-1252, see ``load``)
        self.encoding = "utf-8"

        self.solids: list[Solid] = []
        self.elements: list[Element] = []
        self.variations: list[Variation] = []
        self.analysis = Analysis()
        self._warned: set[str] = set()

    # ---- building ----------------------------------------------------------------------
    def add_solid(self, solid: Solid | str, **keys) -> Solid:
        """Add a solid (a Solid, or a name and its keys); returns it.

        Parameters
        ----------
        solid : Solid or str
            A Solid, or the name of a new one.
        **keys
            The new solid's keys, as for ``Solid``: ``x``, ``y`` [m], ``fi`` [rad],
            ``mass`` [kg], ``inertia`` [kg·m²], ``cog`` [m], ``points`` [m], ``lines``
            [m, rad]. None when ``solid`` is a Solid.

        Returns
        -------
        Solid
            The solid added (its ``position`` set to its number in the model when unset).

        Raises
        ------
        ModelError
            A key that a solid does not have (the message suggests the nearest). The values
            and the name are checked later, by ``problems``.
        TypeError
            Keys given together with a Solid object.

        Examples
        --------
        >>> m = Model("demo")
        >>> m.add_solid("crank", fi=0.3, points={"O": [0, 0], "A": [0.1, 0]}).position
        1
        >>> m.add_solid("rod", lenght=0.3)
        Traceback (most recent call last):
        ...
        pam2exu.errors.ModelError: a solid has no key 'lenght'
        """
        if not isinstance(solid, Solid):
            allowed = [f.name for f in fields(Solid)]
            unknown = [k for k in keys if k not in allowed]
            if unknown:
                raise ModelError([f"a solid has no key '{k}'{closest(k, allowed)}" for k in unknown],
                                 self.source)
            solid = Solid(solid, **keys)
        elif keys:
            raise TypeError(f"add_solid: keys {', '.join(map(repr, keys))} given with a Solid "
                            f"object; set them on the Solid, or pass its name and the keys")
        if solid.position is None:
            solid.position = len(self.solids) + 1
        self.solids.append(solid)
        return solid

    def add(self, element: Element | str, **keys) -> Element:
        """Add an element (an Element, or a type name or Catalan alias and its keys).

        ``add_element`` is the same method.

        Parameters
        ----------
        element : Element or str
            An element object (``pam2exu.Revolute(name="A", anc1="crank.A",
            anc2="rod.A")``), or a type name of ``pam2exu.ELEMENTS`` (``"revolute"``) or its
            Catalan alias (``"articulacio"``).
        **keys
            The new element's keys: ``name``, the anchors ``anc1`` and ``anc2`` (a
            ``"solid"``, ``"solid.point"`` or ``"solid.line"``, as the type requires) and
            the keys of its type (``law`` and ``C`` of an actuator, ``T``, ``C`` and ``arm``
            of a transmission, …; see the element types). None when ``element`` is an
            Element.

        Returns
        -------
        Element
            The element added. Without a name it is named ``<type><n>``, n counting the
            elements of its type (``revolute2``); its ``position`` is set to its number in
            the model when unset.

        Raises
        ------
        ModelError
            An unknown element type, or a key its type does not have (the message suggests
            the nearest). Anchors and values are checked later, by ``problems``.
        TypeError
            Keys given together with an Element object.

        Examples
        --------
        >>> m = Model("demo")
        >>> m.add("articulacio", anc1="ground.O", anc2="crank.O").name
        'revolute1'
        >>> m.add("angular_actuator", anc1="ground", anc2="crank", law="harmonic",
        ...       C=[0.0, 0.5, 6.0]).type
        'angular_actuator'
        """
        if isinstance(element, str):
            kind = ALIASES.get(element, element)
            if kind not in ELEMENTS:
                raise ModelError(f"unknown element type '{element}'"
                                 f"{closest(element, [*ELEMENTS, *ALIASES])}; known types: "
                                 f"{', '.join(ELEMENTS)}", self.source)
            cls = ELEMENTS[kind]
            unknown = [k for k in keys if k not in {f.name for f in fields(cls)}]
            if unknown:
                raise ModelError([misplaced_clearance(kind) if k == "clearance" else
                                  f"a {kind} has no key '{k}'{closest(k, cls.keys())}; its keys "
                                  f"are: {', '.join(cls.keys()[1:])}" for k in unknown],
                                 self.source)
            element = cls(**keys)
        elif keys:
            raise TypeError(f"add: keys {', '.join(map(repr, keys))} given with an element "
                            f"object; set them on the element, or pass its type and the keys")
        if element.position is None:
            element.position = len(self.elements) + 1
        if element.name is None:
            same = sum(1 for e in self.elements if e.type == element.type)
            element.name = f"{element.type}{same + 1}"
        self.elements.append(element)
        return element

    add_element = add

    def add_variation(self, variation: Variation | str | None = None, **keys) -> Variation:
        """Add a dimension variation (a ``[[variation]]``; only the clearance analysis reads it).

        Parameters
        ----------
        variation : Variation or str, optional
            A Variation, or the anchor of a new one (``"solid.point"`` or ``"solid.line"``;
            or give it as ``anchor=``).
        **keys
            The new variation's keys, as for ``Variation``: ``anchor``, ``dx``, ``dy`` [m],
            ``dangle`` [rad], ``w``, ``wx``, ``wy``, ``wangle`` [rad/s], ``tau`` [s].

        Returns
        -------
        Variation
            The variation added (its ``position`` set to its number when unset).

        Raises
        ------
        ModelError
            A key that a variation does not have (the message suggests the nearest). Values
            and the anchor are checked later, by ``problems``.

        Examples
        --------
        >>> m = Model("demo")
        >>> m.add_variation("ground.O2", dx=3.7e-4, wx=1.91).where
        "[[variation]] #1 (anchor 'ground.O2')"
        """
        if not isinstance(variation, Variation):
            unknown = [k for k in keys if k not in VARIATION_KEYS]
            if unknown:
                raise ModelError([f"a variation has no key '{k}'{closest(k, VARIATION_KEYS)}; "
                                  f"its keys are: {', '.join(VARIATION_KEYS)}" for k in unknown],
                                 self.source)
            variation = Variation(**keys) if variation is None else Variation(variation, **keys)
        elif keys:
            raise TypeError("add_variation: keys given with a Variation object")
        if variation.position is None:
            variation.position = len(self.variations) + 1
        self.variations.append(variation)
        return variation

    def __repr__(self) -> str:       # one line: name, file, counts, analysis (describe.py)
        return registry.resolve("pam2exu.model.describe:one_line")(self)

    def _repr_html_(self) -> str:    # in a notebook (pam2exu.notebook: needs the analyses)
        return registry.resolve("pam2exu.notebook:model_html")(self)

    def __getitem__(self, name: str) -> Solid | Element:
        """The solid or element named ``name``; KeyError (suggesting the nearest) if none."""
        for item in (*self.solids, *self.elements):
            if item.name == name:
                return item
        raise KeyError(f"no solid or element '{name}'"
                       f"{closest(name, [i.name for i in (*self.solids, *self.elements)])}")

    # ---- validation --------------------------------------------------------------------
    def problems(self) -> list[Problem]:
        """Every problem in the model, in file order (empty when the model is sound).

        Checks gravity, each solid's values, each element's keys and anchors, that names are
        unique (solids and elements share one namespace), each variation's values and anchor
        (a declared point or line, varied once), and the ``analysis`` settings. It
        does not check mobility, which needs the numerics: ``run`` does, and raises
        ``MobilityError`` when a degree of freedom is not driven.

        Returns
        -------
        list of Problem
            Each with ``where`` (``"[[element]] #3 'A' (revolute)"``) and ``message``.

        Examples
        --------
        >>> m = Model("demo", gravity=-9.81)
        >>> m.add_solid("crank", mass=-1.0).name
        'crank'
        >>> for problem in m.problems():
        ...     print(problem)
        [model]: gravity is the magnitude along −y, a number ≥ 0; got -9.81
        [[solid]] #1 'crank': mass is negative (-1.0): it must be ≥ 0
        """
        out: list[Problem] = []
        if not _number(self.gravity) or self.gravity < 0:
            out.append(Problem("[model]", f"gravity is the magnitude along −y, a number ≥ 0; "
                                          f"got {echo(self.gravity)}"))
        elif self.gravity > limits.VALUE:
            out.append(Problem("[model]", f"gravity = {self.gravity:g} m/s² is out of range "
                                          f"(at most {limits.VALUE:g})"))
        if angles_problem(self.angles):
            out.append(Problem("[model]", angles_problem(self.angles)))
        if not isinstance(self.name, str):
            out.append(Problem("[model]", f"name must be a string, got {echo(self.name)}"))
        elif len(self.name) > limits.MODEL_NAME:
            out.append(Problem("[model]", f"name is {len(self.name)} characters long: at most "
                                          f"{limits.MODEL_NAME} are allowed"))
        seen: dict[str, str] = {}
        for solid in self.solids:
            out += [Problem(solid.where, m)
                    for m in solid_problems(solid, degrees=self.angles == "deg")]
            _unique(solid.name, solid.where, seen, out)
        scope = Scope(self.solids)
        scope.elements = self.elements
        for el in self.elements:
            _unique(el.name, el.where, seen, out)
            out += [Problem(el.where, m) for m in el.problems(scope)]
        out += [Problem(*p) for p in variation_problems(self.variations, scope,
                                                         self.elements)[0]]
        out += [Problem("[analysis]", m) for m in self.analysis.problems()]
        if not self.solids:
            out.append(Problem("model", "there are no solids: add at least one [[solid]]"))
        return out

    def validate(self) -> None:
        """Raise ModelError listing every problem, if there is any; else issue ``warnings()``.

        Raises
        ------
        ModelError
            ``problems()`` is not empty; the error's ``problems`` lists them all.

        Warns
        -----
        VariationWarning
            A varied point or line that no constraint uses (once per model and text).
        """
        problems = self.problems()
        if problems:
            raise ModelError(problems, self.source)
        self.issue_warnings()

    def warnings(self) -> list[Problem]:
        """What is suspect but allowed: each varied point or line that no constraint uses.

        Returns
        -------
        list of Problem
            Each with ``where`` (``"[[variation]] #1 (anchor 'ground.O2')"``) and
            ``message``; ``validate`` issues them as ``VariationWarning``.
        """
        scope = Scope(self.solids)
        return [Problem(*p) for p in variation_problems(self.variations, scope,
                                                         self.elements)[1]]

    def issue_warnings(self) -> None:
        """Issue each of ``warnings()`` not issued yet for this model (VariationWarning)."""
        for problem in self.warnings():
            if str(problem) not in self._warned:
                self._warned.add(str(problem))
                warn_outside(f"{self.source}: {problem}" if self.source else str(problem),
                             VariationWarning)

    def mechanism(self) -> "Mechanism":
        """The validated, resolved model (raises ModelError).

        Returns
        -------
        Mechanism
            A snapshot: the solids, and copies of the elements with their anchors resolved.

        Raises
        ------
        ModelError
            The model has problems (see ``problems``).
        """
        self.validate()
        return Mechanism(self)


def _unique(name, where, seen, out):
    problem = limits.name_problem(name)
    if problem:
        out.append(Problem(where, problem))
        if not isinstance(name, str) or len(name) > limits.NAME:
            return
    if name in seen:
        out.append(Problem(where, f"name '{name}' is already used by {seen[name]}: "
                                  "solids and elements share one namespace, rename one of them"))
    else:
        seen[name] = where
