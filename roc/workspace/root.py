"""Find the workspace root from any directory inside a workspace."""

from __future__ import annotations

from pathlib import Path

# Files whose presence makes a directory a package, hence not a workspace root.
PACKAGE_FILES = ("package.xml", "CMakeLists.txt", "setup.py", "colcon.pkg")


def _made_by_colcon_or_roc(directory: Path) -> bool:
    return (
        (directory / "build" / ".built_by").is_file()
        or (directory / "install" / ".colcon_install_layout").is_file()
        or any((directory / base / "COLCON_IGNORE").is_file() for base in ("build", "install", "log"))
    )


def is_workspace_root(directory: Path) -> bool:
    if any((directory / name).exists() for name in PACKAGE_FILES):
        return False
    return (directory / "roc.toml").is_file() or (directory / "src").is_dir() or _made_by_colcon_or_roc(directory)


def find_workspace_root(start: Path) -> Path | None:
    """The nearest directory at or above ``start`` that holds ``src/``, ``roc.toml``, or a build,
    install or log base made by roc or colcon (package directories never count)."""
    for directory in (start, *start.parents):
        if is_workspace_root(directory):
            return directory
    return None
