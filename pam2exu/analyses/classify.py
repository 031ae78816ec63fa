"""The atlas of a mechanism before its run (``pam2exu classify``): its mobility, its
independent loops with their kind, Grashof class and input range, the assembly modes at
t = 0, the dead and change points the driver meets, and each loop's transmission angle.

The loops are those of the joints (``Element.ties`` that do not drive; the actuators drive
the loops, they are not links of them), the frame (the solids held by fixed links) one node.
The mechanism is placed as its structure builds it (``placement``): the held solids, then
each solid the elements to the placed ones fix (a driven crank), then each loop's *dyad*,
the two solids that close it, joined by a pin: its *coupler*, pinned to a placed solid, and
its *output*, pinned (a rocker) or sliding (a slider) on another. The dyad's two assemblies
are the loop's assembly modes; the acute angle between the coupler and the output's path
at their pin is its transmission angle (``points.transmission_angle``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kinematics import State, rotate
from ..points import Coupler
from . import dead_points, grashof, loops, rank
from .job import prepare
from .native import equations
from .positions import GUESS_STIFFNESS, assemble, positions

#: a dyad's two assemblies coincide when its pin is this close (relative) to the line
#: of its reach (a dead point at t = 0)
TOGGLE = 1e-9


@dataclass(frozen=True)
class Dyad:
    """The two solids that close a loop: ``coupler`` pinned to a placed solid at its point
    ``a`` and to ``output`` at ``b``; the output pinned at ``pivot`` (a point of a placed
    solid) or sliding along ``guide`` (a placed solid's line)."""

    coupler: int
    output: int
    a: object
    b: object
    pivot: object = None
    guide: object = None

    @property
    def transmission(self) -> Coupler:
        """Its coupler, whose ``angle`` is the transmission angle."""
        return Coupler(self.coupler, self.a, self.b, self.pivot, self.guide)


@dataclass
class Loop:
    """One independent loop: its solids and joints in order around it, its kind, the solid
    it is measured from (``reference``: the frame, or the first placed), its Grashof class,
    its input and the input's range, its dyad, modes and transmission angle."""

    solids: list[str]
    joints: list[str]
    kind: str
    reference: str
    grashof: grashof.Grashof | None = None
    input: str | None = None
    input_range: list = field(default_factory=list)
    range_unit: str = "deg"
    dyad: Dyad | None = None
    modes: list[str] = field(default_factory=list)
    selected: str | None = None
    transmission: dict | None = None
    #: the solids' indices and the edges (``loops.Edge``) around it, as ``solids``, ``joints``
    ids: tuple = ()
    edges: tuple = ()


@dataclass
class Atlas:
    """What ``classify`` finds: the Grübler–Kutzbach count, the rank-based mobility, the
    degrees of freedom the actuators leave, the redundant equations' elements, the loops,
    the dead and change points (dicts with ``t``, ``kind``, ``loop``, ``joint``) and the
    interval followed."""

    model: str
    source: str
    gruebler: int
    mobility: int
    actuated: int
    free: int
    redundant: int
    redundant_elements: list[str]
    loops: list[Loop]
    dead_points: list[dict]
    times: tuple[float, float]
    #: the solids' names, by index
    names: list[str] = field(default_factory=list)
    note: str = ""

    @property
    def meaning(self) -> str:
        """What the difference between the two mobilities means, naming the elements."""
        if not self.redundant:
            return ("the Grübler–Kutzbach count and the rank agree: no constraint "
                    "equation repeats another")
        names = ", ".join(f"'{n}'" for n in self.redundant_elements)
        return (f"the rank finds {self.redundant} degree(s) of freedom more than the "
                f"Grübler–Kutzbach count: {self.redundant} equation(s) of {names} repeat "
                "the others (over-constraint, or a special geometry such as parallel "
                "links of equal length): the count assumes them independent")

    def as_dict(self) -> dict:
        """The atlas as one object (``pam2exu classify --json``): angles in degrees."""
        loops_out = []
        for lp in self.loops:
            dyad = lp.dyad
            loops_out.append({
                "solids": lp.solids, "joints": lp.joints, "kind": lp.kind,
                "reference": lp.reference,
                "grashof": None if lp.grashof is None else lp.grashof.as_dict(),
                "input": lp.input, "input_range": lp.input_range,
                "input_unit": lp.range_unit if lp.input else None,
                "coupler": None if dyad is None else self.names[dyad.coupler],
                "output": None if dyad is None else self.names[dyad.output],
                "transmission_angle": lp.transmission})
        return {
            "model": self.model, "file": self.source,
            "dof": self.mobility,
            "mobility": {"gruebler": self.gruebler, "rank": self.mobility,
                    "actuated": self.actuated, "free": self.free,
                    "redundant": self.redundant,
                    "redundant_elements": self.redundant_elements, "meaning": self.meaning},
            "loops": loops_out,
            "assembly_modes": {"count": self.assembly_modes, "loops": [
                {"loop": k + 1, "modes": lp.modes, "selected": lp.selected}
                for k, lp in enumerate(self.loops) if lp.modes]},
            "dead_points": self.dead_points,
            "interval": list(self.times), "note": self.note}

    @property
    def assembly_modes(self) -> int:
        """The assemblies at t = 0: the product of the loops' modes."""
        return int(np.prod([len(lp.modes) for lp in self.loops if lp.modes])) \
            if any(lp.modes for lp in self.loops) else 1


def joint_edges(mech) -> list[loops.Edge]:
    """The ties that are joints (``Element.ties``, not ``drives``): the loops' links."""
    return [e for e in loops.edges(mech) if not e.element.drives]


def independent_loops(mech) -> list[tuple]:
    """A basis of the loops: the shortest loop through each joint, shortest first, kept when
    its set of joints is independent (over GF(2)) of those kept; E − N + 1 per connected
    part of the graph."""
    graph = joint_edges(mech)
    index = {id(e.element): k for k, e in enumerate(graph)}
    candidates = []
    for e in graph:
        cycle = loops.cycle_through(mech, e.element, graph)
        if cycle is not None:
            candidates.append(cycle)
    candidates.sort(key=len)
    basis, rows = [], []                 # reduced rows: (pivot, bits)
    for cycle in candidates:
        bits = 0
        for e, _ in cycle:
            bits |= 1 << index[id(e.element)]
        for pivot, row in rows:
            if bits >> pivot & 1:
                bits ^= row
        if bits:
            rows.append((bits.bit_length() - 1, bits))
            basis.append(tuple(cycle))
    return basis


def _nodes(cycle) -> list[tuple[int, object, object]]:
    """(solid, point it is entered at, point it is left at) around a loop: the solid
    between edge k and edge k + 1."""
    ends = [((e.element.ref1, e.element.ref2) if forward else (e.element.ref2, e.element.ref1))
            for e, forward in cycle]
    return [(ends[k][1].solid, ends[k][1], ends[(k + 1) % len(ends)][0])
            for k in range(len(ends))]


def _at(q, ref) -> np.ndarray:
    """Where the point of ``ref`` (a point, or a line's defining point) is in q."""
    s = ref.solid
    return q[3 * s:3 * s + 2] + rotate(np.array([q[3 * s + 2]]),
                                       np.asarray(ref.anchor_point, dtype=float))[0]


def _direction(q, line) -> np.ndarray:
    """The global direction of a line of a solid in q."""
    return rotate(np.array([q[3 * line.solid + 2]]), np.asarray(line.direction))[0]


def placement(mech, q0: np.ndarray, basis) -> tuple[dict[int, int], dict[int, Dyad]]:
    """(the order each solid is placed in, the dyad that closes each loop of ``basis``):
    the held solids first (0), then one by one each solid that the elements to placed
    solids fix (``loops.rigid``) and each loop left with two solids to place, joined by a
    pin (its coupler, then its output)."""
    jac = equations(mech, State([0.0], q0[None])).jacobian[0]
    order = {s: 0 for s in mech.held}
    dyads: dict[int, Dyad] = {}
    while True:
        grown = False
        for s in range(len(mech.solids)):
            if s in order:
                continue
            near = [el for el in mech.constraints
                    if s in el.solids and set(el.solids) - {s} <= set(order)]
            if near and loops.rigid(mech, jac, near, {s}):
                order[s], grown = len(order), True
        for k, cycle in enumerate(basis):
            if k in dyads:
                continue
            dyad = _dyad(mech, cycle, order)
            if dyad is not None:
                dyads[k] = dyad
                order[dyad.coupler] = len(order)
                order[dyad.output] = len(order)
                grown = True
        if not grown and not _free_input(basis, dyads, order):
            return order, dyads


def _free_input(basis, dyads, order) -> bool:
    """Where no actuator places the next solid (a degree of freedom left free), take as
    the input of the first loop without a dyad its first solid not placed that is pinned
    to a placed one; False when there is none."""
    for k, cycle in enumerate(basis):
        if k in dyads:
            continue
        for e, _ in cycle:
            ends = (e.element.ref1.solid, e.element.ref2.solid)
            placed = [s in order for s in ends]
            if e.element.pins and sum(placed) == 1:
                order[ends[placed.index(False)]] = len(order)
                return True
    return False


def _dyad(mech, cycle, order) -> Dyad | None:
    """The dyad of a loop whose solids are all placed but two, adjacent and pinned, each
    tied to a placed solid (``placement``); None otherwise."""
    nodes = _nodes(cycle)
    free = [k for k, (s, _, _) in enumerate(nodes) if s not in order]
    if len(free) != 2:
        return None
    n = len(nodes)
    i, j = free if (free[0] + 1) % n == free[1] else free[::-1]
    if (i + 1) % n != j or not cycle[j][0].element.pins:
        return None
    # nodes[i] is entered by edge i, left by edge j (the middle pin); nodes[j] left by j + 1
    first, second = cycle[i][0], cycle[(j + 1) % n][0]
    outer_i = nodes[(i - 1) % n][0]
    outer_j = nodes[(j + 1) % n][0]
    # the output hangs on the solid placed first (the frame before a moving solid)
    if order[outer_i] < order[outer_j]:
        coupler, output, c_edge, o_edge = j, i, second, first
    else:
        coupler, output, c_edge, o_edge = i, j, first, second
    if not c_edge.element.pins:
        return None
    c_solid, o_solid = nodes[coupler][0], nodes[output][0]
    a = c_edge.element.ref1 if c_edge.element.ref1.solid == c_solid else c_edge.element.ref2
    middle = cycle[j][0].element
    b = middle.ref1 if middle.ref1.solid == c_solid else middle.ref2
    held_ref = (o_edge.element.ref1 if o_edge.element.ref1.solid != o_solid
                else o_edge.element.ref2)
    if o_edge.element.pins:
        return Dyad(c_solid, o_solid, a, b, pivot=held_ref)
    if o_edge.element.slides:
        return Dyad(c_solid, o_solid, a, b, guide=held_ref)
    return None


def _rotated(mech, cycle, order):
    """(solids, edges) around the loop from its reference (the solid placed first, the
    frame before the others): edges[k] joins solids[k] and solids[k + 1]."""
    nodes = _nodes(cycle)
    n = len(nodes)
    r = min(range(n), key=lambda k: (order.get(nodes[k][0], n + 1), k))
    solids = [nodes[(r + k) % n][0] for k in range(n)]
    edges = [cycle[(r + k + 1) % n][0] for k in range(n)]
    return solids, edges


def _end(element, solid: int):
    """The anchor of ``element`` on ``solid``."""
    return element.ref1 if element.ref1.solid == solid else element.ref2


def _length(q0, edges, solids, k: int) -> float:
    """The link of solid k of the loop: the distance between its two joints' points."""
    return float(np.linalg.norm(_at(q0, _end(edges[k].element, solids[k]))
                                - _at(q0, _end(edges[k - 1].element, solids[k]))))


def describe_loop(mech, cycle, q0, order, dyad: Dyad | None) -> Loop:
    """A loop's kind, Grashof class, input and its range, and its dyad's assembly modes at
    q0 (the assembled position at t = 0)."""
    solids, edges = _rotated(mech, cycle, order)
    names = [mech.solids[s].name for s in solids]
    loop = Loop(names, [e.element.name for e in edges], f"{len(edges)}-link loop",
                names[0], dyad=dyad, ids=tuple(solids), edges=tuple(edges))
    in_dyad = {dyad.coupler, dyad.output} if dyad is not None else set()
    slides = [k for k, e in enumerate(edges) if e.element.slides]
    if len(edges) == 4 and all(e.element.pins for e in edges):
        loop.kind = "four-bar"
        lengths = [_length(q0, edges, solids, k) for k in range(4)]
        first = 3 if solids[1] in in_dyad and solids[3] not in in_dyad else 1
        last = 4 - first
        loop.input = mech.solids[solids[first]].name
        roles = dict(zip(("frame", "input", "coupler", "output"),
                         (names[0], names[first], names[2], names[last])))
        loop.grashof = grashof.four_bar_class(lengths[0], lengths[first], lengths[2],
                                              lengths[last], roles)
        loop.input_range = grashof.degrees(grashof.four_bar_input_range(
            lengths[0], lengths[first], lengths[2], lengths[last]))
    elif (len(edges) == 4 and len(slides) == 1 and slides[0] in (0, 3)
          and sum(e.element.pins for e in edges) == 3):
        loop.kind = "slider-crank"
        crank, slider = (3, 1) if slides[0] == 0 else (1, 3)
        pivot = _at(q0, _end(edges[crank - 1 if crank == 1 else 3].element, solids[crank]))
        pin_a = _at(q0, _end(edges[1 if crank == 1 else 2].element, solids[crank]))
        pin_b = _at(q0, _end(edges[2 if crank == 1 else 1].element, solids[slider]))
        d = _direction(q0, _end(edges[slides[0]].element, solids[0]))
        r, rod = float(np.linalg.norm(pin_a - pivot)), float(np.linalg.norm(pin_b - pin_a))
        offset = float(d[0] * (pin_b - pivot)[1] - d[1] * (pin_b - pivot)[0])
        loop.grashof = grashof.slider_crank_class(r, rod, offset)
        if solids[slider] in in_dyad or not in_dyad:
            loop.input = mech.solids[solids[crank]].name
            loop.input_range = grashof.degrees(grashof.crank_range(r, rod, offset))
        else:
            loop.input, loop.range_unit = mech.solids[solids[slider]].name, "m"
            loop.input_range = [list(x) for x in grashof.slider_range(r, rod, offset)]
    elif len(edges) == 4 and len(slides) == 1:
        loop.kind = "inverted slider-crank"
    if dyad is not None:
        loop.modes, loop.selected = modes(q0, dyad)
    return loop


def modes(q0, dyad: Dyad) -> tuple[list[str], str]:
    """(the names of the dyad's assemblies at q0, the one q0 is in): two, mirror images
    across the line of its reach, or one at a toggle position."""
    a, b = _at(q0, dyad.a), _at(q0, dyad.b)
    coupler = float(np.linalg.norm(b - a))
    if dyad.pivot is not None:
        p = _at(q0, dyad.pivot)
        output, reach = float(np.linalg.norm(b - p)), float(np.linalg.norm(p - a))
        two = abs(coupler - output) * (1 + TOGGLE) < reach < (coupler + output) * (1 - TOGGLE)
        selected = grashof.four_bar_mode(a, b, p)
    else:
        d = _direction(q0, dyad.guide)
        height = abs(float(d[0] * (a - b)[1] - d[1] * (a - b)[0]))
        two = height < coupler * (1 - TOGGLE)
        selected = grashof.slider_mode(a, b, d)
    return (["open", "crossed"] if two else [selected]), selected


def _where(mech, found_loops: list[Loop], point) -> tuple[int | None, str | None]:
    """(the loop, the joint) of a singular position: the loop that holds most of the solids
    its null motion moves, and in it the pin whose two links are nearest in line."""
    v = np.abs(point.v.reshape(-1, 3)) * np.array([1.0, 1.0, mech.scale()])
    moved = {s for s, w in enumerate(v.max(axis=1)) if w > 1e-6 * v.max()}
    if not found_loops:
        return None, None
    k = max(range(len(found_loops)), key=lambda i: (len(set(found_loops[i].ids) & moved),
                                                   -len(found_loops[i].ids)))
    solids, edges = found_loops[k].ids, found_loops[k].edges
    best, joint = np.inf, None
    n = len(edges)
    for i, e in enumerate(edges):
        before, after = edges[i - 1], edges[(i + 1) % n]
        if not e.element.pins or before.element.slides or after.element.slides:
            continue
        here = _at(point.q, _end(e.element, solids[i]))
        u = here - _at(point.q, _end(before.element, solids[i]))
        w = _at(point.q, _end(after.element, solids[(i + 1) % n])) - here
        size = np.linalg.norm(u) * np.linalg.norm(w)
        if size > 0 and abs(u[0] * w[1] - u[1] * w[0]) / size < best:
            best, joint = abs(u[0] * w[1] - u[1] * w[0]) / size, e.element.name
    return k, joint


def transmission_extremes(mech, dyad: Dyad, t, q) -> dict:
    """The transmission angle's min and max [deg] over the rows (t, q), with their times."""
    mu = np.degrees(dyad.transmission.angle(State(t, q)))
    i, j = int(np.nanargmin(mu)), int(np.nanargmax(mu))
    return {"min": float(mu[i]), "max": float(mu[j]), "t_min": float(t[i]),
            "t_max": float(t[j])}


def classify(model, backend: str | None = None, t_end: float | None = None,
             steps: int | None = None) -> Atlas:
    """The atlas of ``model`` (a file or a Model) over its run's interval (``t_end``,
    ``steps``: the model's unless given): assembled at t = 0 from its guess and followed
    along the kinematic run's grid by ``backend`` (default: the model's), as ``pam2exu run``
    would."""
    job = prepare(model, analysis="kinematic", t_end=t_end, steps=steps, backend=backend)
    mech = job.mech
    t = job.times
    t0 = float(t[0])
    rank.require_defined(mech, t0, mech.initial_q())
    guess = rank.mobility(mech, t0, mech.initial_q())
    note = ""
    if guess.dof > 0:
        q = assemble(job, guess.redundant > 0, GUESS_STIFFNESS)[None]
        solved = 1
        note = (f"{guess.dof} degree(s) of freedom not driven (solid(s) "
                f"{', '.join(guess.free_solids)}): the position at t = 0 is the assembly "
                "nearest the guess, no run is followed, and a loop's input is its first "
                "free solid next to the frame")
    else:
        q, found = positions(job, guess.redundant > 0, partial=True)
        solved = found.solved
    q0 = q[0]
    joints = np.zeros(mech.n_equations, dtype=bool)
    for el, rows in zip(mech.constraints, mech.rows):
        joints[rows] = not el.drives
    without = rank.mobility(mech, t0, q0, rows=joints)
    driven = rank.mobility(mech, t0, q0)
    moving = len(mech.solids) - len(mech.held)
    gruebler = 3 * moving - sum(el.equations for el in mech.constraints
                                if not (el.drives or el.grounds))
    basis = independent_loops(mech)
    order, dyads = placement(mech, q0, basis)
    found_loops = [describe_loop(mech, c, q0, order, dyads.get(k))
                   for k, c in enumerate(basis)]
    points = (dead_points.singular_points(mech, t, q, solved, mech.scale())
              if guess.dof == 0 else [])
    singular = []
    for p in points:
        k, joint = _where(mech, found_loops, p)
        singular.append({"t": p.t, "kind": p.kind, "loop": None if k is None else k + 1,
                         "joint": joint})
    rows_t = np.concatenate([t[:solved], [p.t for p in points]])
    rows_q = np.vstack([q[:solved], *[p.q[None] for p in points]])
    for lp in found_loops:
        if lp.dyad is not None:
            lp.transmission = transmission_extremes(mech, lp.dyad, rows_t, rows_q)
    if guess.dof == 0 and 0 < solved < len(t) and not any(p.kind == "dead point"
                                                          for p in points):
        note = (f"the run stops after t = {t[solved - 1]:g} s "
                f"(no dead point found there: run it to see why)")
    return Atlas(mech.model.name, str(mech.model.source), gruebler, without.dof,
                 sum(el.equations for el in mech.drivers), driven.dof, without.redundant,
                 without.redundant_elements, found_loops, singular,
                 (t0, float(t[solved - 1])), [sv.name for sv in mech.solids], note)
