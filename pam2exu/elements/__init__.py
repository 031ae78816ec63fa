"""The ten PAM element types; ``ELEMENTS`` is the only registry from type name to class."""
from .actuators import AngularActuator, LinearActuator
from .base import ACCELERATION, CLEARANCE, FORCE, POSITION, VELOCITY, Element, Var
from .forces import Spring, Torsor, TorsionalSpring
from .joints import Fixed, PinSlot, Prismatic, Revolute, Transmission

#: type name -> element class, in the order of the contract's table
ELEMENTS: dict[str, type[Element]] = {cls.type: cls for cls in (
    Fixed, Revolute, Prismatic, PinSlot, Transmission, Torsor, Spring, TorsionalSpring,
    AngularActuator, LinearActuator)}

#: Catalan PAM type name -> type name
ALIASES: dict[str, str] = {cls.alias: cls.type for cls in ELEMENTS.values()}

#: the types that take ``clearance = true`` (those with ``clearance_parameters``)
CLEARANCE_TYPES: tuple[str, ...] = tuple(t for t, cls in ELEMENTS.items()
                                         if cls.clearance_parameters)


def misplaced_clearance(kind: str) -> str:
    """The message for ``clearance`` on an element type that takes none."""
    *others, last = CLEARANCE_TYPES
    return (f"a {kind} takes no 'clearance': only {', '.join(others)} and {last} joints can "
            "have clearance (the clearance analysis); remove the key")

__all__ = ["ELEMENTS", "ALIASES", "CLEARANCE_TYPES", "misplaced_clearance", "Element", "Var",
           "POSITION", "VELOCITY", "ACCELERATION", "FORCE", "CLEARANCE",
           *(cls.__name__ for cls in ELEMENTS.values())]
