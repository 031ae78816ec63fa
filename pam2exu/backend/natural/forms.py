"""Expressions in the natural coordinates z: linear forms, their products, and the one
trigonometric term of mixed coordinates, with the 2-vectors built from them.

Every constraint of the natural formulation is a sum of terms

    c · z_a · z_b               a product (z_ONE = 1 makes linear terms and constants)
    c · z_a · sin(z_b + α)      an angle coordinate z_b aligned with a unit vector

so that one table of terms per kind describes all of them (``Terms``), and their values,
Jacobians and quadratic velocity terms are evaluated for every time step at once.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

#: the index standing for the constant 1 in a term (z_ONE = 1)
ONE = -1


def _key(a: int, b: int) -> tuple[int, int]:
    """A product's two indices in one order (ONE last)."""
    return (a, b) if (b == ONE or (a != ONE and a <= b)) else (b, a)


@dataclass
class Expr:
    """A scalar function of z: Σ c z_a z_b + Σ c z_a sin(z_b + α) (``ONE`` for 1)."""

    products: dict = field(default_factory=dict)      # (a, b) -> c
    sines: dict = field(default_factory=dict)         # (a, b, α) -> c

    @staticmethod
    def constant(value: float) -> "Expr":
        """e = value."""
        return Expr({(ONE, ONE): float(value)} if value else {})

    @staticmethod
    def coordinate(index: int) -> "Expr":
        """e = z_index."""
        return Expr({(index, ONE): 1.0})

    @property
    def is_constant(self) -> bool:
        """No coordinate in it."""
        return not self.sines and all(k == (ONE, ONE) for k in self.products)

    @property
    def is_linear(self) -> bool:
        return not self.sines and all(ONE in k for k in self.products)

    def linear(self) -> dict:
        """{index (ONE for the constant): coefficient} of a linear form."""
        if self.sines:
            raise ValueError("not a linear form")
        out = {}
        for (a, b), c in self.products.items():
            if b == ONE:
                out[a] = c
            elif a == ONE:
                out[b] = c
            else:
                raise ValueError("not a linear form")
        return out

    def __add__(self, other: "Expr | float") -> "Expr":
        """e = a + b."""
        if not isinstance(other, Expr):
            other = Expr.constant(other)
        products = dict(self.products)
        get = products.get
        for k, c in other.products.items():
            products[k] = get(k, 0.0) + c
        if 0.0 in products.values():                 # (a sum that is 0 leaves the dict)
            products = {k: c for k, c in products.items() if c}
        if not (self.sines or other.sines):
            return Expr(products, {})
        sines = dict(self.sines)
        for k, c in other.sines.items():
            sines[k] = sines.get(k, 0.0) + c
        return Expr(products, {k: c for k, c in sines.items() if c})

    __radd__ = __add__

    def __neg__(self) -> "Expr":
        return self * -1.0

    def __sub__(self, other: "Expr | float") -> "Expr":
        """e = a − b: a + (−1 · b) term after term, in one pass (the same sums, the same
        order of terms)."""
        if not isinstance(other, Expr):
            return self + (-other)
        products = dict(self.products)
        get = products.get
        for k, c in other.products.items():
            if c:                                    # (−b leaves out b's zero terms)
                products[k] = get(k, 0.0) + c * -1.0
        if 0.0 in products.values():
            products = {k: c for k, c in products.items() if c}
        if not (self.sines or other.sines):
            return Expr(products, {})
        return Expr(products, self.sines) + Expr({}, (-other).sines)

    def __rsub__(self, other: float) -> "Expr":
        return -self + other

    def __mul__(self, other: "Expr | float") -> "Expr":
        """e = k a for a number k, or a·b for two linear forms (a quadratic form)."""
        if not isinstance(other, Expr):
            k = float(other)
            return Expr({key: v for key, c in self.products.items() if (v := c * k)},
                        {key: v for key, c in self.sines.items() if (v := c * k)}
                        if self.sines else {})
        products: dict = {}
        left = self.linear()
        right = other.linear().items() if left else ()
        for a, ca in left.items():
            for b, cb in right:
                # out + Expr({key: ca cb}) term after term: a sum that is 0 leaves the dict
                # (and a later term enters at its end, as the sum's new dict would have it)
                key = _key(a, b)
                c = products.get(key, 0.0) + ca * cb
                if c:
                    products[key] = c
                else:
                    products.pop(key, None)
        return Expr(products)

    __rmul__ = __mul__

    def sine(self, angle: int, alpha: float) -> "Expr":
        """e = a · sin(z_angle + α) for a linear form a."""
        return Expr({}, {(i, angle, float(alpha)): c for i, c in self.linear().items()})


@dataclass
class Vec:
    """A 2-vector of expressions (linear forms, in practice)."""

    x: Expr
    y: Expr

    @staticmethod
    def constant(v) -> "Vec":
        return Vec(Expr.constant(v[0]), Expr.constant(v[1]))

    def __add__(self, o: "Vec") -> "Vec":
        return Vec(self.x + o.x, self.y + o.y)

    def __sub__(self, o: "Vec") -> "Vec":
        return Vec(self.x - o.x, self.y - o.y)

    def __mul__(self, k: float) -> "Vec":
        return Vec(self.x * k, self.y * k)

    __rmul__ = __mul__

    def perp(self) -> "Vec":
        """Ω v = (−v_y, v_x): v turned 90° counter-clockwise."""
        return Vec(-self.y, self.x)

    def dot(self, o: "Vec") -> Expr:
        """a · b."""
        return self.x * o.x + self.y * o.y

    def aligned(self, angle: int, alpha: float) -> Expr:
        """v × e(z_angle + α) = v_x sin(z_angle + α) − v_y cos(z_angle + α): zero when the
        angle coordinate plus α is the direction of v (or its opposite, π away)."""
        return self.x.sine(angle, alpha) - self.y.sine(angle, alpha + 0.5 * math.pi)
