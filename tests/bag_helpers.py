"""Helpers for the bag tests: messages of any type with every field set to a non-default value, and a
publisher process that sends them."""

from __future__ import annotations

import importlib
from typing import Any

TEST_MSGS = ("Arrays", "BasicTypes", "BoundedPlainSequences", "BoundedSequences", "Builtins", "Constants",
             "Defaults", "Empty", "MultiNested", "Nested", "Strings", "UnboundedSequences", "WStrings")


def load(type_name: str) -> type:
    package, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def _value(slot: Any, seed: int) -> Any:
    from rosidl_parser import definition as d

    if isinstance(slot, d.AbstractNestedType):
        size = slot.size if isinstance(slot, d.Array) else min(2, getattr(slot, "maximum_size", 2) or 2)
        return [_value(slot.value_type, seed + i) for i in range(size)]
    if isinstance(slot, d.NamespacedType):
        cls = load("/".join([*slot.namespaces, slot.name]))
        return filled(cls, seed)
    if isinstance(slot, (d.AbstractString, d.AbstractWString)):
        bound = getattr(slot, "maximum_size", None)
        text = f"v{seed}é" if isinstance(slot, d.AbstractWString) else f"value {seed}"
        return text[:bound] if bound else text
    kind = slot.typename
    if kind == "boolean":
        return seed % 2 == 0
    if kind == "octet":
        return bytes([seed % 256])
    if kind in ("float", "double"):
        return seed + 0.5
    if kind == "char":
        return 65 + seed % 26
    return seed % 100 + 1


def filled(cls: type, seed: int = 1) -> Any:
    """An instance of ``cls`` with every field set (nested messages and arrays too)."""
    import numpy

    message = cls()
    for index, (name, slot) in enumerate(zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES)):
        value = _value(slot, seed + index)
        current = getattr(message, name)
        if isinstance(current, numpy.ndarray):
            value = numpy.array(value, dtype=current.dtype)
        elif hasattr(current, "typecode"):  # array.array
            import array

            value = array.array(current.typecode, value)
        setattr(message, name, value)
    return message
