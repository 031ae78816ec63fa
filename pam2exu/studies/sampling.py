"""The variants of a study: each parameter's distribution (``scipy.stats``) and the design
of the methods (``scipy.stats.qmc``), in rows that depend only on the seed, the method, the
number of samples, the parameter list and the row's index.

Every sampled method makes points u in the unit hypercube, one row per variant, and maps
each column through its parameter's inverse CDF (``ppf``): ``monte_carlo`` independent
uniform draws (PCG64 seeded by ``seed``, advanced to the chunk's first row),
``latin_hypercube`` one point per stratum per parameter, ``sobol`` scrambled Sobol' points
(fast-forwarded to the chunk's first row); ``grid`` the row-major product of the ``values``
lists; ``linear`` the nominal variant alone.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

#: the distributions a parameter may have
DISTRIBUTIONS = ("normal", "uniform", "triangular", "values")
#: the study methods
METHODS = ("monte_carlo", "latin_hypercube", "sobol", "grid", "linear")


def normal_std(tol: float) -> float:
    """σ = tol / 3 (3σ = tol)."""
    return tol / 3.0


@dataclass
class Parameter:
    """One ``[[parameter]]``: what varies and how (validated by the study's loader).

    Parameters
    ----------
    name : str
        What varies (``pam2exu.studies.parameters.targets``).
    distribution : str
        ``normal``, ``uniform``, ``triangular`` or ``values``.
    nominal : float
        The model's value, in its units.
    mean : float, optional
        Centre of a normal, mode of a triangular, centre of a ``tol`` interval; default
        the nominal value.
    tol : float, optional
        normal: 3σ = tol; uniform and triangular: mean ± tol.
    std : float, optional
        A normal's σ.
    low, high : float, optional
        A uniform's or triangular's bounds.
    values : list of float, optional
        The values of a ``values`` distribution (equally likely) or of a grid.
    unit : str
        Its unit, for tables and messages.
    """

    name: str
    distribution: str
    nominal: float
    mean: float | None = None
    tol: float | None = None
    std: float | None = None
    low: float | None = None
    high: float | None = None
    values: list[float] | None = None
    unit: str = ""
    _frozen: object = field(default=None, init=False, repr=False, compare=False)

    @property
    def centre(self) -> float:
        """The mean given, else the nominal value."""
        return self.nominal if self.mean is None else self.mean

    def bounds(self) -> tuple[float, float]:
        """(low, high) of a uniform or triangular: as given, else centre ∓ tol."""
        if self.low is not None:
            return self.low, self.high
        return self.centre - self.tol, self.centre + self.tol

    def distribution_object(self):
        """The frozen ``scipy.stats`` distribution (a ``values`` one: of the list's index)."""
        # imported here, not with the module: the worker processes that run the variants
        # import this module but never draw (scipy.stats costs about 1 s to import)
        from scipy import stats
        if self._frozen is None:
            if self.distribution == "normal":
                sigma = self.std if self.std is not None else normal_std(self.tol)
                self._frozen = stats.norm(loc=self.centre, scale=sigma)
            elif self.distribution == "values":
                self._frozen = stats.randint(0, len(self.values))
            else:
                low, high = self.bounds()
                if self.distribution == "uniform":
                    self._frozen = stats.uniform(loc=low, scale=high - low)
                else:
                    self._frozen = stats.triang((self.centre - low) / (high - low), loc=low,
                                                scale=high - low)
        return self._frozen

    @property
    def sigma(self) -> float:
        """σ_p, the parameter's standard deviation (a ``values`` one: of its values,
        equally likely)."""
        if self.distribution == "values":
            return float(np.std(np.asarray(self.values, dtype=float)))
        return float(self.distribution_object().std())

    def quantile(self, u: np.ndarray) -> np.ndarray:
        """The values at the probabilities u ∈ [0, 1) (the inverse CDF)."""
        if self.distribution == "values":
            index = self.distribution_object().ppf(u).astype(int)
            return np.asarray(self.values, dtype=float)[np.clip(index, 0, len(self.values) - 1)]
        return self.distribution_object().ppf(u)


def grid_size(parameters: list[Parameter]) -> int:
    """N = Π n_k, the number of combinations of the ``values`` lists."""
    return math.prod(len(p.values) for p in parameters)


def unit_design(method: str, dimensions: int, samples: int, seed: int, start: int,
                stop: int) -> np.ndarray:
    """Rows [start, stop) of the method's design in the unit hypercube, (stop − start, d).

    The rows are those of the whole design of ``samples`` rows, whatever the chunk: Monte
    Carlo advances PCG64 by ``start · d`` draws; Sobol' fast-forwards ``start`` points;
    the Latin hypercube is made whole (its strata span every row) and sliced.
    """
    from scipy.stats import qmc                  # with the draws only (distribution_object)
    n = stop - start
    if method == "monte_carlo":
        bits = np.random.PCG64(seed)
        bits.advance(start * dimensions)
        return np.random.Generator(bits).random((n, dimensions))
    if method == "latin_hypercube":
        return qmc.LatinHypercube(dimensions, rng=seed).random(samples)[start:stop]
    if method == "sobol":
        engine = qmc.Sobol(dimensions, scramble=True, rng=seed)
        if start:
            engine.fast_forward(start)
        with warnings.catch_warnings():      # the study's loader warns of it once
            warnings.filterwarnings("ignore", "The balance properties of Sobol",
                                    UserWarning)
            return engine.random(n)
    raise ValueError(f"method {method!r} has no unit design")


def design(method: str, parameters: list[Parameter], samples: int, seed: int, start: int,
           stop: int) -> np.ndarray:
    """Rows [start, stop) of the variants' values, (stop − start, number of parameters).

    Parameters
    ----------
    method : str
        One of ``METHODS``.
    parameters : list of Parameter
        The study's parameters, in its order (the columns).
    samples : int
        The number of variants of the whole study (``grid_size`` for a grid, 1 for linear).
    seed : int
        The seed of the sampled methods.
    start, stop : int
        The rows, 0 ≤ start ≤ stop ≤ samples.

    Returns
    -------
    ndarray
        Row i is variant start + i, each column in its parameter's model units.
    """
    if not 0 <= start <= stop <= samples:
        raise ValueError(f"rows [{start}, {stop}) are not within the {samples} variants")
    rows = np.arange(start, stop)
    if method == "linear":
        return np.tile([p.nominal for p in parameters], (len(rows), 1)).astype(float)
    if method == "grid":
        index = np.unravel_index(rows, [len(p.values) for p in parameters])
        return np.column_stack([np.asarray(p.values, dtype=float)[k]
                                for p, k in zip(parameters, index)]).reshape(len(rows), -1)
    u = unit_design(method, len(parameters), samples, seed, start, stop)
    return np.column_stack([p.quantile(u[:, k]) for k, p in enumerate(parameters)]) \
        .reshape(len(rows), -1)
