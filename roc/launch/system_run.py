"""``roc launch NAME``: a system of roc.toml started by roc's engine (roc/launch/plan.py) and then
supervised (roc/launch/supervisor.py) until Ctrl+C, SIGTERM or a closed terminal, or until every process
has ended. Exit code: 0 when stopped or when every process ended cleanly; 1 when a condition was not met
or a process failed (and has no ``respawn``)."""

from __future__ import annotations

import threading

from roc.engine.events import Event, TaskFailed, TaskFinished, TaskSkipped
from roc.launch.plan import PROCESS, LazySession, plan
from roc.launch.running import Running, RunOptions
from roc.launch.status import SupervisorControl, serve
from roc.launch.supervisor import Supervisor, command
from roc.launch.system import System
from roc.launch.warm_start import WarmStart


def _start_up_notes(running: Running, system: System):
    """The engine's events during start-up, as lines of the run's output."""
    note = running.monitor.note

    def handler(event: Event) -> None:
        if event.kind == PROCESS:
            if isinstance(event, TaskFailed):
                note(f"[ERROR] [{event.task}]: not started: {event.reason}")
            elif isinstance(event, TaskSkipped):
                note(f"[ERROR] [{event.task}]: not started: it waits for '{event.because_of.split(':', 1)[1]}', "
                     "which was not met")
        elif isinstance(event, TaskFinished):
            note(f"[INFO] [roc]: {event.task}: met after {event.duration:.1f} s")
        elif isinstance(event, TaskFailed) and not running.stopping.is_set():
            note(f"[ERROR] [roc]: {event.task}: not met within {system.timeout:g} s: {event.reason}")

    return handler


def _warm_start(system: System, running: Running) -> WarmStart:
    """The fork servers for the system's Python processes, started before anything else (see
    roc/launch/warm_start.py)."""
    from roc.errors import RocError

    starts = []
    for spec in system.processes:
        try:
            if spec.warm_start and not spec.host:
                starts.append((command(spec), running.environment(spec.env), spec.respawn))
        except RocError:
            continue  # reported when the process is due to start
    warm = WarmStart()
    warm.prepare(starts)
    for pid in warm.pids:
        running.guard.record(pid)
    return warm


def launch_system(system: System, options: RunOptions, use_daemon: bool, spin_time: float | None) -> int:
    from roc.engine.executor import execute

    running = Running(options, echo=True)
    supervisor = Supervisor(running.monitor, running.environment, running.guard.record)
    supervisor.hosts, supervisor.token = system.hosts, running.guard.token
    for spec in system.remote():
        running.monitor.place(spec.label, spec.host)
    session = LazySession(use_daemon, spin_time)
    status = serve(running, SupervisorControl(supervisor, system))  # roc tui's view of the run
    settled = threading.Event()
    ok = False
    try:
        tasks = plan(system, supervisor.start, session, running.stopping.is_set)
        running.catch_signals(stop=lambda: None)  # the engine, then supervisor.wait, see running.stopping
        if options.warm_start:  # after catch_signals: the servers must not inherit an ignored SIGINT
            supervisor.warm = _warm_start(system, running)
        running.start_check(settled, request_stop=lambda: None)
        if running.log_directory is not None:
            running.monitor.note(f"[INFO] [launch]: All log files can be found below {running.log_directory}")
        for spec in system.processes:
            if spec.after:
                running.monitor.waiting(spec.label, ", ".join(condition.text for condition in spec.after))
        result = execute(tasks, [_start_up_notes(running, system)], workers=0, continue_on_error=True, kind="process")
        session.close()
        if result.interrupted:
            running.stopping.set()
        ok = result.ok or running.stopping.is_set()
        if result.ok and not running.stopping.is_set():
            settled.set()
            supervisor.wait(running.stopping)
    finally:
        if status is not None:
            status.close()
        settled.set()
        running.stopping.set()
        supervisor.stop()
        if supervisor.warm is not None:
            supervisor.warm.close()
        running.close()
    return running.exit_code(0 if ok and not supervisor.failed else 1)
