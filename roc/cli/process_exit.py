"""How roc's process ends once its command is done.

Python's own exit, once rclpy is loaded, runs the middleware's teardown: the destructor of Fast DDS's
DomainParticipantFactory (2.14 and 3.x alike) sleeps 100 ms before it stops its log thread, and
unloading rclpy's modules takes some 60 ms more, a sixth of a first query's time. When every participant
roc made is closed (roc.ros.graph: a Graph's close deletes its participant, telling the others it left),
nothing of that teardown matters outside the process, so roc does what Python's exit does for the program
(non-daemon threads joined, atexit callbacks such as logging's flush and temporary directories'
finalizers, standard streams flushed) and ends the process at once. So it ends a command that never
reached the graph: the interpreter's finalization (every module freed) costs a listing of 1000 packages
or a no-op build some 4 to 8 ms, and changes nothing outside the process, since roc closes what it
writes. Only a graph still open leaves the process to Python's exit, whose atexit callbacks close it.
"""

from __future__ import annotations

import os
import sys

TYPE_CHECKING = False  # typing costs every command's start-up
if TYPE_CHECKING:
    from typing import NoReturn


def finish(code: int) -> NoReturn:
    """End this process with exit code ``code``."""
    graph = sys.modules.get("roc.ros.graph")  # loaded only by commands that reached the ROS graph
    if graph is not None and not graph.every_graph_closed():
        sys.exit(code)
    import atexit

    threading = sys.modules.get("threading")  # never imported: no thread but this one
    if threading is not None:
        for thread in threading.enumerate():
            if thread is not threading.main_thread() and not thread.daemon:
                thread.join()
    atexit._run_exitfuncs()  # CPython's own step of its exit: the callbacks registered with atexit
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a reader gone, or a stream closed: nothing more can reach it
            pass
    os._exit(code)
