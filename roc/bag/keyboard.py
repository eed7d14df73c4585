"""Keys pressed on the terminal, for the player's and the recorder's keyboard controls (space,
arrows), read on a thread of their own with the terminal in cbreak mode and restored at the end."""

from __future__ import annotations

import os
import select
import sys
import threading
from collections.abc import Callable

_SEQUENCES = {b" ": "space", b"\x1b[C": "right", b"\x1b[A": "up", b"\x1b[B": "down", b"\x1b[D": "left"}


class Keyboard:
    """Calls ``on_key(name)`` for each known key while open; does nothing when stdin is no terminal."""

    def __init__(self, on_key: Callable[[str], None], enabled: bool = True) -> None:
        self._on_key = on_key
        self._fd = sys.stdin.fileno() if enabled and sys.stdin is not None and sys.stdin.isatty() else None
        self._saved: list | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def active(self) -> bool:
        return self._fd is not None

    def __enter__(self) -> Keyboard:
        if self._fd is None:
            return self
        import termios
        import tty

        try:
            self._saved = termios.tcgetattr(self._fd)
            tty.setcbreak(self._fd)
        except termios.error:
            self._fd = None
            return self
        self._thread = threading.Thread(target=self._read, name="roc-keyboard", daemon=True)
        self._thread.start()
        return self

    def _read(self) -> None:
        assert self._fd is not None
        while not self._stop.is_set():
            ready, _, _ = select.select([self._fd], [], [], 0.1)
            if not ready:
                continue
            data = os.read(self._fd, 16)
            if not data:
                return
            while data:
                name = next((n for sequence, n in _SEQUENCES.items() if data.startswith(sequence)), None)
                if name is not None:
                    self._on_key(name)
                    data = data[len(next(s for s, n in _SEQUENCES.items() if n == name)):]
                else:
                    data = data[1:]

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1)
        if self._fd is not None and self._saved is not None:
            import termios

            termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
