"""The manual's examples of a live ROS graph (``<!-- example: DIR, graph NAME -->``) print what the pages
show: each page's commands run beside the graph it describes (tests/helpers/docs_graphs.py), with the
example workspace built and sourced, in a ROS domain of this file's own. A command shown until the
reader's ``^C`` gets SIGINT once the output before it was printed."""

from __future__ import annotations

import os
import queue
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest
from helpers.build import ros_domain_id
from helpers.docs_examples import (
    REPO,
    Command,
    Sequence,
    matches,
    pages,
    reader_environment,
    sequences,
    split_at_interrupt,
)
from helpers.docs_graphs import LiveGraph

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("example_workspace")]  # one build of the workspace
SLOT = 62
COMMAND_TIMEOUT = 60.0


def _live_sequences() -> list:
    found = [sequence for page in pages() for sequence in sequences(page) if sequence.graph]
    # by graph, so that each graph starts once
    return [pytest.param(s, id=s.name) for s in sorted(found, key=lambda s: (s.graph != "demo", s.graph, s.page))]


def _sourced(workspace: Path, env: dict[str, str]) -> dict[str, str]:
    """``env`` after ``source install/setup.bash`` of ``workspace``, as the reader's shell has it."""
    dumped = subprocess.run(["bash", "-c", "source install/setup.bash && env -0"], cwd=workspace, env=env,
                            capture_output=True, text=True, timeout=60, check=True)
    return dict(entry.split("=", 1) for entry in dumped.stdout.split("\0") if "=" in entry)


@pytest.fixture(scope="module")
def live(tmp_path_factory, example_workspace):
    """Start a graph by name (stopping the one running before): its LiveGraph."""
    root = tmp_path_factory.mktemp("live")
    (root / "home").mkdir()
    (root / "runtime").mkdir(mode=0o700)
    env = reader_environment(root / "home")
    env.update(ROS_DOMAIN_ID=ros_domain_id(SLOT), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               XDG_RUNTIME_DIR=str(root / "runtime"))
    env.pop("ROS_LOCALHOST_ONLY", None)
    env = _sourced(example_workspace, env)
    running: dict[str, LiveGraph] = {}

    def start(name: str) -> LiveGraph:
        if name not in running:
            for graph in running.values():
                graph.stop()
            running.clear()
            running[name] = LiveGraph(name, example_workspace, dict(env), root / name)
        return running[name]

    yield start
    for graph in running.values():
        graph.stop()


def _run(command: Command, env: dict[str, str], cwd: Path) -> tuple[list[str], list[str] | None]:
    """The command's output; with a ``^C`` in what the page shows, the output until the lines before it
    were printed, then SIGINT, and the output after it."""
    before, after = split_at_interrupt(command.expected)
    started = time.monotonic()
    process = subprocess.Popen(["bash", "-c", command.command], cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    lines: queue.SimpleQueue[str | None] = queue.SimpleQueue()

    def pump() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            lines.put(line.rstrip("\n"))
        lines.put(None)

    threading.Thread(target=pump, daemon=True).start()

    def read_until(done, timeout: float) -> list[str]:
        """The lines until ``done(lines)``, the end of the output, or ``timeout`` seconds in all."""
        seen: list[str] = []
        deadline = time.monotonic() + timeout
        while not done(seen):
            try:
                line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                break
            seen.append(line)
        return seen

    try:
        if after is None:
            return read_until(lambda _seen: False, COMMAND_TIMEOUT), None
        shown = read_until(lambda seen: matches(before, seen), COMMAND_TIMEOUT)
        time.sleep(max(0.0, started + command.interrupt_after - time.monotonic()))
        os.killpg(process.pid, signal.SIGINT)  # the reader's Ctrl+C, to the command's process group
        return shown, read_until(lambda _seen: False, COMMAND_TIMEOUT)
    finally:
        if process.poll() is None:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


@pytest.mark.parametrize("sequence", _live_sequences())
def test_the_live_examples_print_what_the_page_shows(sequence: Sequence, live, example_workspace: Path,
                                                     tmp_path: Path) -> None:
    graph = live(sequence.graph)
    directory = tmp_path / "example"
    shutil.copytree(REPO / sequence.directory, directory, symlinks=True,
                    ignore=shutil.ignore_patterns("build", "install", "log", "__pycache__"))
    if sequence.directory == "workspaces/example":
        (directory / "install").symlink_to(example_workspace / "install")  # built once, shared, read only
    for name, text in sequence.files.items():
        (directory / name).write_text(text)
    for command in sequence.commands:
        shown, after = _run(command, graph.env, directory)
        before, expected_after = split_at_interrupt(command.expected)
        printed = "\n".join(shown + (["^C", *after] if after is not None else []))
        # what the command printed while Ctrl+C was on its way is left out: the lines after ^C end its output
        assert matches(before, shown) and (after is None or matches(["...", *(expected_after or [])], after)), (
            f"{sequence.page}:{command.line}: $ {command.command}\n--- the page shows:\n"
            + "\n".join(command.expected) + "\n--- roc printed:\n" + printed)
