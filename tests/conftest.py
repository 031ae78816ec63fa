"""Shared fixtures: paths of the shipped models, and a rigidly moved copy of a model."""
import io
from pathlib import Path

import numpy as np
import pytest

import pam2exu

ROOT = Path(__file__).resolve().parents[1]


class Terminal(io.StringIO):
    """A text stream that says it is a terminal: what ``progress.Progress`` draws on."""

    def isatty(self):
        return True


@pytest.fixture
def examples() -> Path:
    return ROOT / "examples"


@pytest.fixture
def data() -> Path:
    return ROOT / "tests" / "data"


def moved_model(path, x0=0.3, y0=-0.2, fi0=0.7):
    """The model with every solid's pose moved by the same rigid motion (x0, y0, fi0): the
    ground is then rotated and shifted (its ObjectGround has a rotation, the actuators on
    it an angle shift)."""
    model = pam2exu.load(path)
    c, s = np.cos(fi0), np.sin(fi0)
    for solid in model.solids:
        x, y = float(solid.x), float(solid.y)
        solid.x, solid.y = x0 + c * x - s * y, y0 + s * x + c * y
        solid.fi = float(solid.fi) + fi0
    return model


@pytest.fixture
def moved():
    """``moved_model``, for tests."""
    return moved_model


def guides_model(slot_clearance=True, guide_clearance=True):
    """A pin (crank.A) in a slot and a slider (slider.axis) in a prismatic guide, both on
    the ground's rail (point (0.1, −0.2), angle 0.3): the two line-based joints that take
    clearance (the clearance tests and drawings)."""
    m = pam2exu.Model("guides", gravity=0.0)
    m.add_solid("ground", lines={"rail": {"point": [0.1, -0.2], "angle": 0.3}})
    m.add_solid("crank", points={"A": [0.25, 0.05]})
    m.add_solid("slider", lines={"axis": {"point": [0.02, 0.03], "angle": 0.2}})
    m.add("fixed", anc1="ground")
    m.add("pin_slot", name="slot", anc1="ground.rail", anc2="crank.A",
          clearance=slot_clearance)
    m.add("prismatic", name="guide", anc1="ground.rail", anc2="slider.axis",
          clearance=guide_clearance)
    return m


@pytest.fixture
def guides():
    """``guides_model``, for tests."""
    return guides_model


def pytest_addoption(parser):
    parser.addoption("--fuzz-long", action="store_true", default=False,
                     help="tests/fuzz: run the long fuzz campaign (10,000 mutants) instead of "
                          "the CI one")
    parser.addoption("--long", action="store_true", default=False,
                     help="also run the long tests (marked 'long': long runs and sweeps, "
                          "minutes each on two cores), skipped by default")


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "long(backends=None): a long run or sweep, run only with --long; with "
                   "backends=(...), only its cases on those backends (every_backend) are long")


def pytest_collection_modifyitems(config, items):
    """Skip the tests marked ``long`` (or their cases on the backends the marker names)
    unless ``--long`` is given."""
    if config.getoption("--long"):
        return
    skip = pytest.mark.skip(reason="a long test: run with --long")
    for item in items:
        mark = item.get_closest_marker("long")
        if mark is None:
            continue
        backends = mark.kwargs.get("backends")
        params = getattr(getattr(item, "callspec", None), "params", {})
        if backends is None or params.get("every_backend") in backends:
            item.add_marker(skip)


@pytest.fixture(params=list(pam2exu.registry.BACKENDS))
def every_backend(request, monkeypatch):
    """Run the test once per backend: ``pam2exu.run`` uses it unless the call names one
    (a module opts in with ``pytestmark = pytest.mark.usefixtures("every_backend")``)."""
    run = pam2exu.run

    def run_on(*args, **settings):
        settings.setdefault("backend", request.param)
        return run(*args, **settings)

    monkeypatch.setattr(pam2exu, "run", run_on)
    return request.param


def varied_mechanisms(model, values: dict):
    """The mechanisms of ``model`` with each parameter's k-th value written in (the names
    of ``studies.parameters.targets``): a study's variants, made directly."""
    import copy
    from pam2exu.studies.parameters import targets, write
    found = targets(model)
    count = len(next(iter(values.values())))
    out = []
    for k in range(count):
        m = copy.deepcopy(model)
        for name, vals in values.items():
            write(m, found[name], vals[k])
        out.append(m.mechanism())
    return out
