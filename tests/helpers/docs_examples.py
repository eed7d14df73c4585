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

Examples of a live ROS graph say which graph runs while they do: `<!-- example: workspaces/example, graph
demo -->`. The graphs are tests/helpers/docs_graphs.py's (the example workspace's reading_publisher, a
motor controller, a fibonacci server, ...); the block's commands run in a copy of the directory while
that graph runs, in a ROS domain of the test's own, with the example workspace built and sourced. A
command that runs until Ctrl+C shows `^C` on a line of its own where the reader pressed it: the test
presses Ctrl+C (SIGINT) once the output before it has been printed, and the lines after `^C` are the
last the command printed (what it printed while the signal was on its way does not count). A command
that prints nothing while it works, such as a recording, is interrupted as late as its comment says:
`<!-- example: DIR, graph NAME, ctrl-c after 3 s -->`. A file an example needs is a block right after
`<!-- example file: NAME -->` (any language), written as NAME into the directory of every example of that page before
they run.

A console block that shows output but cannot run (two machines, a client elsewhere) says why:
`<!-- not run: REASON -->`. tests/docs/test_docs.py checks that every console block showing output is
either run or says why not. Console blocks of commands alone (no output) are shown, never run.
"""

from __future__ import annotations

import functools
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent
MARKER = re.compile(r"^<!--\s*example:\s*(?P<directory>[^,\s]+)\s*(?P<slow>,\s*slow\s*)?"
                    r"(?:,\s*graph\s+(?P<graph>[\w-]+)\s*)?"
                    r"(?:,\s*ctrl-c after\s+(?P<after>\d+(?:\.\d+)?)\s*s\s*)?-->\s*$")
FILE_MARKER = re.compile(r"^<!--\s*example file:\s*(?P<name>[^\s]+)\s*-->\s*$")
NOT_RUN = re.compile(r"^<!--\s*not run:\s*\S.*-->\s*$")
ELLIPSIS = "..."
INTERRUPT = "^C"  # an output line: the reader pressed Ctrl+C here


@dataclass
class Command:
    line: int  # 1-based line of the `$ ` line in its page
    command: str
    expected: list[str] = field(default_factory=list)
    interrupt_after: float = 0.0  # the reader's Ctrl+C comes no sooner than this many seconds after the start


@dataclass
class Sequence:
    """The examples of one page that run in one directory."""

    page: str  # relative to the repository
    directory: str
    slow: bool = False
    graph: str | None = None  # the live graph of tests/helpers/docs_graphs.py the commands run beside
    commands: list[Command] = field(default_factory=list)
    files: dict[str, str] = field(default_factory=dict)  # written into the directory first

    @property
    def name(self) -> str:
        return f"{self.page}@{self.directory}" + (",slow" if self.slow else "") + (
            f",graph {self.graph}" if self.graph else "")


def pages() -> list[Path]:
    return sorted((REPO / "docs").rglob("*.md")) + [REPO / "README.md"]


def _fenced_block(lines: list[str], start: int, page: str) -> tuple[list[str], int]:
    """The lines of the fenced block opening on line index ``start``, and the index after its end."""
    end = start + 1
    while end < len(lines) and lines[end].strip() != "```":
        end += 1
    if end >= len(lines):
        raise ValueError(f"{page}:{start + 1}: the block is not closed")
    return lines[start + 1:end], end + 1


def sequences(path: Path) -> list[Sequence]:
    """The runnable examples of one Markdown file, by directory (and live graph)."""
    page = str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)
    lines = path.read_text().splitlines()
    found: dict[str, Sequence] = {}
    files: dict[str, str] = {}
    index = 0
    while index < len(lines):
        file_marker = FILE_MARKER.match(lines[index])
        marker = MARKER.match(lines[index])  # at the start of a line: not one quoted in an indented block
        index += 1
        if file_marker:
            if index >= len(lines) or not lines[index].startswith("```"):
                raise ValueError(f"{page}:{index}: an example file comment must be followed by a fenced block")
            content, index = _fenced_block(lines, index, page)
            files[file_marker["name"]] = "\n".join(content) + "\n"
            continue
        if not marker:
            continue
        if index >= len(lines) or lines[index].rstrip() != "```console":
            raise ValueError(f"{page}:{index}: an example comment must be followed by a ```console block")
        slow = bool(marker["slow"])
        key = f"{marker['directory']}{slow}{marker['graph']}"
        sequence = found.setdefault(key, Sequence(page, marker["directory"], slow, marker["graph"]))
        block, end = _fenced_block(lines, index, page)
        started = False  # a command of this block was seen
        for number, text in enumerate(block, index + 2):
            if text.startswith("$ "):
                sequence.commands.append(Command(number, text[2:], interrupt_after=float(marker["after"] or 0)))
                started = True
            elif not started:
                raise ValueError(f"{page}:{number}: output before the first '$ ' command of the block")
            else:
                sequence.commands[-1].expected.append(text)
        index = end
    for sequence in found.values():
        sequence.files = files
    return list(found.values())


def unchecked_output_blocks(path: Path) -> list[int]:
    """The lines of the console blocks of a page that show output (a line not starting with ``$ ``) but are
    neither run (an example comment) nor say why not (a not-run comment); a transcript in an indented code
    block (a ``$ `` line and output) counts as an unchecked block too: make it a console block."""
    lines = path.read_text().splitlines()
    unchecked = []
    index = 0
    while index < len(lines):
        line = lines[index]
        if line.startswith("```"):  # fenced: skip to its end, checking console blocks
            block, end = _fenced_block(lines, index, str(path))
            before = lines[index - 1] if index else ""
            if line.rstrip() == "```console" and any(text.strip() and not text.startswith("$ ") for text in block) \
                    and not (MARKER.match(before) or NOT_RUN.match(before)):
                unchecked.append(index + 1)
            index = end
            continue
        if line.startswith("    ") and (index == 0 or not lines[index - 1].strip()):  # an indented block
            end = index
            while end < len(lines) and (lines[end].startswith("    ") or not lines[end].strip()):
                end += 1
            block = [text[4:] for text in lines[index:end] if text.strip()]
            said = NOT_RUN.match(block[0]) or (index >= 2 and NOT_RUN.match(lines[index - 2]))  # a quoted example
            if any(text.startswith("$ ") for text in block) and any(not text.startswith("$ ") for text in block) \
                    and not said:
                unchecked.append(index + 1)
            index = end
            continue
        index += 1
    return unchecked


def split_at_interrupt(expected: list[str]) -> tuple[list[str], list[str] | None]:
    """The output before the reader's Ctrl+C and after it (None: the command ends by itself)."""
    if INTERRUPT not in [line.rstrip() for line in expected]:
        return expected, None
    at = [line.rstrip() for line in expected].index(INTERRUPT)
    return expected[:at], expected[at + 1:]


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


def reader_environment(home: Path) -> dict[str, str]:
    """A reader's shell: no ROS environment sourced (roc's own .venv is the underlay), nobody's colcon
    settings, Python's byte-code writing on (as on a machine without PYTHONDONTWRITEBYTECODE)."""
    drop = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "COLCON_PREFIX_PATH", "PYTHONPATH", "PYTHONDONTWRITEBYTECODE",
            "COLCON_DEFAULTS_FILE", "ROC_CACHE_DIR", "XDG_CACHE_HOME", "MAKEFLAGS", "CMAKE_GENERATOR", "NO_COLOR")
    env = {k: v for k, v in os.environ.items() if k not in drop and not k.startswith("ROC_")}
    env.update(HOME=str(home), PATH=f"{BIN}{os.pathsep}{env.get('PATH', '/usr/bin:/bin')}", PYTHONUNBUFFERED="1")
    return env
