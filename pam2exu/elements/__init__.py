"""The ten PAM element types; ``ELEMENTS`` is the only registry from type name to class."""
from .actuators import AngularActuator, LinearActuator
from .base import ACCELERATION, FORCE, POSITION, VELOCITY, Element, Var
from .forces import Spring, Torsor, TorsionalSpring
from .joints import Fixed, PinSlot, Prismatic, Revolute, Transmission

#: type name -> element class, in the order of the contract's table
ELEMENTS: dict[str, type[Element]] = {cls.type: cls for cls in (
    Fixed, Revolute, Prismatic, PinSlot, Transmission, Torsor, Spring, TorsionalSpring,
    AngularActuator, LinearActuator)}

#: Catalan PAM type name -> type name
ALIASES: dict[str, str] = {cls.alias: cls.type for cls in ELEMENTS.values()}

__all__ = ["ELEMENTS", "ALIASES", "Element", "Var", "POSITION", "VELOCITY", "ACCELERATION",
           "FORCE", "Fixed", "Revolute", "Prismatic", "PinSlot", "Transmission", "Torsor",
           "Spring", "TorsionalSpring", "AngularActuator", "LinearActuator"]
