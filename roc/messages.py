"""Warnings on stderr, also kept so that a cached result can repeat the warnings it was made with."""

from __future__ import annotations

import sys

emitted: list[str] = []


def warn(message: str) -> None:
    emitted.append(message)
    print(f"roc: warning: {message}", file=sys.stderr)
