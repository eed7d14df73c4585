"""A real Dask cluster on localhost for the cluster tests: a scheduler and roc workers, each a process of
its own (a worker is Dask's nanny and its worker process), started and stopped by the tests by PID.

One worker is started by ``roc work worker``, another by Dask's own ``dask worker --preload
roc.cluster.worker``: both ways must give the same worker.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import psutil

from helpers.build import BIN, stop_process

WAIT_SECONDS = 90.0


def _wait(condition, what: str, timeout: float = WAIT_SECONDS, process: subprocess.Popen | None = None):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        if process is not None and process.poll() is not None:
            raise AssertionError(f"{what}: the process exited with {process.returncode}")
        time.sleep(0.1)
    raise AssertionError(f"{what}: not within {timeout:g} s")


def start_scheduler(folder: Path, env: dict[str, str], *extra: str) -> tuple[subprocess.Popen, str]:
    """A scheduler on 127.0.0.1 (a free port): its process and address."""
    folder.mkdir(parents=True, exist_ok=True)
    info = folder / "scheduler.json"
    info.unlink(missing_ok=True)
    with open(folder / "scheduler.log", "ab") as log:
        process = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
             "--no-dashboard", "--scheduler-file", str(info), *extra],
            stdout=log, stderr=log, stdin=subprocess.DEVNULL, env=env)

    def address() -> str | None:
        try:
            return json.loads(info.read_text())["address"]
        except (OSError, ValueError, KeyError):
            return None

    return process, _wait(address, "the Dask scheduler", process=process)


def start_worker(address: str, root: Path, name: str, env: dict[str, str], via: str = "roc",
                 dask_options: tuple[str, ...] = (), prefix: tuple[str, ...] = ()) -> subprocess.Popen:
    """A roc worker (``via`` roc work worker or Dask's dask worker), its logs beside its root; ``prefix``
    runs it through another command (taskset)."""
    options = ["--host", "127.0.0.1", "--no-dashboard", *dask_options]
    if via == "roc":
        command = [str(BIN / "roc"), "work", "worker", address, "--root", str(root), "--name", name, "--dask-options", *options]
    else:
        command = [str(BIN / "dask"), "worker", address, "--preload", "roc.cluster.worker", "--roc-root", str(root),
                   "--name", name, "--nthreads", "1", "--resources", "roc-build=1", *options]
    with open(root.parent / f"{name}.log", "ab") as log:
        return subprocess.Popen([*prefix, *command], stdout=log, stderr=log, stdin=subprocess.DEVNULL, env=env)


def scheduler_workers(address: str, env: dict[str, str] | None = None) -> dict[str, dict]:
    """The scheduler's workers by name: their resources (asked with a Dask client of the test's own)."""
    import distributed

    security = None
    if address.startswith("tls://") and env is not None:
        security = distributed.security.Security(
            tls_ca_file=env["DASK_DISTRIBUTED__COMM__TLS__CA_FILE"],
            tls_client_cert=env["DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT"],
            tls_client_key=env["DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY"], require_encryption=True)
    with distributed.Client(address, timeout=30, set_as_default=False, security=security) as client:
        return {str(info["name"]): info for info in client.scheduler_info()["workers"].values()}


def wait_for_workers(address: str, names: set[str], env: dict[str, str] | None = None,
                     processes: list[subprocess.Popen] = ()) -> None:
    def registered() -> bool:
        for process in processes:
            assert process.poll() is None, f"a worker exited with {process.returncode}"
        found = scheduler_workers(address, env)
        return names <= {name for name, info in found.items() if "roc-build" in info.get("resources", {})}

    _wait(registered, f"workers {sorted(names)}")


def worker_process(nanny: subprocess.Popen) -> psutil.Process:
    """The worker process a ``roc work worker`` or ``dask worker`` started: the nanny's child that
    multiprocessing spawned (not its resource tracker, the other child)."""
    def child():
        children = []
        for process in psutil.Process(nanny.pid).children():
            with contextlib.suppress(psutil.Error):
                if "spawn_main" in " ".join(process.cmdline()):
                    children.append(process)
        return children[0] if children else None

    return _wait(child, "the worker process below the nanny")


def building(nanny: subprocess.Popen, marker: str) -> bool:
    """Whether a command below the worker works on a path holding ``marker`` (a package's build)."""
    with contextlib.suppress(psutil.Error):
        for process in psutil.Process(nanny.pid).children(recursive=True):
            with contextlib.suppress(psutil.Error):
                if marker in " ".join(process.cmdline()) or marker in process.cwd():
                    return True
    return False


def stop_all(processes: list[subprocess.Popen]) -> None:
    """Stop the processes and everything below them (a killed worker's commands included), by PID."""
    below: list[psutil.Process] = []
    for process in processes:
        with contextlib.suppress(psutil.Error):
            below += psutil.Process(process.pid).children(recursive=True)
    for process in processes:
        stop_process(process)
    kill_processes(below)


def kill_processes(processes: list[psutil.Process]) -> None:
    for process in processes:
        with contextlib.suppress(psutil.Error):
            process.kill()
    psutil.wait_procs(processes, timeout=10)


@contextlib.contextmanager
def dask_cluster(folder: Path, env: dict[str, str], workers: dict[str, str],
                 scheduler_options: tuple[str, ...] = (), worker_options: tuple[str, ...] = ()
                 ) -> Iterator[tuple[str, dict[str, subprocess.Popen], dict[str, Path]]]:
    """A scheduler and ``workers`` (name -> roc or dask, each with a root of its own, at different
    paths): yields the address, the workers' processes and their roots."""
    started: list[subprocess.Popen] = []
    try:
        scheduler, address = start_scheduler(folder / "scheduler", env, *scheduler_options)
        started.append(scheduler)
        processes, roots = {}, {}
        for index, (name, via) in enumerate(workers.items()):
            root = folder / f"host-{index}" / "roc work root"  # different paths, one with a space
            root.mkdir(parents=True)
            roots[name] = root
            processes[name] = start_worker(address, root, name, env, via, worker_options)
            started.append(processes[name])
        wait_for_workers(address, set(workers), env, list(processes.values()))
        yield address, processes, roots
    finally:
        stop_all(started[::-1])


def interrupt(process: subprocess.Popen) -> None:
    process.send_signal(signal.SIGINT)


def sitecustomize_audit(folder: Path, log: Path) -> dict[str, str]:
    """The environment that makes every Python process started with it log each process it starts
    (Python's audit events, in a sitecustomize on PYTHONPATH) to ``log``, one line each."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "sitecustomize.py").write_text(f'''
import sys

def _audit(event, args, _log={str(log)!r}):
    if event in ("subprocess.Popen", "os.posix_spawn", "os.exec", "os.system", "os.spawn"):
        with open(_log, "a") as out:
            out.write(f"{{event}} {{args[1] if event != 'os.system' else args[0]!r}}\\n")

sys.addaudithook(_audit)
''')
    return {"PYTHONPATH": os.pathsep.join(p for p in (str(folder), os.environ.get("PYTHONPATH", "")) if p)}


def tls_files(folder: Path) -> tuple[Path, Path]:
    """A self-signed certificate (its own CA) and its key, as Dask's Security.temporary makes them."""
    from distributed.security import Security

    temporary = Security.temporary()
    folder.mkdir(parents=True, exist_ok=True)
    cert, key = folder / "cert.pem", folder / "key.pem"
    cert.write_text(temporary.tls_ca_file)
    key.write_text(temporary.tls_client_key)
    key.chmod(0o600)
    return cert, key


def tls_client_environment(cert: Path, key: Path) -> dict[str, str]:
    """Dask's TLS settings for a client, as environment variables (what the manual tells users)."""
    return {"DASK_DISTRIBUTED__COMM__TLS__CA_FILE": str(cert), "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": str(cert),
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": str(key), "DASK_DISTRIBUTED__COMM__REQUIRE_ENCRYPTION": "True"}
