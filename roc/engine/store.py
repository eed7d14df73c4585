"""Small state kept between runs in the build base: how long each task took last time.

The durations weight the scheduler's critical path (a long package on a long chain starts first).
"""

from __future__ import annotations

import json
from pathlib import Path

from roc.engine.events import Event, TaskFinished
from roc.fsutil import write_text_if_changed


class DurationStore:
    def __init__(self, path: Path):
        self.path = path
        try:
            self.durations: dict[str, float] = json.loads(path.read_text())
        except (OSError, ValueError):
            self.durations = {}  # missing or damaged: schedule without weights

    def __call__(self, event: Event) -> None:
        if isinstance(event, TaskFinished) and not (event.cached or event.restored):
            self.durations[event.key] = round(event.duration, 3)

    def save(self) -> None:
        write_text_if_changed(self.path, json.dumps(self.durations, indent=1, sort_keys=True))
