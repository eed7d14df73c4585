"""What colcon infers from a plain CMake project: its name and the packages it looks for."""

from __future__ import annotations

import os
import re
from pathlib import Path

# A quoted string, a comment, or anything else; comments outside strings are dropped.
_LINE_PARTS = re.compile(r'("[^"]*")|(#.*)|([^#"]+)')
_NAME = r'("?)([A-Za-z0-9_-]+)\{q}'
# Command names are case-insensitive in CMake; colcon matches them so too.
_PROJECT = re.compile(r"(?i:project)\s*\(\s*" + _NAME.format(q=1) + r"(\s+[^)]*)?\)")
_FIND_PACKAGE = re.compile(r"(?i:find_package)\s*\(\s*" + _NAME.format(q=1) + r"(\s+[^)]*)?\)")
_PKG_CONFIG = re.compile(
    r'(?i:pkg_check_modules|pkg_search_module)\s*\(\s*("?)[A-Za-z0-9_]+\1'
    r"(?:\s+(?:REQUIRED|QUIET|NO_CMAKE_PATH|NO_CMAKE_ENVIRONMENT_PATH))*([^)]+)\)"
)


def strip_comments(text: str) -> str:
    lines = []
    for line in text.splitlines():
        lines.append("".join(m.group(1) or m.group(3) or "" for m in _LINE_PARTS.finditer(line)))
    return "\n".join(lines)


def _cmake_files(directory: Path, skip: Path) -> str:
    """All CMakeLists.txt and *.cmake files below ``directory`` (hidden directories skipped)."""
    parts = []
    for dirpath, dirnames, filenames in os.walk(directory):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        for name in sorted(filenames):
            path = Path(dirpath, name)
            if (name == "CMakeLists.txt" or name.endswith(".cmake")) and path != skip:
                parts.append(path.read_text(errors="replace"))
    return strip_comments("\n".join(parts))


def read_cmake_project(cmakelists: Path) -> tuple[str, set[str]] | None:
    """The project name (the directory name when it has none) and its inferred dependencies; None for
    the top-level CMakeLists.txt that catkin_make puts in ``src/``, which is not a package."""
    text = cmakelists.read_text(errors="replace")
    content = strip_comments(text)
    match = _PROJECT.search(content)
    name = match.group(2) if match else cmakelists.parent.name
    if name == "Project" and "catkin_workspace()" in text.splitlines():
        return None
    everything = content + "\n" + _cmake_files(cmakelists.parent, cmakelists)
    depends = {m.group(2) for m in _FIND_PACKAGE.finditer(everything)}
    for match in _PKG_CONFIG.finditer(everything):
        for module in match.group(2).split():
            depends.add(re.split(r"[<>=]", module, maxsplit=1)[0])
    depends.discard(name)
    depends.discard("")
    return name, depends
