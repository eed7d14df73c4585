"""Errors that roc reports to the user as one clear line (no traceback)."""

from __future__ import annotations

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


class RocError(Exception):
    """A failure the user can act on; the message says what and where. ``ros2_line``: the line the ros2
    CLI prints for the same failure, where roc's message says more than it; printed first, then roc's
    ``roc: error: ...`` line (ros2's own words stay where a user or a script looks for them)."""

    exit_code = EXIT_FAILURE

    def __init__(self, message: str = "", *, ros2_line: str | None = None) -> None:
        super().__init__(message)
        self.ros2_line = ros2_line


class UsageError(RocError):
    """Bad command-line input (unknown package name, conflicting options, ...)."""

    exit_code = EXIT_USAGE


class ManifestError(RocError):
    """A package manifest (package.xml, colcon.pkg, setup.cfg, ...) that cannot be read."""

    def __init__(self, path: str, message: str, line: int | None = None):
        location = f"{path}:{line}" if line else str(path)
        super().__init__(f"{location}: {message}")
        self.path = path
        self.line = line
