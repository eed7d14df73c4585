"""The client's side of a cluster run: the connection to the Dask scheduler, how many packages its
fitting workers take at once, and one package's work as a Dask task, waited for in an engine task's
thread and cancelled with it.

Dask does the distributing: the task asks for one ``roc-build`` unit and the client's toolchain
resource, so only a worker with the client's toolchain gets it; a worker that dies while building is
replaced by another (Dask reschedules the task, up to its ``allowed-failures``); two clients needing
the same package share one task, named by the package's remote key.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from roc.cluster.spec import PackageWork, WorkResult
from roc.cluster.toolchain import BUILD_RESOURCE, RESOURCE_PREFIX, resource_name
from roc.engine.events import TaskWarning
from roc.engine.process import TaskCancelled, TaskContext, TaskError
from roc.errors import RocError

POLL_SECONDS = 0.25
CAPACITY_SECONDS = 1.0  # how long the workers' count is taken as still true


def _quiet_dask_logging() -> None:
    """Dask's own log lines (a lost connection, a retry) would break roc's console: roc says what
    matters in its own words."""
    for name in [n for n in logging.root.manager.loggerDict if n.split(".")[0] in ("distributed", "dask")]:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


def connect(address: str, install_base: Path) -> Cluster:
    """Connect to the scheduler and check that a worker fits this workspace's toolchain: a RocError
    (one line) before anything is built; a note on stderr when the cluster has no worker yet."""
    import importlib.util

    from roc.cluster.toolchain import client_fingerprint
    from roc.errors import UsageError
    from roc.messages import warn

    if importlib.util.find_spec("distributed") is None:
        raise UsageError("--cluster needs Dask's distributed: pip install 'roc[cluster]' (or distributed) into "
                         "roc's environment")
    digest, parts = client_fingerprint(install_base)
    cluster = Cluster(address, digest, parts)
    try:
        note = cluster.check_fits()
    except BaseException:
        cluster.close()
        raise
    if note:
        warn(note)
    return cluster


class Cluster:
    """One run's connection to a scheduler, for a client with toolchain fingerprint ``toolchain`` (made of
    ``toolchain_parts``)."""

    def __init__(self, address: str, toolchain: str, toolchain_parts: dict | None = None):
        import distributed

        _quiet_dask_logging()
        self.address, self.toolchain, self.toolchain_parts = address, toolchain, toolchain_parts or {}
        security = distributed.security.Security()  # Dask's own settings (its configuration files, DASK_* variables)
        if address.startswith("tls://") and not (getattr(security, "tls_ca_file", None)
                                                    and getattr(security, "tls_client_cert", None)):
            raise RocError(f"cannot reach the Dask scheduler at {address}: tls:// needs Dask's TLS settings for "
                           "a client (distributed.comm.tls.ca-file, client.cert and client.key, e.g. "
                           "$DASK_DISTRIBUTED__COMM__TLS__CA_FILE; see docs/cluster.md)")
        try:
            self.client = distributed.Client(address, set_as_default=False, security=security)
        except (OSError, TimeoutError, ValueError, TypeError) as error:
            reason = str(error).splitlines()[0] if str(error) else type(error).__name__
            raise RocError(f"cannot reach the Dask scheduler at {address}: {reason}") from None
        _quiet_dask_logging()
        self._capacity, self._asked = 0, 0.0
        self._here, self._here_lock = 0, threading.Lock()
        self.lost = False
        self._names: dict[str, str] = {}  # worker address -> name, as last asked
        self._lost_workers: dict[str, str] = {}  # task key -> the name of the worker lost while running it
        self.client.subscribe_topic("all", self._on_scheduler_event)

    def _on_scheduler_event(self, event: tuple[float, object]) -> None:
        """The scheduler's events (in Dask's event loop): a worker removed while it ran tasks, which Dask
        gives to other workers; ``run`` says so for each of this client's tasks."""
        message = event[1]
        if isinstance(message, dict) and message.get("action") == "remove-worker":
            address = str(message.get("worker", ""))
            for key in message.get("processing-tasks", ()):
                self._lost_workers[str(key)] = self._names.get(address, address)

    def close(self) -> None:
        try:
            self.client.unsubscribe_topic("all")  # else the scheduler logs that it could not send this client's end
            self.client.close(timeout=5)
        except Exception:  # noqa: BLE001 - the scheduler may be gone already; nothing to keep
            pass

    def workers(self) -> dict[str, dict]:
        """The scheduler's workers (address -> its information)."""
        try:
            workers = dict(self.client.scheduler_info()["workers"])
        except (OSError, TimeoutError) as error:
            self.lost = True
            raise RocError(f"lost the Dask scheduler at {self.address}: {error}") from None
        self._names.update({address: str(info.get("name", address)) for address, info in workers.items()})
        return workers

    def fitting(self) -> dict[str, float]:
        """The workers with this client's toolchain: name -> the packages it builds at once."""
        wanted = resource_name(self.toolchain)
        return {str(info.get("name", address)): float(info.get("resources", {}).get(BUILD_RESOURCE, 0))
                for address, info in self.workers().items() if info.get("resources", {}).get(wanted)}

    def check_fits(self) -> str | None:
        """A RocError when the cluster has workers and none has this toolchain; a note when it has no
        worker yet (tasks then wait for one), else None."""
        workers = self.workers()
        if not workers:
            return f"the cluster at {self.address} has no worker yet: its tasks wait for one"
        if self.fitting():
            return None
        theirs: dict[str, list[str]] = {}
        for address, info in workers.items():
            found = [r.removeprefix(RESOURCE_PREFIX) for r in info.get("resources", {})
                     if r.startswith(RESOURCE_PREFIX)]
            theirs.setdefault(found[0] if found else "not a roc worker", []).append(str(info.get("name", address)))
        listed = "; ".join(f"{digest}: {', '.join(sorted(names))}" for digest, names in sorted(theirs.items()))
        raise RocError(f"no worker of the cluster at {self.address} has this toolchain ({self.toolchain}); "
                       f"its workers have {listed} (start workers with the same compilers, build variables and "
                       "underlays: see docs/cluster.md)")

    def capacity(self) -> int:
        """How many packages the fitting workers build at once (asked at most once a second)."""
        now = time.monotonic()
        if now - self._asked >= CAPACITY_SECONDS and not self.lost:
            self._asked = now
            try:
                self._capacity = int(sum(self.fitting().values()))
            except RocError:
                pass  # the tasks that wait say so
        return self._capacity

    def task_limit(self, local: int) -> int | Callable[[], int]:
        """The engine's limit of tasks at once (roc.engine.executor.execute's ``workers``): what the fitting
        workers build at once (two while they build one or none: see ``limit``), and the tasks working
        on the client (``here``), at most ``local`` of those (--parallel-workers; 0: no limit). Dask gives
        a task to a worker as it is submitted, so a task submitted beyond the workers' slots waits in one
        worker's queue: a package of the longest chain, ready a moment later, waited there behind a long
        build while the other worker was free. Within the limit, what waits stays in roc's ready queue,
        the longest chain first, and a task keeps its slot while its result is restored here (well under
        a second), so a package that becomes ready then takes the worker its dependency freed."""
        return local if not local else lambda: self.limit(local)

    def limit(self, local: int) -> int:
        """``task_limit``'s value now. A cluster of one build slot gets its next package ahead, waiting on
        that worker while a result travels: there is no other worker it could wait behind."""
        slots = self.capacity()
        return (2 if slots <= 1 else slots) + min(self._here, local)

    @contextlib.contextmanager
    def here(self) -> Iterator[None]:
        """While a task of this run works on the client (a package built or tested here, roc.cluster.
        remote_build and remote_test): it takes none of the workers' slots (``limit``)."""
        with self._here_lock:
            self._here += 1
        try:
            yield
        finally:
            with self._here_lock:
                self._here -= 1

    def run(self, function: Callable[[PackageWork], WorkResult], work: PackageWork, key: str,
            context: TaskContext) -> WorkResult:
        """Run ``function(work)`` as the Dask task ``key`` and wait for its result; Ctrl+C or another
        task's failure (``context`` cancelled) cancels it."""
        from concurrent.futures import CancelledError
        from concurrent.futures import TimeoutError as FutureTimeout

        resources = {BUILD_RESOURCE: 1, resource_name(self.toolchain): 1}
        future = self.client.submit(function, work, key=key, resources=resources, pure=False,
                                    priority=context.priority)
        while True:
            lost_on = self._lost_workers.pop(key, None)
            if lost_on is not None:
                context.emit(TaskWarning(context.name, context.kind, message=f"worker {lost_on} was lost while it ran "
                                         f"this {context.kind}; the cluster runs it again"))
            try:
                result = future.result(timeout=POLL_SECONDS)
            except FutureTimeout:
                if context.cancelled:
                    self.client.cancel([future])
                    raise TaskCancelled from None
                if self.client.status not in ("running", "connecting"):
                    self.lost = True
                    raise TaskError(f"lost the Dask scheduler at {self.address}") from None
                continue
            except CancelledError:
                if context.cancelled:
                    raise TaskCancelled from None
                self.lost = True
                raise TaskError(f"lost the Dask scheduler at {self.address}") from None
            except Exception as error:  # noqa: BLE001 - Dask's errors: KilledWorker, a lost connection
                raise TaskError(_dask_failure(error)) from None
            if not isinstance(result, WorkResult):
                raise TaskError(f"the cluster's task returned {type(result).__name__}, not a roc result: "
                                "do the workers run this version of roc?")
            return result


class OnDemand:
    """A run's Cluster, connected when first needed (``get``): a build whose packages the remote cache has
    restores them without the scheduler. A connection that failed fails each task that needs it, with
    its reason."""

    def __init__(self, connect: Callable[[], Cluster]):
        self._connect, self._lock = connect, threading.Lock()
        self._cluster: Cluster | None = None
        self._failed: str | None = None

    def connect(self) -> Cluster:
        """The Cluster, connected now if it is not yet (connect's RocError when it cannot be)."""
        with self._lock:
            if self._cluster is None:
                if self._failed is not None:
                    raise RocError(self._failed)
                try:
                    self._cluster = self._connect()
                except RocError as error:
                    self._failed = str(error)
                    raise
            return self._cluster

    def get(self) -> Cluster:
        """``connect`` for a task's action: its failure is the task's."""
        try:
            return self.connect()
        except RocError as error:
            raise TaskError(str(error)) from None

    def task_limit(self, local: int) -> int | Callable[[], int]:
        """Cluster.task_limit once connected; ``local`` until then."""
        return local if not local else lambda: self._cluster.limit(local) if self._cluster is not None else local

    def here(self) -> contextlib.AbstractContextManager:
        """Cluster.here once connected; nothing to count until then (the limit is ``local``)."""
        return self._cluster.here() if self._cluster is not None else contextlib.nullcontext()

    def close(self) -> None:
        if self._cluster is not None:
            self._cluster.close()


def _dask_failure(error: Exception) -> str:
    name = type(error).__name__
    if name == "KilledWorker":
        return "every worker that took it died (Dask gave up after its allowed failures)"
    text = str(error).splitlines()[0] if str(error) else ""
    return f"the cluster failed it: {name}{': ' + text if text else ''}"
