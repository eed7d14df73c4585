"""Asking the user before removing files."""

from __future__ import annotations

import sys

from roc.errors import UsageError


def confirm(question: str, yes_option: str) -> bool:
    """Ask ``question [y/n]`` on the terminal until the answer is y or n; without a terminal to ask on,
    refuse (the caller names the option that skips the question)."""
    if not sys.stdin or not sys.stdin.isatty():
        raise UsageError(f"no terminal to confirm on; pass {yes_option} to remove without asking")
    while True:
        try:
            answer = input(f"{question} [y/n] ").strip().lower()
        except EOFError:
            return False
        if answer in ("y", "yes"):
            return True
        if answer in ("n", "no", ""):
            return False
