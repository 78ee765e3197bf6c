"""A frozen dataclass with some of its fields changed, without ``dataclasses.replace``'s cost.

``dataclasses.replace(obj, **changes)`` reads every field back by name, gathers them in a
dict and calls the class's ``__init__``, which sets each field through
``object.__setattr__`` (the class is frozen): 3-6 us for a state estimate or a board's, and
the rider makes several a control tick (each Hovershoe's corrected heading, the estimate
holding them, the contact set's least forces). Where ``__init__`` only stores the fields
(a dataclass whose fields all go through ``__init__``, without ``__post_init__``, without a
custom ``__init__``, with an instance ``__dict__``), the object that ``replace`` makes is
the original's fields with the changed ones written over them: :func:`changed` makes that
object directly. Only the fields are copied, so a value a method cached on the instance is
not carried over, as with ``replace``. Any other class, or a name that is not such a
field, goes through ``replace`` itself (which raises as it does).
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

__all__ = ["changed"]

T = TypeVar("T")

# per class: its fields' names when __init__ only stores them, else None (replace)
_STORED: dict[type, tuple[frozenset[str], tuple[str, ...]] | None] = {}


def _stored_fields(cls: type) -> tuple[frozenset[str], tuple[str, ...]] | None:
    """The names of ``cls``'s fields if its ``__init__`` only stores them, else None."""
    params = getattr(cls, "__dataclass_params__", None)
    every = getattr(cls, "__dataclass_fields__", None)
    if params is None or every is None or not params.init or hasattr(cls, "__post_init__"):
        return None
    if "__slots__" in cls.__dict__ or cls.__new__ is not object.__new__:
        return None  # slots: no __dict__
    init = cls.__dict__.get("__init__")
    if getattr(getattr(init, "__code__", None), "co_filename", None) != "<string>":
        return None  # not the __init__ that dataclasses wrote (exec'd source) for this class
    fields = dataclasses.fields(cls)
    if len(fields) != len(every) or not all(f.init for f in fields):
        return None  # an InitVar (or a ClassVar), or a field __init__ does not take
    names = tuple(f.name for f in fields)
    return frozenset(names), names


def changed(obj: T, **changes: Any) -> T:
    """``dataclasses.replace(obj, **changes)``, made directly where that is the same object
    (module docstring)."""
    cls = type(obj)
    try:
        stored = _STORED[cls]
    except KeyError:
        stored = _STORED[cls] = _stored_fields(cls)
    if stored is None or not stored[0].issuperset(changes):
        return dataclasses.replace(obj, **changes)  # type: ignore[type-var]
    old = obj.__dict__
    copy = object.__new__(cls)
    values = copy.__dict__
    for name in stored[1]:
        values[name] = old[name]
    values.update(changes)
    return copy
