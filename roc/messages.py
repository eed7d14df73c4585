"""Warnings on stderr, also kept so that a cached result can repeat the warnings it was made with."""

from __future__ import annotations

import sys
from collections.abc import Iterable

emitted: list[str] = []
# Package names share their suffixes (``_msgs``, ``_srvs``, ``_interfaces``), which alone makes ``foo_msgs``
# look 60-75 % like ``tf2_msgs`` or ``std_msgs``: for them, only a name one or two typos away is suggested.
PACKAGE_NAME_CUTOFF = 0.85


def warn(message: str) -> None:
    emitted.append(message)
    print(f"roc: warning: {message}", file=sys.stderr)


def did_you_mean(word: str, choices: Iterable[str], count: int = 3, quote: bool = True, cutoff: float = 0.6) -> str:
    """``did you mean 'a' or 'b'?`` for the choices closest to a misspelled ``word`` (a similarity of
    at least ``cutoff``, 0 to 1), or ''."""
    import difflib

    close = difflib.get_close_matches(word, sorted(choices), n=count, cutoff=cutoff)
    names = [f"'{name}'" if quote else name for name in close]
    return f"did you mean {' or '.join(names)}?" if names else ""


def unknown_package(name: str, names: Iterable[str]) -> str:
    """The one message for a package name the workspace does not have, with the closest names."""
    hint = did_you_mean(name, names, quote=False) or "run 'roc work list -n' to see the package names"
    return f"no package named '{name}' in the workspace; {hint}"
