"""Tests for the fixes of issue 17 (what a newcomer trial found)."""

from __future__ import annotations

import io
from pathlib import Path

from build_helpers import copy_fixture, roc

from roc.engine.events import Tick, TaskOutput, TaskQueued, TaskStarted


class FakeLive:
    def __init__(self) -> None:
        self.updates: list[str] = []

    def start(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def update(self, renderable, refresh: bool = False) -> None:
        self.updates.append(str(renderable))


def test_status_line_redraws_only_on_change_and_at_most_four_times_a_second():
    from rich.console import Console

    from roc.handlers.status import StatusLine

    now = [100.0]
    live = FakeLive()
    status = StatusLine(console=Console(file=io.StringIO(), width=120), live=live, clock=lambda: now[0])
    status(TaskQueued("a"))
    status(TaskStarted("a"))  # within 0.25 s of the first draw: not drawn
    assert live.updates == ["[0s] [0/1 done] [0 running] "]
    for _ in range(100):  # a burst of output in the same instant: no redraw
        status(TaskOutput("a", data=b"compiling"))
    assert len(live.updates) == 1
    now[0] += 0.3
    status(Tick(""))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a"
    now[0] += 0.3
    for _ in range(100):  # unchanged text: never redrawn, however long it goes on
        status(TaskOutput("a", data=b"no progress here"))
        now[0] += 0.001
    assert len(live.updates) == 2
    status(TaskOutput("a", data=b"[ 45%] Building"))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a 45%"
    # 10 s of events every 10 ms, the text changing each second: one redraw per change
    for _ in range(1000):
        now[0] += 0.01
        status(Tick(""))
    assert len(live.updates) == 3 + 10


def test_paths_entries_that_are_not_directories_are_ignored(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    (workspace / "src" / "README.md").write_text("a file beside the packages\n")
    # what a shell makes of 'src/*' (and a path that does not exist at all)
    paths = sorted(str(p.relative_to(workspace)) for p in (workspace / "src").iterdir())
    result = roc("work", "list", "-n", "--paths", *paths, "src/missing", cwd=workspace)
    assert result.returncode == 0, result.stderr
    assert "core" in result.stdout.split() and len(result.stdout.split()) == 10
