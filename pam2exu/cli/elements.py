"""``pam2exu elements``: the element types, their keys, anchors, outputs and sign conventions
(the text of docs/model-format.md)."""
from __future__ import annotations

from ..errors import ModelError


def add_parser(sub) -> None:
    elements = sub.add_parser(
        "elements", help="the element types: keys, anchors, outputs and sign conventions",
        description="Without TYPE: every element type (Catalan PAM names in brackets) and the "
                    "time laws. With TYPE (English or Catalan): its keys, defaults, constraint "
                    "equations, outputs with units, and where its reaction is reported. The "
                    "same text as docs/model-format.md.")
    elements.add_argument("types", nargs="*", metavar="TYPE", help="e.g. revolute, piu_guia")


def command(args, warnings) -> int:
    from .. import reference
    if not args.types:
        from ..elements import ELEMENTS
        width = max(len(t) + len(c.alias) for t, c in ELEMENTS.items()) + 3
        for kind, cls in ELEMENTS.items():
            anchors = ", ".join(reference.anchor_meaning(cls, k) for k in range(len(cls.anchors)))
            print(f"{f'{kind} [{cls.alias}]':<{width}}  {anchors}: {cls.summary}")
        print("\ntime laws (law = ..., constants C = [C1, C2, C3, C4]):\n")
        print(reference.laws_markdown())
        print("pam2exu elements TYPE: keys, outputs and sign conventions of one type")
        return 0
    try:
        classes = [reference.element_class(name) for name in args.types]
    except KeyError as exc:
        raise ModelError(exc.args[0]) from None
    print("\n".join(reference.element_markdown(cls, anchor=False) for cls in classes), end="")
    return 0
