"""What the tests compare a started process with: what /proc says of its command line and environment."""

from __future__ import annotations

import os
from pathlib import Path


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


def proc_argv(pid: int) -> list[str]:
    """A process's command line from /proc, as psutil reads it: a process forked by roc's warm start shows
    it as one title (words joined by spaces, as setproctitle writes it), an exec'd one word by word."""
    raw = Path(f"/proc/{pid}/cmdline").read_bytes()
    if raw.count(b"\0") == 1 and raw.endswith(b"\0"):
        return raw[:-1].decode().split(" ")
    return raw.decode().split("\0")[:-1]


def proc_environ(pid: int) -> dict[str, str]:
    entries = Path(f"/proc/{pid}/environ").read_bytes().decode().split("\0")
    return dict(entry.split("=", 1) for entry in entries if "=" in entry)
