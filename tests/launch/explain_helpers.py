"""What the tests of ``roc launch --explain`` compare a started process with."""

from __future__ import annotations

import os


def as_proc_shows(command: list[str]) -> list[str]:
    """The command line /proc/PID/cmdline shows for ``command`` exec'd: a script's ``#!`` interpreter (and
    its argument) before it, as the kernel runs it (``#!/usr/bin/env python3`` runs ``python3``)."""
    try:
        with open(command[0], "rb") as handle:
            head = handle.readline()
    except OSError:
        return command
    if not head.startswith(b"#!"):
        return command
    words = head[2:].decode().split()
    if os.path.basename(words[0]) == "env":
        words = words[1:]
    return [*words, *command]
