"""Which loop of a mechanism cannot close, and which lengths conflict (failure diagnosis).

The solids and the elements that tie points together (``Element.ties``: revolute, prismatic,
pin_slot and linear_actuator) form a graph; the solids held by fixed links
(``Mechanism.held``) are one node, the frame. A
joint that cannot hold closes a loop: the shortest cycle through it. Around a loop each
solid contributes the distance between the two points its joints use (its *link*), and a
linear actuator its distance f(t). A loop of pins and actuators closes only if

    the longest link ≤ the sum of the others                        (a polygon),

and, where actuators fix the angles of some solids, the part of the loop that is still free
(a chain of links between two points whose places are known) must reach across the gap
between those points: |Σ l − …| ≤ gap ≤ Σ l. ``diagnose`` says which loop and which of these fails.

Which loop: ``first_open`` builds the mechanism part by part, as its structure does (the
driven crank, the dyad that closes its loop, the dyad hung on that one …), solving each
time what is built so far, and names the first part that cannot close, with the places the
parts before it give its solids. ``diagnose`` (the loop through the worst-violated joint) is
what is left when no part is found (an element outside the loops, such as a transmission).
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from ..kinematics import rotate

#: the node of the solids held by fixed links
FRAME = -1


@dataclass(frozen=True)
class Edge:
    """A tie between two solids: the element, its two solids and its local points."""

    element: object
    a: int
    b: int
    pa: tuple[float, float]
    pb: tuple[float, float]


def _point(ref) -> tuple[float, float]:
    """The local point of an anchor (a point, or a line's defining point)."""
    return tuple(ref.anchor_point)


def edges(mech) -> list[Edge]:
    """The ties of the mechanism (``Element.ties``), in the order of its elements."""
    return [Edge(el, el.ref1.solid, el.ref2.solid, _point(el.ref1), _point(el.ref2))
            for el in mech.constraints if el.ties]


def cycle_through(mech, element, graph: list[Edge] | None = None
                  ) -> list[tuple[Edge, bool]] | None:
    """The shortest loop through ``element``: its edges in order, each with True when it
    is walked from its solid a to its solid b; None when the element closes no loop.
    ``graph``: the edges to walk (default: every tie, ``edges``)."""
    frame = mech.held
    node = (lambda s: FRAME if s in frame else s)
    graph = edges(mech) if graph is None else graph
    start = next((e for e in graph if e.element is element), None)
    if start is None or node(start.a) == node(start.b):
        return None
    # breadth-first from b back to a, without the element's own edge
    goal, origin = node(start.a), node(start.b)
    previous = {origin: None}
    queue = deque([origin])
    while queue and goal not in previous:
        here = queue.popleft()
        for e in graph:
            if e is start:
                continue
            for u, v, forward in ((node(e.a), node(e.b), True), (node(e.b), node(e.a), False)):
                if u == here and v not in previous:
                    previous[v] = (e, forward, here)
                    queue.append(v)
    if goal not in previous:
        return None
    path, here = [], goal
    while previous[here] is not None:
        e, forward, before = previous[here]
        path.append((e, forward))
        here = before
    path.reverse()
    return [(start, True), *path]


def _name(mech, solid: int) -> str:
    return mech.solids[solid].name


def known_poses(mech, t: float) -> dict[int, tuple[np.ndarray, float]]:
    """Solids whose pose (origin, fi) at time t follows from the fixed links and the angular
    actuators alone: the held solids, then every solid an actuator turns relative to a
    known one and a revolute pins to a known one."""
    poses = {i: (np.array([float(s.x), float(s.y)]), float(s.fi))
             for i, s in enumerate(mech.solids) if i in mech.held}
    angles = {i: fi for i, (_, fi) in poses.items()}
    changed = True
    while changed:
        changed = False
        for el in mech.drivers:
            if not el.angular:
                continue
            f = float(el.time_law()(np.array([t]))[0][0])
            s1, s2 = el.ref1.solid, el.ref2.solid
            if s1 in angles and s2 not in angles:
                angles[s2], changed = angles[s1] + f, True
            elif s2 in angles and s1 not in angles:
                angles[s1], changed = angles[s2] - f, True
        for el in mech.constraints:
            if not el.pins:
                continue
            for mine, other in ((el.ref2, el.ref1), (el.ref1, el.ref2)):
                if mine.solid in angles and mine.solid not in poses and other.solid in poses:
                    fi = angles[mine.solid]
                    at = place(poses[other.solid], other.local)
                    poses[mine.solid] = (at - rotate(np.array([fi]), np.asarray(mine.local))[0],
                                         fi)
                    changed = True
    return poses


def place(pose, local) -> np.ndarray:
    """r = R + A(fi) s: where a point of a solid of known pose is."""
    origin, fi = pose
    return origin + rotate(np.array([fi]), np.asarray(local, dtype=float))[0]


@dataclass
class _Node:
    """A solid of the loop, entered at one point and left at another (the frame: two held
    solids, maybe)."""

    solid_in: int
    p_in: tuple[float, float]
    label_in: str
    solid_out: int
    p_out: tuple[float, float]
    label_out: str

    def link(self, poses) -> float:
        """The distance between its two points [m]."""
        if self.solid_in != self.solid_out:
            return float(np.linalg.norm(place(poses[self.solid_out], self.p_out)
                                        - place(poses[self.solid_in], self.p_in)))
        return float(np.hypot(self.p_out[0] - self.p_in[0], self.p_out[1] - self.p_in[1]))


def _walk(mech, cycle):
    """The loop's edges (oriented) and its nodes: node k lies between edge k and edge k+1."""
    steps = []
    for e, forward in cycle:
        ref_a, ref_b = (e.element.ref1, e.element.ref2)
        if forward:
            steps.append((e, e.a, e.b, e.pa, e.pb, ref_a.label, ref_b.label))
        else:
            steps.append((e, e.b, e.a, e.pb, e.pa, ref_b.label, ref_a.label))
    nodes = []
    for k, (e, a, b, pa, pb, la, lb) in enumerate(steps):
        nxt = steps[(k + 1) % len(steps)]
        nodes.append(_Node(b, pb, lb, nxt[1], nxt[3], nxt[5]))
    return steps, nodes


def _length(step, t: float) -> float | None:
    """What an edge adds to the loop (``Element.tie_length``): 0 (a pin), f(t) (an actuator),
    None (it slides)."""
    return step[0].element.tie_length(t)


@dataclass(frozen=True)
class Diagnosis:
    """Why a loop cannot close: the text, whether its lengths prove it (``definite``), and
    the names of the loop's elements."""

    text: str
    definite: bool
    elements: tuple[str, ...]


def diagnose(mech, violated, t: float) -> Diagnosis | None:
    """The loop that cannot close at time t, from the elements ``violated`` (worst first):
    the first whose lengths prove it, else the loop of the worst; None if none is a loop."""
    found = [d for d in (describe(mech, el, t) for el in violated) if d is not None]
    return next((d for d in found if d.definite), found[0] if found else None)


def describe(mech, element, t: float) -> Diagnosis | None:
    """Why the loop through ``element`` cannot close at time t; None when the element
    closes no loop."""
    cycle = cycle_through(mech, element)
    if cycle is None:
        return None
    return describe_cycle(mech, cycle, t, known_poses(mech, t), _placers(mech, False))


def _placers(mech, loops: bool) -> str:
    """What places the solids whose poses are known: "the fixed links and the actuators
    ('motor')", and the loops built before (``loops``)."""
    drivers = ", ".join(f"'{el.name}'" for el in mech.drivers)
    actuators = f"the actuators ({drivers})" if drivers else "the actuators"
    return (f"the fixed links, {actuators} and the loops that close" if loops
            else f"the fixed links and {actuators}")


def describe_cycle(mech, cycle, t: float, poses, by: str) -> Diagnosis:
    """Why the loop ``cycle`` (``cycle_through``'s edges) cannot close at time t, where
    ``by`` (words) put the solids of ``poses`` (index → (origin, fi))."""
    members = tuple(e.element.name for e, _ in cycle)
    steps, nodes = _walk(mech, cycle)
    frame = mech.held
    names = [_name(mech, steps[0][1])]
    for (e, *_), node in zip(steps, nodes):
        names += [f"–{e.element.name}–", _name(mech, node.solid_in)]
    loop = " ".join(names)
    links = []           # (text, length or None) around the loop
    for step, node in zip(steps, nodes):
        extra = _length(step, t)
        if extra is None:
            links.append((f"'{step[0].element.name}' ({step[0].element.type}) slides", None))
        elif extra:
            links.append((f"actuator '{step[0].element.name}' {extra:.4g} m", extra))
        if node.solid_in in frame or node.solid_in == node.solid_out:
            links.append((f"{node.label_in}–{node.label_out} {node.link(poses):.4g} m",
                          node.link(poses)))
    listing = ", ".join(text for text, _ in links)
    head = f"the loop {loop} cannot close at t = {t:g} s (its lengths: {listing})"
    if any(length is None for _, length in links):
        return Diagnosis(head + "; with sliding joints the lengths alone do not decide: check "
                         "them, the lines' angles and the actuators' values at this time",
                         False, members)
    lengths = [length for _, length in links]
    k = int(np.argmax(lengths))
    rest = sum(lengths) - lengths[k]
    if lengths[k] > rest * (1 + 1e-9):
        return Diagnosis(head + f": the longest, {links[k][0]}, is longer than all the others "
                         f"together ({rest:.4g} m). Change the lengths so that none is longer "
                         "than the sum of the others", True, members)
    reach = _reach(steps, nodes, poses, t, by)
    if reach:
        return Diagnosis(head + ": " + reach, True, members)
    return Diagnosis(head + ": its lengths would close it, but not in the position its "
                     "actuators set at this time; check the actuators' values and the points "
                     "they drive", False, members)


def _reach(steps, nodes, poses, t: float, by: str) -> str | None:
    """Where ``by`` (the actuators, …) place some solids (``poses``), the free chain between
    two placed points that cannot reach across their distance, in words (None if none is
    found)."""
    known = [k for k, node in enumerate(nodes) if node.solid_in in poses
             and node.solid_out in poses]
    if not known or len(known) == len(nodes):
        return None
    count = len(nodes)
    for i in known:
        j = (i + 1) % count
        chain_nodes = []
        while j not in known:
            chain_nodes.append(j)
            j = (j + 1) % count
        if not chain_nodes:
            continue
        start, end = nodes[i], nodes[j]
        gap = float(np.linalg.norm(place(poses[end.solid_in], end.p_in)
                                   - place(poses[start.solid_out], start.p_out)))
        parts, lengths = [], []
        for k in [*chain_nodes, j]:
            extra = _length(steps[k], t)
            if extra is None:
                return None
            if extra:
                parts.append(f"actuator '{steps[k][0].element.name}' {extra:.4g} m")
                lengths.append(extra)
            if k != j:
                node = nodes[k]
                parts.append(f"{node.label_in}–{node.label_out} {node.link(poses):.4g} m")
                lengths.append(node.link(poses))
        total, longest = sum(lengths), max(lengths)
        shortest = max(0.0, 2 * longest - total)
        if gap > total * (1 + 1e-9) or gap < shortest * (1 - 1e-9):
            return (f"where {by} put them, "
                    f"{start.label_out} and {end.label_in} are {gap:.4g} m apart, but the "
                    f"chain between them ({', '.join(parts)}) spans only "
                    f"{shortest:.4g} … {total:.4g} m. Change these lengths, or the "
                    f"actuators' values at t = {t:g} s")
    return None


def bar_of(mech, element) -> tuple[int, list] | None:
    """(solid, its two ties) when the tie ``element`` holds a binary bar: one of its two
    solids, not held, that has exactly two ties (the fifth bar of a parallelogram)."""
    if not element.ties:
        return None
    graph = edges(mech)
    frame = mech.held
    for solid in (element.ref2.solid, element.ref1.solid):
        ties = [e.element for e in graph if solid in (e.a, e.b)]
        if solid not in frame and len(ties) == 2:
            return solid, ties
    return None


# ---- the loop that cannot close, in the order the mechanism is built ----------------------


@dataclass(frozen=True)
class _Unit:
    """A part of the mechanism added at once: one tie, or the loop through it (``cycle``)."""

    ties: frozenset
    cycle: tuple | None


def _units(mech) -> list[_Unit]:
    """Every tie alone and every loop (the shortest one through each tie), once each."""
    found, seen = [], set()
    for e in edges(mech):
        cycle = cycle_through(mech, e.element)
        for unit in (_Unit(frozenset([e.element]), None),
                     _Unit(frozenset(x.element for x, _ in cycle), tuple(cycle))
                     if cycle is not None else None):
            if unit is not None and unit.ties not in seen:
                seen.add(unit.ties)
                found.append(unit)
    return found


def _solids_of(unit: _Unit) -> set[int]:
    return {s for el in unit.ties for s in (el.ref1.solid, el.ref2.solid)}


def _mask(mech, elements) -> np.ndarray:
    """The equations of ``elements``, as a mask of C's rows."""
    keep = np.zeros(mech.n_equations, dtype=bool)
    for el, rows in zip(mech.constraints, mech.rows):
        if el in elements:
            keep[rows] = True
    return keep


def rigid(mech, jac, elements, new: set[int]) -> bool:
    """Whether the equations of ``elements`` fix the solids ``new`` once the others they
    touch are placed: their Jacobian columns (angles times the length scale) have full rank.
    False where those columns are not finite (the rank cannot be told there: a law constant
    of 5e-324 made one infinite, fuzz seed 60675, and the SVD raised)."""
    if not new:
        return True
    cols = [3 * s + k for s in sorted(new) for k in range(3)]
    J = jac[_mask(mech, elements)][:, cols] * np.tile([1.0, 1.0, 1.0 / mech.scale()], len(new))
    if J.shape[0] < J.shape[1] or not np.isfinite(J).all():
        return False
    sv = np.linalg.svd(J, compute_uv=False)
    return bool(sv[-1] > 1e-9 * max(1.0, sv[0]))


def _poses(q, solids) -> dict[int, tuple[np.ndarray, float]]:
    """Pose (origin, fi) of each of ``solids`` in configuration q."""
    return {s: (np.array(q[3 * s:3 * s + 2], dtype=float), float(q[3 * s + 2])) for s in solids}


#: the least squares' relative tolerance in ``first_open``: enough to tell a part that
#: closes (to the solver's tolerance) from one that stays open by more than ``can_hold``
VERDICT_TOL = 1e-10
#: ``first_open``'s solves together may do this many times ``closest.DIAGNOSIS_WORK`` (a
#: guard against crawling along a flat valley only: the Watt six-bar of the tests takes
#: 0.3 s for its three solves)
OPEN_BUDGET = 4


def first_open(mech, t: float, q_start: np.ndarray, can_hold: float,
               worst: dict[str, float] | None = None) -> Diagnosis | None:
    """The first part of the mechanism that cannot close at time t, building it as its
    structure does: from the fixed links and the actuators, add each time the smallest tie
    or loop that places its solids (Assur groups: the driven crank, then the four-bar's
    dyad, then the dyad hung on it …), solving what is built so far (least squares from
    ``q_start``, all of them within ``OPEN_BUDGET`` times ``closest.DIAGNOSIS_WORK``;
    None when that work is spent). The first addition left violated by more than ``can_hold`` is the part
    that cannot close; its diagnosis names its ties less those of the loops that closed
    before it. None when every addition closes. ``worst``: the ties' violations at
    the closest configuration of the whole mechanism, to start the loop's text at the worst.
    """
    from . import closest, native
    from ..kinematics import State

    setters = [el for el in mech.constraints if el.drives or el.grounds]
    placed = set(mech.held)
    built: set = set()
    closed: set = set()       # the ties of the loops that closed
    units = _units(mech)
    q = np.array(q_start, dtype=float)
    by = _placers(mech, False)
    budget = closest.Budget(mech, OPEN_BUDGET)
    while True:
        with np.errstate(all="ignore"):     # (two points of a distance that coincide: NaN,
            jac = native.equations(mech, State([t], q[None])).jacobian[0]   # ``rigid`` says)
        choices = []
        for order, unit in enumerate(units):
            if unit.ties <= built:
                continue
            new = _solids_of(unit) - placed
            inside = placed | new
            rules = [el for el in setters if el.ref1.solid in inside
                     and (el.ref2 is None or el.ref2.solid in inside)]
            if rigid(mech, jac, [*unit.ties, *rules], new):
                choices.append((len(new), len(unit.ties), order, unit, new))
        if not choices:
            return None
        *_, unit, new = min(choices, key=lambda c: c[:3])
        keep = _mask(mech, [*setters, *built, *unit.ties])
        left, found, converged = closest.closest_violation(
            mech, t, q, keep, budget, tol=VERDICT_TOL)
        if not converged:                # out of work: no verdict
            return None
        if not np.all(np.abs(left[keep]) <= can_hold):
            return _open(mech, unit, closed, t, _poses(q, placed), by, worst or {})
        built |= unit.ties
        placed |= new
        q = found
        if unit.cycle is not None:
            closed |= unit.ties
            by = _placers(mech, True)


def _open(mech, unit: _Unit, closed, t: float, poses, by: str,
          worst: dict[str, float]) -> Diagnosis:
    """The diagnosis of ``unit``, which cannot close where the parts built before it put
    the solids (``poses``): its ties, less those of the loops that ``closed``."""
    own = [el for el in mech.constraints if el in unit.ties and el not in closed]
    names = tuple(el.name for el in own)
    if unit.cycle is None:
        el = own[0]
        a = place(poses[el.ref1.solid], _point(el.ref1)) if el.ref1.solid in poses else None
        b = place(poses[el.ref2.solid], _point(el.ref2)) if el.ref2.solid in poses else None
        apart = (f": {by} put {el.ref1.label} and {el.ref2.label} "
                 f"{float(np.linalg.norm(b - a)):.4g} m apart" if a is not None
                 and b is not None else "")
        return Diagnosis(f"'{el.name}' ({el.type}) cannot hold at t = {t:g} s{apart}",
                         False, names)
    first = max(own, key=lambda el: worst.get(el.name, 0.0))
    cycle = cycle_through(mech, first)
    if cycle is None or frozenset(e.element for e, _ in cycle) != unit.ties:
        cycle = list(unit.cycle)
    found = describe_cycle(mech, cycle, t, poses, by)
    return Diagnosis(found.text, found.definite, names)
