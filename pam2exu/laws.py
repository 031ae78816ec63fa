"""Time laws of the actuators (PAM's "lleis temporals").

Every law is a pure function of time giving f, f' and f'' at once, vectorised
over NumPy arrays. Laws with breakpoints C1 < C2 take the right-hand limit at a
breakpoint, so the value there describes the motion that follows.

Each law is written against a small array namespace ``xp`` (``where``, ``cos``,
``sin``) so the same expression serves NumPy and any other backend.

Each law is declared once, in ``LAWS`` (a ``LawForm``): its function, whether it is a
transition, the units of its constants, its Catalan alias and the formulas an exported
script writes (``law_code`` makes the script's functions from them).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from .complex_step import scalar

__all__ = ["Law", "LawForm", "LAWS", "LAW_ALIASES", "F_ORDERS", "VALUES_OF_F", "law_names"]


def polynomial(t, C, xp=np):
    """f = C1 + C2 t + C3 t² + C4 t³."""
    c1, c2, c3, c4 = C
    f = c1 + t * (c2 + t * (c3 + t * c4))
    df = c2 + t * (2.0 * c3 + 3.0 * c4 * t)
    ddf = 2.0 * c3 + 6.0 * c4 * t
    return f, df, ddf


def harmonic(t, C, xp=np):
    """f = C1 + C2 cos(C3 t + C4)."""
    c1, c2, c3, c4 = C
    phase = c3 * t + c4
    cos, sin = xp.cos(phase), xp.sin(phase)
    return c1 + c2 * cos, -c2 * c3 * sin, -c2 * c3 * c3 * cos


def _ramp_shape(u):
    """s(u) = u."""
    return u, 1.0 + 0.0 * u, 0.0 * u


def _bezier_c1_shape(u):
    """s(u) = 3u² − 2u³."""
    return u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u), 6.0 - 12.0 * u


def _bezier_c2_shape(u):
    """s(u) = 6u⁵ − 15u⁴ + 10u³."""
    u2 = u * u
    return (u2 * u * (10.0 + u * (-15.0 + 6.0 * u)),
            30.0 * u2 * (1.0 - u) ** 2,
            60.0 * u * (1.0 - u) * (1.0 - 2.0 * u))


def _transition(shape: Callable) -> Callable:
    """f = C3 + (C4 − C3) s(u), u = (t − C1)/(C2 − C1) on C1 ≤ t < C2; C3 before, C4 from C2 on."""

    def law(t, C, xp=np):
        c1, c2, c3, c4 = C
        span = c2 - c1
        u = (t - c1) / span
        s, ds, dds = shape(u)
        rise = c4 - c3
        before, inside = t < c1, t < c2
        f = xp.where(before, c3, xp.where(inside, c3 + rise * s, c4))
        df = xp.where(before, 0.0, xp.where(inside, rise * ds / span, 0.0))
        ddf = xp.where(before, 0.0, xp.where(inside, rise * dds / (span * span), 0.0))
        return f, df, ddf

    s = _formula(shape)                                           # "3u² − 2u³"
    law.__doc__ = _transition.__doc__.replace(" s(u)", " " + s if s == "u" else f"({s})")
    return law


def _formula(function: Callable) -> str:
    """The right-hand side of a law's or a shape's one-line docstring: "f = X." -> "X"."""
    return function.__doc__.split("=", 1)[1].strip().rstrip(".")


class LawForm(NamedTuple):
    """A time law, declared once: what computes it, what it needs, how a script writes it.

    function:   (t, C, xp) -> (f, f', f''), its docstring "f = …" the formula in words
    interval:   a transition from C3 to C4 between the times C1 < C2 (checked by the
                model's validation; C1 and C2 are its breakpoints)
    orders:     per constant, the unit it carries as a power of seconds under f's unit: 0
                for f itself [u], 1 for [u/s], 2 for [u/s²], 3 for [u/s³]; None for a
                constant in its own unit (the times C1, C2 of a transition [s]; a
                harmonic's ω [rad/s] and phase [rad])
    code:       f as an exported script computes it, Python in t and C1 … C4 (``np.cos``),
                the same operations as ``function`` (the same values, bit for bit); a
                transition's s(u), in u
    rate_code:  f'(t) likewise, to round-off (a transition's s'(u); None: s' = 1, a ramp)
    rate_words: ``rate_code`` in words, for the script's docstring
    alias:      PAM's Catalan name, if it has one
    shape:      a transition's s(u) (``_ramp_shape`` …), its docstring "s(u) = …"
    """

    function: Callable
    interval: bool
    orders: tuple[int | None, int | None, int | None, int | None]
    code: str
    rate_code: str | None
    rate_words: str | None
    alias: str | None = None
    shape: Callable | None = None

    @property
    def words(self) -> str:
        """The formula in words: f's ("C1 + C2 t + …"), a transition's s(u) ("3u² − 2u³")."""
        return _formula(self.shape or self.function)


def _transition_form(shape: Callable, code: str, rate_code: str | None,
                     rate_words: str | None, alias: str | None = None) -> LawForm:
    """A transition law from its shape s(u): f = C3 + (C4 − C3) s(u)."""
    return LawForm(_transition(shape), True, (None, None, 0, 0), code, rate_code, rate_words,
                   alias, shape)


#: law name -> its declaration, in the order of the contract's table
LAWS: dict[str, LawForm] = {
    "polynomial": LawForm(polynomial, False, (0, 1, 2, 3),
                          "C1 + t * (C2 + t * (C3 + t * C4))",
                          "C2 + t * (2.0 * C3 + 3.0 * C4 * t)", "C2 + 2 C3 t + 3 C4 t^2",
                          "polinomica"),
    "harmonic": LawForm(harmonic, False, (0, 0, None, None), "C1 + C2 * np.cos(C3 * t + C4)",
                        "-C2 * C3 * np.sin(C3 * t + C4)", "-C2 C3 sin(C3 t + C4)",
                        "harmonica"),
    "ramp": _transition_form(_ramp_shape, "u", None, None, "rampa"),
    "bezier_c1": _transition_form(_bezier_c1_shape, "u * u * (3.0 - 2.0 * u)",
                                  "6.0 * u * (1.0 - u)", "6u - 6u^2"),
    "bezier_c2": _transition_form(_bezier_c2_shape,
                                  "u * u * u * (10.0 + u * (-15.0 + 6.0 * u))",
                                  "30.0 * u * u * (1.0 - u) ** 2", "30u^2 (1 - u)^2"),
}
ramp, bezier_c1, bezier_c2 = (LAWS[name].function for name in ("ramp", "bezier_c1",
                                                                  "bezier_c2"))

#: law name -> per constant, the unit it carries as a power of seconds under f's unit
#: (``LawForm.orders``)
F_ORDERS: dict[str, tuple[int | None, int | None, int | None, int | None]] = {
    name: form.orders for name, form in LAWS.items()}

#: law name -> which constants are in the unit of f (per s, s², s³): C1…C4 of a polynomial,
#: C1 and C2 of a harmonic (C3 and C4 are the cosine's ω [rad/s] and phase [rad]), C3 and C4
#: of a transition (C1 and C2 are times). In a model with angles = "deg" these constants of an
#: angular actuator are degrees (deg/s, …); the others keep their units.
VALUES_OF_F: dict[str, tuple[bool, bool, bool, bool]] = {
    name: tuple(order is not None for order in orders) for name, orders in F_ORDERS.items()}

#: Catalan PAM names (``LawForm.alias``)
LAW_ALIASES = {form.alias: name for name, form in LAWS.items() if form.alias}


def law_names() -> list[str]:
    """All accepted law names, canonical first.

    Returns
    -------
    list of str
        The names of ``LAWS``, then the Catalan aliases of ``LAW_ALIASES``.

    Examples
    --------
    >>> law_names()[:5]
    ['polynomial', 'harmonic', 'ramp', 'bezier_c1', 'bezier_c2']
    >>> law_names()[5:]
    ['polinomica', 'harmonica', 'rampa']
    """
    return [*LAWS, *LAW_ALIASES]


_FLOAT = np.dtype(float)


def _own(value, shape: tuple) -> np.ndarray:
    """A law's f, f' or f'' as an array of its own of the times' shape: a fresh float array
    of that shape as it is (``* 1.0`` would copy it bit for bit), anything else broadcast
    and copied: a complex one (``* 1.0`` turns its NaN and signed zeros as before), one
    time (a NumPy scalar, as before)."""
    if shape and type(value) is np.ndarray and value.shape == shape and value.dtype == _FLOAT:
        return value
    return np.broadcast_to(value, shape) * 1.0


def _plain(C) -> bool:
    """C is already what ``Law`` keeps: a tuple of four Python floats or complex numbers."""
    return type(C) is tuple and len(C) == 4 and all(type(c) in (float, complex) for c in C)


@dataclass(frozen=True)
class Law:
    """A time law ``name`` with constants ``C = (C1, C2, C3, C4)``.

    The law of an actuator: f(t) is the relative angle fi2 − fi1 [rad] of an
    angular_actuator, or the distance PQ [m] of a linear_actuator. Below, [u] is that unit.

    - ``polynomial``: f = C1 + C2 t + C3 t² + C4 t³; C1 [u], C2 [u/s], C3 [u/s²], C4 [u/s³].
    - ``harmonic``: f = C1 + C2 cos(C3 t + C4); C1 [u], C2 [u], C3 [rad/s], C4 [rad].
    - ``ramp``: f = C3 + (C4 − C3) u with u = (t − C1)/(C2 − C1) on C1 ≤ t < C2, C3 before
      C1 and C4 from C2 on; C1 [s], C2 [s], C3 [u], C4 [u]. f' jumps at C1 and C2.
    - ``bezier_c1``: as ramp, with s(u) = 3u² − 2u³ instead of u: f' is continuous.
    - ``bezier_c2``: as ramp, with s(u) = 6u⁵ − 15u⁴ + 10u³: f' and f'' are continuous.

    The transition laws (ramp, bezier_c1, bezier_c2) need C1 < C2 (checked by the model's
    validation) and take the right-hand limit at C1 and C2.

    Parameters
    ----------
    name : str
        One of ``law_names()``; a Catalan alias (``polinomica``, ``harmonica``, ``rampa``)
        is replaced by its canonical name.
    C : sequence of float
        Up to four constants C1 … C4, in the units of the list above ([s], [u], [u/s],
        …); missing ones are 0.

    Raises
    ------
    ValueError
        An unknown law name (the message lists the known ones), or more than four
        constants.

    Examples
    --------
    >>> law = Law("harmonic", [0.0, 0.5, 6.0])
    >>> law.C
    (0.0, 0.5, 6.0, 0.0)
    >>> law.value(0.0)
    0.5
    >>> Law("rampa", [1.0, 2.0, 0.0, 0.3]).name
    'ramp'
    """

    name: str = "polynomial"
    C: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)

    def __post_init__(self):
        if self.name not in LAWS:
            object.__setattr__(self, "name", LAW_ALIASES.get(self.name, self.name))
        if self.name not in LAWS:
            raise ValueError(f"unknown law '{self.name}'; known laws: {', '.join(law_names())}")
        if _plain(self.C):
            return                                      # four floats (or complex) already
        C = tuple(scalar(c) for c in (self.C if np.ndim(self.C) else [self.C]))
        if len(C) > 4:
            raise ValueError(f"a law has at most four constants C1 … C4, got {len(C)}")
        object.__setattr__(self, "C", C + (0.0,) * (4 - len(C)))

    def __call__(self, t, xp=np):
        """(f, f', f'') at time(s) t [s].

        Parameters
        ----------
        t : float or array_like
            Time or times [s].
        xp : module
            Array namespace with ``where``, ``cos`` and ``sin`` (default NumPy). With NumPy
            the three arrays have the shape of ``t``; with another namespace they are
            whatever its operations return.

        Returns
        -------
        f, df, ddf : numpy.ndarray
            The law [u], its first [u/s] and second [u/s²] time derivatives, where [u] is
            rad (angular actuator) or m (linear actuator).

        Examples
        --------
        >>> f, df, ddf = Law("polynomial", [0.0, 2.0, 0.0, 1.0])([0.0, 1.0])
        >>> f.tolist(), df.tolist(), ddf.tolist()
        ([0.0, 3.0], [2.0, 5.0], [0.0, 6.0])
        """
        if xp is np:
            t = np.asarray(t, dtype=float)
            shape = t.shape
            return tuple(_own(v, shape) for v in LAWS[self.name].function(t, self.C, xp))
        return LAWS[self.name].function(t, self.C, xp)

    def value(self, t: float) -> float:
        """f(t) for a scalar t, as a Python float (used in solver callbacks).

        Parameters
        ----------
        t : float
            Time [s].

        Returns
        -------
        float
            f(t) [rad or m, as the actuator].
        """
        return float(self(t)[0])

    def breakpoints(self) -> tuple[float, ...]:
        """Times where f' or f'' may jump: C1 and C2 of the transition laws, none otherwise.

        Returns
        -------
        tuple of float
            ``(C1, C2)`` [s] for ramp, bezier_c1 and bezier_c2; ``()`` for polynomial and
            harmonic.

        Examples
        --------
        >>> Law("ramp", [0.5, 1.0, 0.0, 1.0]).breakpoints()
        (0.5, 1.0)
        """
        return self.C[:2] if LAWS[self.name].interval else ()
