"""Stopping one process of a ``roc launch`` run from roc tui is on purpose: the process is shown stopped,
is not respawned, and does not fail the run (ros2 launch goes on, and exits 0, when a process is stopped
from outside); a launch file's process cannot be started again, and the view says so."""

from __future__ import annotations

import asyncio
import os
import re
import time
from pathlib import Path

import pytest
from helpers.launch import demo_env, roc_launch, skip_without_launch_library
from helpers.tui import launch_rows, live_graph, open_launches, table, text_of, until, until_screen

from roc.tui.app import RocApp

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("tui_launch")]
SYSTEM = """
[launch.pair]
[[launch.pair.process]]
package = "roc_launch_demo"
executable = "talker"
parameters = { rate = 5.0 }
respawn = true
respawn-delay = 0.5

[[launch.pair.process]]
package = "sleeper"
executable = "sleep_forever"
"""
# a process as many are written: Ctrl+C (SIGINT) ends it with KeyboardInterrupt, exit code -2, not 0
SLEEPER = "#!/usr/bin/env python3\nimport time\nprint('sleeping', flush=True)\ntime.sleep(600)\n"


def sleeper_prefix(root: Path) -> Path:
    """An install prefix with the package ``sleeper`` and its executable, laid out as colcon installs one."""
    (root / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (root / "share" / "ament_index" / "resource_index" / "packages" / "sleeper").write_text("")
    script = root / "lib" / "sleeper" / "sleep_forever"
    script.parent.mkdir(parents=True)
    script.write_text(SLEEPER)
    script.chmod(0o755)
    return root


async def stop_from_the_view(app, pilot, process: str, last: bool = False) -> None:
    """``s`` on the process; then it is shown stopped (the ``last`` one of a run ends the run)."""
    processes = table(app, "#processes")
    processes.select(next(key for key, row in processes.rows_by_key.items() if row.cells[0] == process))
    await pilot.press("s")
    if not last:
        await until_screen(app, pilot, lambda _: launch_rows(app)[process].cells[3].startswith("stopped"),
                           f"{process} stopped")


def test_a_process_stopped_on_purpose_is_not_respawned_nor_a_failure(tmp_path, launch_demo_prefix) -> None:
    (tmp_path / "runtime").mkdir()
    env = demo_env(64, tmp_path / "runtime", launch_demo_prefix)
    env["AMENT_PREFIX_PATH"] += os.pathsep + str(sleeper_prefix(tmp_path / "sleeper"))
    (tmp_path / "roc.toml").write_text(SYSTEM)
    launcher = roc_launch("pair", env=env, log=tmp_path / "launch.log")
    try:
        with live_graph(env, []):
            async def test() -> None:
                app = RocApp()
                async with app.run_test(size=(100, 30)) as pilot:
                    await open_launches(app, pilot, {"talker", "sleep_forever"})
                    await stop_from_the_view(app, pilot, "talker")
                    stopped = time.monotonic()  # respawn-delay is 0.5 s: a respawn would come by now
                    await until(pilot, lambda: time.monotonic() > stopped + 3.0, what="three seconds")
                    assert launch_rows(app)["talker"].cells[3].startswith("stopped"), launch_rows(app)["talker"]
                    assert launch_rows(app)["talker"].cells[4] == "0"  # no restart
                    await stop_from_the_view(app, pilot, "sleep_forever", last=True)
            asyncio.run(test())
            code = launcher.process.wait(timeout=30)  # every process ended: the run ends by itself
        output = launcher.output()
        assert code == 0, output  # though the sleeper ended with an error code:
        assert re.search(r"\[sleep_forever\]: process has died \[pid \d+, exit code -2", output), output
        assert output.count("[INFO] [talker]: process started") == 1, output
    finally:
        launcher.stop()


def test_a_launch_file_process_stopped_and_why_it_cannot_be_restarted(tmp_path, launch_demo_prefix) -> None:
    skip_without_launch_library()
    (tmp_path / "runtime").mkdir()
    env = demo_env(64, tmp_path / "runtime", launch_demo_prefix)
    launch_file = launch_demo_prefix / "share" / "roc_launch_demo" / "launch" / "demo.launch.py"
    launcher = roc_launch(str(launch_file), env=env, log=tmp_path / "launch.log")
    try:
        with live_graph(env, []):
            async def test() -> None:
                app = RocApp()
                async with app.run_test(size=(100, 30)) as pilot:
                    await open_launches(app, pilot, {"listener-2"})
                    await stop_from_the_view(app, pilot, "listener-2")
                    assert "cannot be restarted" in text_of(app, "#detail")
                    await pilot.press("R")
                    await until_screen(app, pilot, lambda s: "listener-2: cannot restart a launch file's process" in s,
                                       "the view saying why")
                    assert launch_rows(app)["listener-2"].cells[3].startswith("stopped")
            asyncio.run(test())
        assert launcher.stop() == 0, launcher.output()  # as ros2 launch: a process stopped is no failure
    finally:
        launcher.stop()
