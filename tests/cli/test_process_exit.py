"""How roc's process ends (roc.cli.process_exit): what Python's exit does for the program still happens,
and the interpreter's teardown (the middleware's with it) is skipped unless a participant is still open."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from helpers.graph import graph_env

SLOT = 68

PROGRAM = """
import atexit, sys, threading, time
from pathlib import Path
from roc.cli.process_exit import finish

out = Path(sys.argv[1])
if sys.argv[2] != "none":  # none: a command that never reached the graph (roc.ros.graph never loaded)
    from roc.ros.graph import Graph

    graph = Graph()
    if sys.argv[2] == "closed":
        graph.close()
    else:  # still open when the process ends: Python's exit closes it, in an atexit callback
        atexit.register(graph.close)
atexit.register(lambda: (out / "atexit").write_text("ran"))
threading.Thread(target=lambda: (time.sleep(0.3), (out / "thread").write_text("ran"))).start()
sys.stdout.write("buffered, no newline")
try:
    finish(3)
except SystemExit:
    sys.stdout.write("; Python's exit")
    raise
"""


@pytest.mark.parametrize("graph, python_exit", [
    pytest.param("closed", False, marks=pytest.mark.slow),  # ROS participants (the quick loop stays under 45 s)
    pytest.param("open", True, marks=pytest.mark.slow),
    ("none", False),
])
def test_the_process_ends_as_python_would_and_skips_the_teardown_unless_a_graph_is_open(
        tmp_path: Path, graph: str, python_exit: bool) -> None:
    done = subprocess.run([sys.executable, "-c", PROGRAM, str(tmp_path), graph], env=graph_env(SLOT, tmp_path),
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 3, done.stderr
    assert done.stdout == "buffered, no newline" + ("; Python's exit" if python_exit else "")
    assert (tmp_path / "atexit").read_text() == (tmp_path / "thread").read_text() == "ran"
