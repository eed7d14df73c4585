"""The runnable examples of the manual (docs/**/*.md) and of README.md, and how their output is compared.

The convention, for a writer:

    <!-- example: workspaces/example -->
    ```console
    $ roc work list -n --packages-up-to demo_py
    demo_interfaces
    demo_py
    ```

- The comment names a directory of the repository; the console block right after it is run in a fresh
  copy of that directory (without its build/, install/ and log/). Every block of one page that names
  the same directory runs in the same copy, in page order, so a page can build and then show what the
  build left. Mark the blocks that take more than a few seconds (a build) `, slow`
  (`<!-- example: workspaces/example, slow -->`): they run in a copy of their own (shared by the page's
  slow blocks of that directory), in a test left out of the quick loop.
- Each `$ ` line is one command, run by bash with the project's `.venv/bin` first on PATH; the lines
  after it, up to the next `$ ` line, are its output (stdout and stderr together).
- Output that varies from run to run: `...` alone on a line stands for any number of lines (none
  included), and `...` inside a line for any text on that line (`Finished <<< demo_core [...]`).
  Trailing spaces, and blank lines at the end of an output, do not count.

Console blocks without the comment are shown, never run (examples of a live ROS graph).
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
MARKER = re.compile(r"^<!--\s*example:\s*(?P<directory>[^,\s]+)\s*(?P<slow>,\s*slow\s*)?-->\s*$")
ELLIPSIS = "..."


@dataclass
class Command:
    line: int  # 1-based line of the `$ ` line in its page
    command: str
    expected: list[str] = field(default_factory=list)


@dataclass
class Sequence:
    """The examples of one page that run in one directory."""

    page: str  # relative to the repository
    directory: str
    slow: bool = False
    commands: list[Command] = field(default_factory=list)

    @property
    def name(self) -> str:
        return f"{self.page}@{self.directory}" + (",slow" if self.slow else "")


def pages() -> list[Path]:
    return sorted((REPO / "docs").rglob("*.md")) + [REPO / "README.md"]


def sequences(path: Path) -> list[Sequence]:
    """The runnable examples of one Markdown file, by directory."""
    page = str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)
    lines = path.read_text().splitlines()
    found: dict[str, Sequence] = {}
    index = 0
    while index < len(lines):
        marker = MARKER.match(lines[index])  # at the start of a line: not one quoted in an indented block
        index += 1
        if not marker:
            continue
        if index >= len(lines) or lines[index].rstrip() != "```console":
            raise ValueError(f"{page}:{index}: an example comment must be followed by a ```console block")
        slow = bool(marker["slow"])
        sequence = found.setdefault(f"{marker['directory']}{slow}", Sequence(page, marker["directory"], slow))
        index += 1
        started = False  # a command of this block was seen
        while index < len(lines) and lines[index].strip() != "```":
            text = lines[index]
            if text.startswith("$ "):
                sequence.commands.append(Command(index + 1, text[2:]))
                started = True
            elif not started:
                raise ValueError(f"{page}:{index + 1}: output before the first '$ ' command of the block")
            else:
                sequence.commands[-1].expected.append(text)
            index += 1
        if index >= len(lines):
            raise ValueError(f"{page}: the console block of the example comment is not closed")
    return list(found.values())


def _line_pattern(expected: str) -> re.Pattern[str]:
    parts = (re.escape(part) for part in expected.rstrip().split(ELLIPSIS))
    return re.compile(".*".join(parts) + r"\Z")


def _without_trailing_blank_lines(lines: list[str]) -> list[str]:
    while lines and not lines[-1]:
        lines = lines[:-1]
    return lines


def matches(expected: list[str], actual: list[str]) -> bool:
    """Whether ``actual`` lines are what ``expected`` shows, with ``...`` as described above."""
    expected = _without_trailing_blank_lines([line.rstrip() for line in expected])
    actual = _without_trailing_blank_lines([line.rstrip() for line in actual])

    @functools.cache
    def match(e: int, a: int) -> bool:
        if e == len(expected):
            return a == len(actual)
        if expected[e].strip() == ELLIPSIS:
            return any(match(e + 1, skip) for skip in range(a, len(actual) + 1))
        return a < len(actual) and bool(_line_pattern(expected[e]).match(actual[a])) and match(e + 1, a + 1)

    return match(0, 0)
