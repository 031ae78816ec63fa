"""The backend interface (``pam2exu.backend.base.Backend``): what a backend declares it can
do, and what the analyses do with each declaration, without probing the object (that
importing the natural backend loads no Exudyn: tests/test_architecture.py).

References: the contract in ``Backend``'s docstring; the subclasses below each break or
change one declaration; the registry's two backends.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pam2exu
from pam2exu import registry
from pam2exu.backend import Backend, Integrator
from pam2exu.backend.natural import Natural
from pam2exu.results.info import RunInfo
from references.pendulum import pendulum_toml

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "examples" / "four_bar.toml"


def test_the_registered_backends_declare_their_capabilities():
    declared = {name: b.create() for name, b in registry.BACKENDS.items()}
    assert all(isinstance(b, Backend) for b in declared.values())
    assert {n: (declared[n].gives_rates, declared[n].moves_free_solids, declared[n].integrator,
                declared[n].gives_reactions) for n in ("exudyn", "natural")} \
        == {"exudyn": (False, True, Integrator.FIXED_STEP, False),
            "natural": (True, True, Integrator.ADAPTIVE, True)}
    assert declared["exudyn"].integrator_name == "Exudyn's generalized-α"


def _identity(name):
    return {"name": name, "label": f"the {name} backend", "solver_name": f"{name}'s solver",
            "Settings": Natural.Settings}


@pytest.mark.parametrize("declaration, missing", [
    ({"moves_free_solids": True}, "static_equilibrium"),
    ({"integrator": Integrator.ADAPTIVE}, "motion"),
    ({"integrator": Integrator.FIXED_STEP, "integrator_name": "its rule"}, "integrate"),
    ({"integrator": Integrator.FIXED_STEP, "integrate": lambda *a, **k: None}, "integrator_name"),
    ({"gives_reactions": True}, "reactions"),
])
def test_a_capability_declared_without_its_method_is_refused(declaration, missing):
    body = {**_identity("half"), "solve_positions": Natural.solve_positions, **declaration}
    with pytest.raises(TypeError, match=missing):
        type("Half", (Backend,), body)


def test_a_backend_without_its_identity_is_refused():
    body = {k: v for k, v in _identity("anonymous").items() if k != "label"}
    with pytest.raises(TypeError, match="does not set label"):
        type("Anonymous", (Backend,), {**body, "solve_positions": Natural.solve_positions})
    # with everything declared, only solve_positions is needed: the defaults declare nothing
    plain = type("Plain", (Backend,), {**_identity("plain"),
                                       "solve_positions": Natural.solve_positions})()
    assert (plain.gives_rates, plain.moves_free_solids, plain.integrator,
            plain.gives_reactions) == (False, False, Integrator.NONE, False)
    with pytest.raises(NotImplementedError, match="plain backend has no adaptive"):
        plain.motion(None, np.zeros(2), None, None, 1e-6)


class _Reached(Exception):
    """Raised by a dummy backend's integrator: the analysis called it."""


class StillNatural(Natural):
    """The natural backend declaring no integrator."""
    name = "still"
    integrator = Integrator.NONE


class FixedStepNatural(Natural):
    """The natural backend declaring a fixed-step integrator (it still has ``motion``)."""
    name = "fixed"
    integrator = Integrator.FIXED_STEP
    integrator_name = "a test rule"

    def integrate(self, mech, times, q0, qd0, substeps, verbose=0):
        raise _Reached(substeps)


def _register(monkeypatch, cls):
    monkeypatch.setitem(registry.BACKENDS, cls.name,
                        registry.BackendType(cls.name, "a test backend", cls))


def test_the_dynamic_analysis_follows_the_declared_integrator(monkeypatch):
    """No integrator: refused, naming the backends that integrate; a fixed-step one: its
    ``integrate`` is called (the ``motion`` it inherits is not looked for)."""
    for cls in (StillNatural, FixedStepNatural):
        _register(monkeypatch, cls)
    model = pam2exu.loads(pendulum_toml(-1.0))
    able = " or ".join(n for n in registry.BACKENDS if n != "still")    # exudyn or natural …
    with pytest.raises(pam2exu.ModelError, match=r"still backend cannot integrate the motion "
                       rf"of free solids \('lever'\): run the dynamic analysis on the {able} "
                       r"backend"):
        pam2exu.run(model, "dynamic", steps=4, backend="still")
    with pytest.raises(pam2exu.SolverError, match=r"_Reached: 16\)") as caught:
        pam2exu.run(model, "dynamic", steps=4, backend="fixed")
    assert isinstance(caught.value.__cause__, _Reached)       # 64 steps / 4 intervals


class RatelessNatural(Natural):
    """The natural backend declaring that it gives no rates (it records what it is asked)."""
    name = "rateless"
    gives_rates = False
    asked: list = []

    def solve_positions(self, *args, rates=False, **kwargs):
        self.asked.append(rates)
        return super().solve_positions(*args, rates=rates, **kwargs)


def test_rates_are_asked_only_of_a_backend_that_gives_them(monkeypatch):
    """A backend that declares ``gives_rates = False`` is never asked for them: the native
    pass computes the velocities, equal to the natural backend's own within 1e-9 (relative
    to the largest rate); its positions are the natural backend's bit for bit."""
    _register(monkeypatch, RatelessNatural)
    RatelessNatural.asked.clear()
    mine = pam2exu.run(FOUR_BAR, "kinematic", steps=8, backend="rateless")
    theirs = pam2exu.run(FOUR_BAR, "kinematic", steps=8, backend="natural")
    assert RatelessNatural.asked and not any(RatelessNatural.asked)
    assert np.array_equal(mine["rocker.fi"], theirs["rocker.fi"])
    for name in ("rocker.Dfi", "coupler.Dx", "rocker.DDfi"):
        scale = np.max(np.abs(theirs[name]))
        assert np.max(np.abs(mine[name] - theirs[name])) <= 1e-9 * scale, name


@pytest.fixture(scope="module")
def quasi_static():
    """The four-bar's quasi-static run on each backend (4 steps)."""
    return {b: pam2exu.run(FOUR_BAR, "quasi_static", steps=4, backend=b)
            for b in registry.BACKENDS}


def test_the_checks_name_the_backend_that_ran(quasi_static):
    for name, res in quasi_static.items():
        label = registry.BACKENDS[name].create().label
        assert res.backend == label == res.select(["crank.*"]).backend
        assert res.checks()[1] == (f"{label}'s multipliers vs native equilibrium "
                                   f"{res.info['equilibrium_error']:.1e} (relative)")
    assert quasi_static["natural"].checks()[1].startswith("the natural-coordinate backend's")
    assert "Exudyn" not in quasi_static["natural"].summary()


def test_backend_seconds_is_read_by_its_old_name_too(quasi_static):
    res = quasi_static["natural"]
    assert res.info["backend_seconds"] > 0 and "exudyn_seconds" not in dict(res.info)
    with pytest.warns(DeprecationWarning, match="'exudyn_seconds' is now 'backend_seconds'"):
        assert res.info["exudyn_seconds"] == res.info["backend_seconds"]
    info = RunInfo()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        info["exudyn_seconds"] = 1.5
        assert "exudyn_seconds" in info
    assert dict(info) == {"backend_seconds": 1.5}
