"""One log file per process of a launched system, ``<run directory>/<process name>.log``: everything the
process wrote (stdout and stderr as they came), with a ``[roc]`` line when it starts and when it ends."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TextIO


def file_name(process: str) -> str:
    """A process name as a file name (launch names such as ``talker-1`` stay as they are)."""
    return "".join(c if c.isalnum() or c in "-_.@" else "_" for c in process).lstrip(".") or "_"


class ProcessLogs:
    def __init__(self, directory: Path):
        self.directory = directory
        self._files: dict[str, TextIO] = {}

    def _file(self, process: str) -> TextIO:
        if process not in self._files:
            self._files[process] = open(self.directory / f"{file_name(process)}.log", "a", buffering=1,
                                        errors="replace")
        return self._files[process]

    def write(self, process: str, text: str) -> None:
        self._file(process).write(text)

    def note(self, process: str, text: str) -> None:
        self._file(process).write(f"[roc] {time.strftime('%Y-%m-%d %H:%M:%S')} {text}\n")

    def close(self) -> None:
        for handle in self._files.values():
            handle.close()
        self._files.clear()
