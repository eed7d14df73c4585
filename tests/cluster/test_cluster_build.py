"""``roc work build --cluster`` and ``roc work test --cluster`` end to end, on real servers on localhost:
a Dask scheduler, two roc workers whose roots are at different paths (one started by ``roc work
worker``, one by Dask's own ``dask worker --preload roc.cluster.worker``), and the WebDAV store of the
remote cache tests. The workspace is a diamond (dia_a; dia_b and dia_c on it; dia_d on both) with C++
and Python packages (workspaces/fixtures/cluster_diamond).
"""

from __future__ import annotations

import contextlib
import json
import re
import shutil
import signal
import subprocess
import time
from collections.abc import Iterator

import psutil
import pytest
from helpers.build import (
    BIN,
    FIXTURES,
    add_cmake_package,
    in_sourced_shell,
    installed_files,
    roc,
    ros_env,
    without_suite_compiler_cache,
)
from helpers.cluster import (
    _wait,
    building,
    dask_cluster,
    kill_processes,
    scheduler_workers,
    sitecustomize_audit,
    start_scheduler,
    start_worker,
    stop_all,
    tls_client_environment,
    tls_files,
    wait_for_workers,
    worker_process,
)
from helpers.remote_servers import free_port, webdav

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("cluster")]  # one worker: one cluster for the module

PACKAGES = {"dia_a", "dia_b", "dia_c", "dia_d"}
RUN_ALL = "dia_a_hello; dia_b_app; install/dia_c/lib/dia_c/dia_c_hello; dia_d_app"
PROGRAMS_SAY = ("dia_a says 42", "dia_b uses dia_a: 42", "dia_c doubles 21: 42", "dia_d on top: 43")


def _checkout(base, name):
    """Sources only, as a fresh clone has them."""
    ws = base / name
    shutil.copytree(FIXTURES / "cluster_diamond" / "src", ws / "src")
    return ws


def _events(ws, verb="build") -> list[dict]:
    return [json.loads(line) for line in (ws / "log" / f"latest_{verb}" / "events.log").read_text().splitlines()]


def _finished_on(ws, verb="build") -> dict[str, str]:
    return {e["task"]: e["worker"] for e in _events(ws, verb) if e["event"] == "TaskFinished" and e["worker"]}


@pytest.fixture(scope="module")
def dav(tmp_path_factory):
    """The remote cache's WebDAV store, shared by the module: its URL."""
    root = tmp_path_factory.mktemp("dav")
    with webdav(root) as port:
        yield f"http://127.0.0.1:{port}/diamond"


@pytest.fixture(scope="module")
def servers(dav, tmp_path_factory):
    """The Dask cluster, shared by the module: (scheduler address, cache URL, environment, worker
    processes by name, worker roots by name)."""
    base = tmp_path_factory.mktemp("servers")
    # no suite-wide ccache: its base directory would make the header paths compiled into programs relative
    env = without_suite_compiler_cache(ros_env())
    with dask_cluster(base, env, {"worker-1": "roc", "worker-2": "dask"}) as cluster:
        address, processes, roots = cluster
        yield address, dav, env, processes, roots


def _build(ws, servers, *extra, env=None, timeout=600):
    address, url, base_env, _, _ = servers
    return roc("work", "build", "--cluster", address, "--remote-cache", url, *extra, cwd=ws, env=env or base_env,
               timeout=timeout)


@contextlib.contextmanager
def _building(ws, servers, package: str) -> Iterator[tuple[subprocess.Popen, str]]:
    """A cluster build of ``ws`` in the background, from the moment a worker builds ``package``: the
    client and that worker's name (the client is killed if the test leaves it running)."""
    address, url, env, processes, _ = servers
    client = subprocess.Popen([str(BIN / "roc"), "work", "build", "--cluster", address, "--remote-cache", url],
                              cwd=ws, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        worker = _wait(lambda: next((n for n, p in processes.items() if building(p, f"/build/{package}")), None),
                       f"a worker building {package}", process=client)
        yield client, worker
    finally:
        if client.poll() is None:
            client.kill()
            client.communicate()


@pytest.fixture(scope="module")
def built(servers, tmp_path_factory):
    """A checkout built on the cluster, every process the client started logged (Python's audit hook)."""
    base = tmp_path_factory.mktemp("client")
    ws = _checkout(base, "client checkout")
    audit = base / "started.log"
    audit.touch()
    result = _build(ws, servers, env={**servers[2], **sitecustomize_audit(base / "audit", audit)})
    assert result.returncode == 0, result.stdout + result.stderr
    return ws, result, audit.read_text()


def test_diamond_builds_on_both_workers_and_the_client_runs_no_build_tool(built, servers):
    ws, result, started = built
    on = _finished_on(ws)
    assert set(on) == PACKAGES, result.stdout
    assert on["dia_b"] != on["dia_c"] and set(on.values()) == {"worker-1", "worker-2"}, result.stdout
    for name, worker in on.items():
        assert re.search(rf"^Finished <<< {name} \[[0-9.]+s on {worker}\]$", result.stdout, re.MULTILINE), result.stdout
    assert "(0 built here, 4 on the cluster, 0 up to date)" in result.stdout
    # the client itself started no build tool (no compiler, no cmake, no setup.py); Dask's client asks
    # `uname -p` once, for the versions it compares with the scheduler's
    assert [line for line in started.splitlines() if "'uname', '-p'" not in line] == [], started
    # the workers built in workspaces of their own, at paths the client does not have; both have dia_a
    # (one built it, the other restored it for what it built on it)
    for root in servers[4].values():
        assert list((root / "slots").glob("*/install/dia_a/lib/libdia_a.so")), root


def test_workers_started_either_way_do_not_profile_their_threads(servers):
    import distributed

    with distributed.Client(servers[0], timeout=30, set_as_default=False) as client:
        callbacks = client.run(lambda dask_worker: sorted(dask_worker.periodic_callbacks))
    assert len(callbacks) == 2, callbacks
    for names in callbacks.values():
        assert "heartbeat" in names and "profile" not in names and "profile-cycle" not in names, names


def test_install_tree_equals_a_local_build_and_its_programs_run(built, tmp_path):
    ws, _, _ = built
    local = _checkout(tmp_path, "local")
    here = roc("work", "build", cwd=local)
    assert here.returncode == 0, here.stdout + here.stderr
    remote_files = set(installed_files(ws / "install"))
    assert remote_files == set(installed_files(local / "install"))  # byte-code caches included
    for name in sorted(remote_files):  # text files (scripts, hooks, CMake configs) the same, at each one's path
        mine, theirs = (ws / "install" / name), (local / "install" / name)
        if mine.is_file() and not mine.is_symlink() and b"\0" not in mine.read_bytes()[:8192]:
            a = mine.read_bytes().replace(str(ws).encode(), b"WS")
            b = theirs.read_bytes().replace(str(local).encode(), b"WS")
            assert a == b, f"install/{name} differs from a local build's"
    ran = in_sourced_shell(ws, RUN_ALL)
    assert ran.returncode == 0, ran.stderr
    for said in PROGRAMS_SAY:
        assert said in ran.stdout


def test_a_second_run_and_another_checkout_submit_no_task(built, servers, tmp_path):
    ws, _, _ = built
    again = _build(ws, servers)
    assert again.returncode == 0 and "4 packages up to date" in again.stdout, again.stdout + again.stderr
    other = _checkout(tmp_path / "elsewhere", "checkout")
    restored = _build(other, servers)
    assert restored.returncode == 0, restored.stdout + restored.stderr
    events = _events(other)
    assert not [e for e in events if e["event"] == "TaskStarted"], restored.stdout  # nothing ran, nothing sent
    assert {e["task"] for e in events if e["event"] == "TaskFinished" and e["restored"]} == PACKAGES
    assert " on worker-" not in restored.stdout


def test_a_worker_killed_while_building_is_replaced(servers, built, tmp_path):
    """dia_b's configure is made slow; the worker building it is killed (SIGKILL) and Dask runs the task
    again on a worker: the build succeeds, and no half-written cache entry is ever restored."""
    ws, _, _ = built
    killed = _checkout(tmp_path, "killed")
    cmakelists = killed / "src" / "dia_b" / "CMakeLists.txt"
    cmakelists.write_text(cmakelists.read_text().replace(
        "find_package(dia_a REQUIRED)", "find_package(dia_a REQUIRED)\nexecute_process(COMMAND ${CMAKE_COMMAND} -E sleep 4)"))
    address, _, _, processes, _ = servers
    with _building(killed, servers, "dia_b") as (client, victim):
        worker = worker_process(processes[victim])
        below = worker.children(recursive=True)
        worker.kill()
        kill_processes(below)  # the killed worker's commands (a real crash would leave them to finish alone)
        out, err = client.communicate(timeout=600)
    assert client.returncode == 0, out + err
    assert (f"roc: warning: dia_b: worker {victim} was lost while it ran this build; the cluster runs it "
            "again") in err, err
    on = _finished_on(killed)
    assert {"dia_b", "dia_d"} <= set(on), out
    ran = in_sourced_shell(killed, "dia_b_app; dia_d_app")
    assert ran.returncode == 0 and "dia_b uses dia_a: 42" in ran.stdout, ran.stderr
    _wait(lambda: {"worker-1", "worker-2"} <= set(scheduler_workers(address)), "the killed worker back (its nanny)")


def test_a_client_with_another_toolchain_finds_no_worker(servers, tmp_path):
    ws = _checkout(tmp_path, "cflags")
    other = _build(ws, servers, env={**servers[2], "CFLAGS": "-O1"})
    assert other.returncode == 1
    assert other.stderr.count("\n") == 1 and "no worker of the cluster at " in other.stderr, other.stderr
    assert "worker-1" in other.stderr and "Traceback" not in other.stderr
    assert not (ws / "install").exists()


def _package(name: str, depends: tuple[str, ...] = ()) -> dict:
    return {"name": name, "path": f"src/{name}", "type": "ros.cmake", "dependencies": {"build": set(depends)},
            "hooks": [], "metadata": {}, "constraints": {}, "group_depends": [], "member_of_groups": []}


def _run_on(servers, worker: str, task):
    """A task sent straight to one worker (past the resources the client asks for), as another client could."""
    import distributed

    from roc.cluster import work

    with distributed.Client(servers[0], set_as_default=False) as client:
        return client.submit(work.build, task, workers=[worker], pure=False).result(timeout=120)


def test_a_worker_refuses_a_task_of_another_toolchain(servers, built):
    """A task whose toolchain fingerprint is not the worker's is refused: nothing is built."""
    from roc.cluster.spec import PackageWork

    task = PackageWork(package=_package("dia_a"), dependencies=[], key="0" * 64, portable={}, sources=b"",
                       options={}, cache_url=servers[1], cache_timeout=5, toolchain="not-this-one", toolchain_parts={})
    result = _run_on(servers, "worker-2", task)
    assert not result.ok and result.refused and result.worker == "worker-2"
    assert "worker worker-2 refused it: its toolchain differs from the client's" in result.reason


def test_a_dependency_the_cache_lacks_fails_the_package_with_the_reason(servers, built, tmp_path):
    from roc.builder.fingerprint import combine
    from roc.cluster.files import pack_files
    from roc.cluster.spec import PackageWork
    from roc.cluster.toolchain import fingerprint_parts
    from roc.environment import with_implicit_underlay

    parts = fingerprint_parts(with_implicit_underlay(servers[2]), tmp_path)
    source = FIXTURES / "cluster_diamond" / "src" / "dia_b"
    task = PackageWork(package=_package("dia_b", ("dia_a",)), dependencies=[(_package("dia_a"), "f" * 64)],
                       key="1" * 64, portable={}, sources=pack_files(source, ["package.xml", "CMakeLists.txt", "main.cpp"]),
                       options={}, cache_url=servers[1], cache_timeout=5, toolchain=combine(parts)[:16],
                       toolchain_parts=parts)
    result = _run_on(servers, "worker-1", task)
    assert not result.ok and not result.refused, result
    assert result.reason == ("worker worker-1 could not restore the dependency dia_a: not in the remote cache "
                             "(key ffffffffffff)")


def test_cluster_test_results_appear_in_test_result(built, servers):
    ws, _, _ = built
    address, url, env, _, _ = servers
    tested = roc("work", "test", "--cluster", address, "--remote-cache", url, cwd=ws, env=env)
    assert tested.returncode == 0, tested.stdout + tested.stderr
    on = _finished_on(ws, "test")
    assert {"dia_b", "dia_c"} <= set(on), tested.stdout
    assert (ws / "build" / "dia_c" / "pytest.xml").is_file()
    assert (ws / "build" / "dia_b" / "Testing" / "TAG").is_file()
    summary = roc("work", "test-result", "--all", cwd=ws, env=env)
    assert summary.returncode == 0, summary.stdout + summary.stderr
    assert "Summary: 3 tests, 0 errors, 0 failures, 0 skipped" in summary.stdout, summary.stdout
    cached = roc("work", "test", "--cluster", address, "--remote-cache", url, cwd=ws, env=env)
    assert cached.returncode == 0 and " on worker-" not in cached.stdout, cached.stdout


def test_a_build_the_cache_has_is_restored_without_the_scheduler(built, servers, tmp_path):
    """The scheduler is needed only for what the remote cache lacks: with it down, another checkout
    restores every package (Dask's 30 s connect timeout never waited for)."""
    ws = _checkout(tmp_path, "cached")
    address = f"tcp://127.0.0.1:{free_port()}"
    result = roc("work", "build", "--cluster", address, "--remote-cache", servers[1], cwd=ws, env=servers[2])
    assert result.returncode == 0, result.stdout + result.stderr
    assert "(0 built, 4 restored from the remote cache, 0 up to date)" in result.stdout, result.stdout
    assert "Dask" not in result.stderr, result.stderr
    ran = in_sourced_shell(ws, RUN_ALL)
    assert ran.returncode == 0 and all(said in ran.stdout for said in PROGRAMS_SAY), ran.stdout + ran.stderr


def test_no_scheduler_is_one_line_and_nothing_restored(servers, tmp_path):
    """What the cache lacks needs the scheduler: it is asked before anything is restored or built."""
    ws = _checkout(tmp_path, "lonely")
    address = f"tcp://127.0.0.1:{free_port()}"
    start = time.monotonic()
    result = roc("work", "build", "--cluster", address, "--remote-cache", f"{servers[1]}-empty", cwd=ws,
                 env={**servers[2], "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "2s"})
    assert result.returncode == 1 and time.monotonic() - start < 60
    assert result.stderr.startswith(f"roc: error: cannot reach the Dask scheduler at {address}"), result.stderr
    assert result.stderr.count("\n") == 1 and result.stdout == ""
    assert not (ws / "install").exists() and not (ws / "build").exists()


def _data_package(ws, name: str) -> None:
    """A CMake package that compiles nothing: it installs one file (the quickest real build)."""
    add_cmake_package(ws, name, f"cmake_minimum_required(VERSION 3.8)\nproject({name} NONE)\n"
                                f"install(FILES package.xml DESTINATION share/{name})\n")


def test_symlink_install_builds_here_and_says_why(servers, tmp_path):
    ws = tmp_path / "symlinks"
    _data_package(ws, "linked")
    result = _build(ws, servers, "--symlink-install")
    assert result.returncode == 0, result.stdout + result.stderr
    assert ("roc: warning: linked: built here, not on the cluster: --symlink-install installs links into the "
            "sources") in result.stderr
    assert "Finished <<< linked [" in result.stdout and " on worker-" not in result.stdout


def test_a_package_built_without_the_remote_cache_is_tested_here(servers, tmp_path):
    ws = tmp_path / "unkeyed"
    _data_package(ws, "unkeyed")
    assert roc("work", "build", cwd=ws).returncode == 0  # no remote cache: no remote key
    tested = roc("work", "test", "--cluster", servers[0], "--remote-cache", servers[1], cwd=ws, env=servers[2])
    assert tested.returncode == 0, tested.stdout + tested.stderr
    assert ("roc: warning: unkeyed: tested here, not on the cluster: unkeyed has no remote key (build with "
            "--remote-cache or --cluster first)") in tested.stderr
    assert "Finished <<< unkeyed [" in tested.stdout and " on worker-" not in tested.stdout


def test_a_package_bound_to_its_build_path_is_built_here(servers, tmp_path):
    """A package whose installed file holds the absolute path it was built at (a path no rewrite
    knows) cannot be restored at the client's path: built on a worker, then here, saying why."""
    ws = tmp_path / "bound"
    add_cmake_package(ws, "where_am_i", 'cmake_minimum_required(VERSION 3.8)\nproject(where_am_i NONE)\n'
                      'file(WRITE ${CMAKE_BINARY_DIR}/where.txt "${CMAKE_INSTALL_PREFIX}\\n")\n'
                      'install(FILES ${CMAKE_BINARY_DIR}/where.txt DESTINATION share/where_am_i)\n')
    result = _build(ws, servers)
    assert result.returncode == 0, result.stdout + result.stderr
    assert re.search(r"roc: warning: where_am_i: built here, not on the cluster: built on worker-\d, its archive "
                     r"holds the path it was built at \(where_am_i/share/where_am_i/where.txt\)", result.stderr), result.stderr
    assert (ws / "install" / "where_am_i" / "share" / "where_am_i" / "where.txt").read_text() == \
        f"{ws / 'install' / 'where_am_i'}\n"
    assert " on worker-" not in result.stdout


def test_ctrl_c_cancels_the_task_and_the_worker_stops_the_build(servers, tmp_path):
    processes = servers[3]
    ws = _checkout(tmp_path, "interrupted")
    cmakelists = ws / "src" / "dia_a" / "CMakeLists.txt"
    cmakelists.write_text(cmakelists.read_text() + "execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 120)\n")
    with _building(ws, servers, "dia_a") as (client, victim):
        client.send_signal(signal.SIGINT)  # as Ctrl+C
        out, err = client.communicate(timeout=60)
    assert client.returncode == 130, out + err
    assert "Aborted  <<< dia_a" in out and "Traceback" not in err
    _wait(lambda: not building(processes[victim], "/build/dia_a"), "the worker to stop dia_a's build", timeout=30)
    assert psutil.pid_exists(processes[victim].pid)  # the worker itself goes on


def test_a_tls_cluster_builds_and_refuses_a_client_without_its_certificate(dav, tmp_path):
    """Dask's own TLS: the scheduler and the worker take Dask's TLS options, the client Dask's settings
    (here its environment variables); a client without them gets one line."""
    cert, key = tls_files(tmp_path / "tls")
    env = ros_env(**tls_client_environment(cert, key))
    tls = ("--protocol", "tls", "--tls-ca-file", str(cert), "--tls-cert", str(cert), "--tls-key", str(key))
    with dask_cluster(tmp_path / "cluster", env, {"secure-worker": "roc"}, tls, tls) as (address, _, _):
        assert address.startswith("tls://127.0.0.1:")
        ws = tmp_path / "tls"
        _data_package(ws, "secret")
        built = roc("work", "build", "--cluster", address, "--remote-cache", dav, cwd=ws, env=env)
        assert built.returncode == 0, built.stdout + built.stderr
        assert re.search(r"^Finished <<< secret \[[0-9.]+s on secure-worker\]$", built.stdout, re.MULTILINE)
        plain = roc("work", "build", "--cluster", address, "--remote-cache", dav, "--force", cwd=ws, env=ros_env())
    assert plain.returncode == 1, plain.stdout + plain.stderr
    assert plain.stderr.startswith(f"roc: error: cannot reach the Dask scheduler at {address}"), plain.stderr
    assert plain.stderr.count("\n") == 1


def test_a_worker_out_of_disk_fails_the_package_with_the_reason(dav, tmp_path):
    """The only worker's root is on a full file system (a 64 kB tmpfs in a mount namespace of its own):
    the package fails as a local build that ran out of disk does, its output saying "No space left on
    device", with no traceback and nothing restored here."""
    env = ros_env()
    root = tmp_path / "small disk" / "root"
    root.mkdir(parents=True)
    mount = ("unshare", "-m", "--propagation", "private", "sh", "-c",
             'mount -t tmpfs -o size=64k tmpfs "$0" && exec "$@"', str(root))
    if shutil.which("unshare") is None or subprocess.run([*mount, "true"], capture_output=True).returncode:
        pytest.skip("a file system of its own (a tmpfs in a mount namespace) needs root")
    scheduler, address = start_scheduler(tmp_path / "scheduler", env)
    worker = start_worker(address, root, "worker-full", env, prefix=mount)
    try:
        wait_for_workers(address, {"worker-full"}, env, [worker])
        ws = _checkout(tmp_path, "client")
        result = roc("work", "build", "--cluster", address, "--remote-cache", f"{dav}-full", "--packages-select",
                     "dia_a", cwd=ws, env=env, timeout=300)
        output = result.stdout + result.stderr
        assert result.returncode == 1, output
        assert "No space left on device" in output, output
        assert "Traceback" not in output
        assert re.search(r"^Failed   <<< dia_a \[[\d.]+s, CMake configure failed\]$", result.stdout, re.M), output
        assert not (ws / "install" / "dia_a").exists(), "nothing restored of a package that failed"
    finally:
        stop_all([worker, scheduler])


def test_a_worker_stops_its_build_when_its_scheduler_dies(dav, tmp_path):
    """The scheduler killed while a worker builds: the worker stops the build nobody waits for at once
    (it went on for a whole compile, then logged Dask's traceback), and the client says what it lost."""
    env = ros_env()
    scheduler, address = start_scheduler(tmp_path / "scheduler", env)
    root = tmp_path / "host" / "root"
    root.mkdir(parents=True)
    worker = start_worker(address, root, "orphan", env)
    ws = tmp_path / "abandoned"
    add_cmake_package(ws, "slow", "cmake_minimum_required(VERSION 3.8)\nproject(slow NONE)\n"
                      "execute_process(COMMAND ${CMAKE_COMMAND} -E sleep 120)\n")
    client = None
    try:
        wait_for_workers(address, {"orphan"}, env, [worker])
        client = subprocess.Popen([str(BIN / "roc"), "work", "build", "--cluster", address, "--remote-cache",
                                   f"{dav}-abandoned"], cwd=ws, env=env, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)
        _wait(lambda: building(worker, "/build/slow"), "the worker building slow", process=client)
        scheduler.kill()
        _wait(lambda: not building(worker, "/build/slow"), "the worker to stop the build", timeout=30)
        out, err = client.communicate(timeout=120)
        assert client.returncode == 1 and f"lost the Dask scheduler at {address}" in out, out + err
    finally:
        if client is not None and client.poll() is None:
            client.kill()
            client.communicate()
        stop_all([worker, scheduler])
    log = (root.parent / "orphan.log").read_text()
    assert "Traceback" not in log, log
