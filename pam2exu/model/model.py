"""The model: the container of solids, elements, variations and analysis settings, built in
Python or loaded from TOML.

``Model.problems()`` collects every problem before any numerics (``problems.py``);
``Model.mechanism()`` returns the validated, resolved form the translation and the analyses
work on (``mechanism.py``); the settings are ``analysis.py``'s ``Analysis``, and how a model
shows itself is ``describe.py``.
"""
from __future__ import annotations

from dataclasses import fields

from ..elements import ALIASES, ELEMENTS, Element, misplaced_clearance
from ..errors import ModelError, Problem, VariationWarning, closest, warn_outside
from . import describe
from .analysis import Analysis
from .mechanism import Mechanism
from .problems import model_problems, model_warnings
from .solid import Solid
from .variation import KEYS as VARIATION_KEYS
from .variation import Variation

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
            same = sum(1 for e in self.elements if type(e) is type(element))
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
            ``dangle`` [rad], ``w``, ``wx``, ``wy``, ``wangle`` [rad/s], ``tau`` [s],
            ``fixed_dx``, ``fixed_dy`` [m], ``fixed_dangle`` [rad].

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
        return describe.one_line(self)

    def _repr_html_(self) -> str:    # IPython's HTML form: solids, elements, drawing (describe.py)
        return describe.html(self)

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
        return model_problems(self)

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
        return model_warnings(self)

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

