"""Fast unit tests of the cluster's pieces that need no server: the address setting, toolchain
differences, the files a task carries, the work root's folders, and how the engine, the console and
the build board show work done on a worker."""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
import tarfile
import threading

import pytest

from roc.cluster.files import pack_files, unpack_files
from roc.cluster.settings import cluster_address
from roc.cluster.toolchain import differences, fingerprint
from roc.cluster.workroot import WorkRoot
from roc.engine.events import RunFinished, TaskFinished, TaskStarted
from roc.engine.executor import execute
from roc.engine.process import RanElsewhere
from roc.engine.ready import Task
from roc.errors import UsageError
from roc.handlers.board import TaskBoard
from roc.handlers.console import ConsoleHandler


def _address(value, env_value=None, remote="a remote cache", monkeypatch=None):
    if monkeypatch is not None:
        if env_value is None:
            monkeypatch.delenv("ROC_CLUSTER", raising=False)
        else:
            monkeypatch.setenv("ROC_CLUSTER", env_value)
    return cluster_address(argparse.Namespace(cluster=value, configuration=None), remote)


@pytest.mark.parametrize("given, address", [
    ("tcp://build:8786", "tcp://build:8786"), ("build-scheduler", "tcp://build-scheduler:8786"),
    ("tls://10.0.0.5:9000", "tls://10.0.0.5:9000"), ("build:1234/", "tcp://build:1234"),
])
def test_cluster_addresses(given, address, monkeypatch):
    assert _address(given, monkeypatch=monkeypatch) == address


def test_cluster_address_errors_and_sources(monkeypatch):
    with pytest.raises(UsageError, match="'http://x:1' is not a Dask scheduler address"):
        _address("http://x:1", monkeypatch=monkeypatch)
    with pytest.raises(UsageError, match="--cluster needs a remote cache"):
        _address("tcp://x:1", remote=None, monkeypatch=monkeypatch)
    assert _address(None, monkeypatch=monkeypatch) is None
    assert _address(None, "tcp://from-env:1", monkeypatch=monkeypatch) == "tcp://from-env:1"
    assert _address("tcp://given:2", "tcp://from-env:1", monkeypatch=monkeypatch) == "tcp://given:2"


def test_the_environment_wins_over_roc_toml(monkeypatch):
    class FromFile:
        def from_configuration(self, args, dest):
            return dest == "cluster"

    args = argparse.Namespace(cluster="tcp://from-roc-toml:1", configuration=FromFile())
    monkeypatch.setenv("ROC_CLUSTER", "tcp://from-env:1")
    assert cluster_address(args, "a remote cache") == "tcp://from-env:1"
    monkeypatch.delenv("ROC_CLUSTER")
    assert cluster_address(args, "a remote cache") == "tcp://from-roc-toml:1"


def test_toolchain_differences_name_the_parts():
    mine = {"toolchain": {"tool c++": "a", "variable CFLAGS": None}, "platform": {"machine": "x86_64"}}
    theirs = {"toolchain": {"tool c++": "b", "variable CFLAGS": None}, "platform": {"machine": "aarch64"}}
    assert differences(mine, theirs) == ["platform: machine", "toolchain: tool c++"]


def test_toolchain_fingerprint_follows_build_variables(tmp_path):
    env = {"PATH": "/usr/bin:/bin"}
    assert fingerprint(env, tmp_path) == fingerprint(dict(env), tmp_path)
    assert fingerprint({**env, "CFLAGS": "-O1"}, tmp_path) != fingerprint(env, tmp_path)


def test_files_keep_content_and_modes_and_refuse_escapes(tmp_path):
    source = tmp_path / "src"
    (source / "sub").mkdir(parents=True)
    (source / "sub" / "run.sh").write_text("#!/bin/sh\n")
    (source / "sub" / "run.sh").chmod(0o755)
    (source / "data.txt").write_text("data")
    (source / "left out").write_text("not listed")
    unpacked = unpack_files(pack_files(source, ["data.txt", "sub/run.sh"]), tmp_path / "out")
    assert sorted(unpacked) == ["data.txt", "sub/run.sh"]
    assert (tmp_path / "out" / "data.txt").read_text() == "data"
    assert (tmp_path / "out" / "sub" / "run.sh").stat().st_mode & 0o100
    assert not (tmp_path / "out" / "left out").exists()
    evil = io.BytesIO()
    with tarfile.open(fileobj=evil, mode="w:gz") as tar:
        info = tarfile.TarInfo("../escaped")
        tar.addfile(info, io.BytesIO(b""))
    with pytest.raises(tarfile.TarError):
        unpack_files(evil.getvalue(), tmp_path / "evil")
    assert not (tmp_path / "escaped").exists()


def test_work_root_slots_are_kept_locked_and_recovered(tmp_path):
    root = WorkRoot(tmp_path / "root")
    with root.slot("a") as first:
        with root.slot("b") as second:
            assert first != second  # one workspace per task at once
        (first / "install" / "a").mkdir(parents=True)
        (first / "install" / "kept").mkdir()
    with root.slot("c") as again:
        assert again == first and (again / "install" / "a").is_dir()  # kept from task to task
    # a task that died with its worker: its commands still run in the slot, its package half made
    (first / "build" / "d").mkdir(parents=True)
    (first / ".roc-busy").write_text("d")
    leftover = subprocess.Popen(["sleep", "60"], cwd=first / "build" / "d")
    try:
        with root.slot("e") as recovered:
            assert recovered == first
            leftover.wait(timeout=10)  # killed (it would sleep 60 s): TimeoutExpired otherwise
            assert not (first / "build" / "d").exists() and (first / "install" / "kept").is_dir()
    finally:
        if leftover.poll() is None:
            leftover.kill()
            leftover.wait()


def test_work_elsewhere_finishes_with_its_worker_and_duration():
    seen = []
    result = execute([Task("pkg", set(), lambda context: RanElsewhere("worker-2", 12.3))], [seen.append], 1)
    assert result.ok
    finished = next(e for e in seen if isinstance(e, TaskFinished))
    assert (finished.worker, finished.duration) == ("worker-2", 12.3)


def test_the_limit_may_change_while_running():
    """A function as the limit is asked again before each dispatch (a cluster whose workers come and go)."""
    limit, running, most = [1], [0], [0]
    lock = threading.Lock()

    def action(context):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        limit[0] = 3
        threading.Event().wait(0.3)
        with lock:
            running[0] -= 1

    tasks = [Task(name, set(), action) for name in ("a", "b", "c", "d")]
    assert execute(tasks, [], lambda: limit[0]).ok
    assert most[0] == 3


def test_the_cluster_gets_as_many_packages_at_once_as_its_workers_build(monkeypatch):
    """Dask gives a task to a worker as it is submitted, so one beyond the workers' slots would wait in a
    worker's queue, where a package of the longest chain ready later waited behind a long build while
    the other worker was free: the engine's limit is the fitting workers' slots (two while there is one
    or none: nothing can wait behind another worker), and besides them the tasks working on the
    client, at most --parallel-workers of those. No scheduler here: Cluster's arithmetic on the
    workers it is told of."""
    from roc.cluster.client import Cluster

    cluster = Cluster.__new__(Cluster)
    cluster._capacity, cluster._asked, cluster.lost = 0, 0.0, False
    cluster._here, cluster._here_lock = 0, threading.Lock()
    workers: dict[str, float] = {}
    monkeypatch.setattr(cluster, "fitting", lambda: workers)
    assert cluster.limit(8) == 2  # no worker yet (or one slot): the next package waits ahead
    workers.update({"worker-0": 1.0, "worker-1": 2.0})
    cluster._asked = -1.0  # ask the scheduler again
    assert cluster.limit(8) == 3
    with cluster.here(), cluster.here():
        assert [cluster.limit(local) for local in (1, 8)] == [4, 5]
    assert cluster.limit(8) == 3


def test_console_and_board_show_the_worker():
    out = io.StringIO()
    console = ConsoleHandler(out, status=None)
    for event in (TaskStarted("a"), TaskFinished("a", duration=12.3, worker="worker-2"),
                  TaskFinished("b", duration=1.0), TaskFinished("c", cached=True), RunFinished("")):
        console(event)
    text = out.getvalue()
    assert "Finished <<< a [12.3s on worker-2]" in text and "Finished <<< b [1.00s]" in text
    assert "(1 built here, 1 on the cluster, 1 up to date)" in text


def test_board_step_names_the_worker():
    from roc.engine.events import TaskQueued

    board = TaskBoard()
    board(TaskQueued("a"))
    board(TaskFinished("a", duration=2.0, worker="worker-1"))
    assert board.rows()[0].step == "on worker-1"


def test_commands_without_cluster_never_load_dask(tmp_path):
    (tmp_path / "src" / "p").mkdir(parents=True)
    (tmp_path / "src" / "p" / "CMakeLists.txt").write_text("project(p)\n")
    code = ("import sys; from roc.cli.main import main; main(sys.argv[1:]); "
            "print('LOADED' if 'distributed' in sys.modules or 'dask' in sys.modules else 'CLEAN')")
    for argv in (["work", "list"], ["work", "build", "--explain", "--cluster", "tcp://127.0.0.1:1",
                                    "--remote-cache", "http://127.0.0.1:1/x"]):
        ran = subprocess.run([sys.executable, "-c", code, *argv], cwd=tmp_path, capture_output=True, text=True,
                             timeout=60)
        assert ran.stdout.strip().endswith("CLEAN"), ran.stdout + ran.stderr
