"""A workspace's packages for the TUI: each with its type, the state of its last build (colcon's
``colcon_build.rc``), when that was and how long it took (``roc_durations.json``)."""

from __future__ import annotations

import json
import time
from pathlib import Path

from roc.tui.model import Row

DURATIONS_FILE = "roc_durations.json"  # roc.commands.work.build's


def age_text(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.0f} s ago"
    if seconds < 3600:
        return f"{seconds / 60:.0f} min ago"
    if seconds < 86400:
        return f"{seconds / 3600:.0f} h ago"
    return f"{seconds / 86400:.0f} d ago"


class WorkspaceView:
    COLUMNS = ("package", "type", "state", "last build", "duration")

    def __init__(self, root: Path, build_base: str = "build") -> None:
        self.root = root
        self.build_base = root / build_base

    def packages(self) -> list:
        from roc.workspace.load import discover_workspace

        return sorted(discover_workspace(self.root), key=lambda p: p.name)

    def rows(self) -> list[Row]:
        try:
            durations = json.loads((self.build_base / DURATIONS_FILE).read_text())
        except (OSError, ValueError):
            durations = {}
        now = time.time()
        rows = []
        for package in self.packages():
            result = self.build_base / package.name / "colcon_build.rc"
            try:
                code, when = result.read_text().strip(), result.stat().st_mtime
            except OSError:
                code, when = None, None
            state = "not built" if code is None else "built" if code == "0" else "failed"
            duration = durations.get(package.name)
            rows.append(Row(package.name, (package.name, package.type, state,
                                           age_text(now - when) if when else "-",
                                           f"{duration:.1f} s" if duration is not None else "-"),
                            ["build failed"] if state == "failed" else []))
        return rows

    def details(self, name: str) -> str:
        """A package's path, dependencies and its last build's stderr, for Enter on its row."""
        package = next((p for p in self.packages() if p.name == name), None)
        if package is None:
            return f"no package {name}"
        lines = [f"path: {package.path}", f"type: {package.type}"]
        for category, names in sorted(package.dependencies.items()):
            lines.append(f"{category} dependencies: {', '.join(sorted(names)) or '-'}")
        stderr = self.root / "log" / "latest_build" / name / "stderr.log"
        if stderr.is_file() and stderr.stat().st_size:
            lines += ["", f"stderr of the last build ({stderr}):", stderr.read_text(errors="replace")]
        return "\n".join(lines)
