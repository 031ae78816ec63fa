"""What is wrong with a model, collected before any numerics: every problem at once, each
with its place (``Model.problems``), and what is suspect but allowed (``Model.warnings``)."""
from __future__ import annotations

from .. import limits
from ..errors import Problem, echo
from ..limits import is_number as _number
from .angles import angles_problem
from .solid import Scope, solid_problems
from .variation import variation_problems


def model_problems(model) -> list[Problem]:
    """Every problem of ``model`` in file order: the [model] values, each solid, each
    element (keys, anchors), names unique across solids and elements, the variations, the
    [analysis] settings, and at least one solid (``Model.problems`` says more)."""
    out: list[Problem] = []
    if not _number(model.gravity) or model.gravity < 0:
        out.append(Problem("[model]", f"gravity is the magnitude along −y, a number ≥ 0; "
                                      f"got {echo(model.gravity)}"))
    elif model.gravity > limits.VALUE:
        out.append(Problem("[model]", f"gravity = {model.gravity:g} m/s² is out of range "
                                      f"(at most {limits.VALUE:g})"))
    if angles_problem(model.angles):
        out.append(Problem("[model]", angles_problem(model.angles)))
    if not isinstance(model.name, str):
        out.append(Problem("[model]", f"name must be a string, got {echo(model.name)}"))
    elif len(model.name) > limits.MODEL_NAME:
        out.append(Problem("[model]", f"name is {len(model.name)} characters long: at most "
                                      f"{limits.MODEL_NAME} are allowed"))
    seen: dict = {}
    for solid in model.solids:
        out += [Problem(solid.where, m)
                for m in solid_problems(solid, degrees=model.angles == "deg")]
        _unique(solid, seen, out)
    scope = Scope(model.solids)
    scope.elements = model.elements
    for el in model.elements:
        _unique(el, seen, out)
        out += [Problem(el.where, m) for m in el.problems(scope)]
    out += [Problem(*p) for p in variation_problems(model.variations, scope,
                                                     model.elements)[0]]
    out += [Problem("[analysis]", m) for m in model.analysis.problems()]
    if not model.solids:
        out.append(Problem("model", "there are no solids: add at least one [[solid]]"))
    return out


def model_warnings(model) -> list[Problem]:
    """What is suspect but allowed in ``model``: each varied point or line that no
    constraint uses (``Model.warnings``)."""
    scope = Scope(model.solids)
    return [Problem(*p) for p in variation_problems(model.variations, scope,
                                                     model.elements)[1]]


def _unique(item, seen, out):
    """A problem when the name of ``item`` (a solid or an element) is no valid name or is
    ``seen`` already (solids and elements share one namespace); else ``seen[name] = item``
    (its ``where`` made only for a message)."""
    name = item.name
    problem = limits.name_problem(name)
    if problem:
        out.append(Problem(item.where, problem))
        if not isinstance(name, str) or len(name) > limits.NAME:
            return
    if name in seen:
        out.append(Problem(item.where, f"name '{name}' is already used by {seen[name].where}: "
                                       "solids and elements share one namespace, rename one "
                                       "of them"))
    else:
        seen[name] = item
