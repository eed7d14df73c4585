"""Package environments described by colcon's ``.dsv`` files, applied in Python or rendered to shell."""

from __future__ import annotations

import os


def path_list(value: str | None) -> list[str]:
    """The entries of a PATH-like variable's value, empty entries left out."""
    return [entry for entry in (value or "").split(os.pathsep) if entry]
