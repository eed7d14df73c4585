"""roc's guard on another host: the program ``roc launch`` runs there over SSH for each process of a system
with ``host = "DEST"`` (roc/launch/remote.py sends it, with roc/launch/guard.py, through the SSH session's
standard input: nothing of roc is installed there). The standard library only, Python 3.8 or newer.

It sources the host's setup files (in a shell of their kind), finds the package's executable in the
resulting ament index as ``ros2 run`` does, and starts it in a session of its own with the system's ROS
settings, its output going straight into the SSH session. Then it stays tied to that session:

- roc writes a line at least every HEARTBEAT_SECONDS; ``signal N`` passes signal N to the process's group
  (roc's stop rules: SIGINT, then SIGTERM, then SIGKILL);
- the end of its standard input (roc, its ssh client or the connection closed), or SILENCE_SECONDS
  without a byte (roc frozen, its host suspended, the network cut: the connection itself may take hours
  to time out), stops the process, its group, every process carrying its token and their descendants
  (guard.sweep: SIGTERM, repeated, then SIGKILL after GRACE_SECONDS). So a remote process outlives a failure
  by at most SILENCE_SECONDS + GRACE_SECONDS.

What it tells roc goes to its standard error as lines ``roc-remote JSON``: ``started`` (pid, command line),
``usage`` (CPU and memory, each second), ``exited`` (the exit code, negative for a signal, as subprocess
reports it, and why the guard stopped it, if it did), ``error`` (nothing started), or for ``mode: check``
one ``checked`` (the executables' paths, what is missing, the working directory there).
"""

from __future__ import annotations

import json
import os
import select
import shlex
import signal
import subprocess
import sys
import tempfile
import time

from roc.launch.guard import GRACE_SECONDS, TOKEN_VARIABLE, start_time, sweep

HEARTBEAT_SECONDS = 1.0
SILENCE_SECONDS = 5.0
USAGE_SECONDS = 1.0
MARK = "roc-remote "
PACKAGES = os.path.join("share", "ament_index", "resource_index", "packages")
SHELLS = {".zsh": "zsh", ".bash": "bash"}  # any other file is sourced by sh


def report(event: str, **fields) -> None:
    try:
        os.write(2, (MARK + json.dumps({"event": event, **fields}) + "\n").encode())
    except OSError:  # roc is gone: the guard still stops what it started
        pass


def sourced_environment(setup: list[str]) -> tuple[dict[str, str], str]:
    """The environment after sourcing ``setup`` in order (one shell: zsh for a .zsh file, else bash for a
    .bash file, else sh), and an error ("" when none)."""
    if not setup:
        return dict(os.environ), ""
    files = [os.path.expanduser(path) for path in setup]
    for path in files:
        if not os.path.isfile(path):
            return {}, f"setup file {path} does not exist"
    suffixes = {os.path.splitext(path)[1] for path in files}
    shell = next((SHELLS[suffix] for suffix in SHELLS if suffix in suffixes), "sh")
    with tempfile.TemporaryFile() as dump:
        dumper = "import json,os,sys; os.write(int(sys.argv[1]), json.dumps(dict(os.environ)).encode())"
        script = "".join(f". {shlex.quote(path)} || {{ echo 'sourcing {path} failed' >&2; exit 97; }}\n"
                         for path in files)
        script += f"exec {shlex.quote(sys.executable)} -S -c {shlex.quote(dumper)} {dump.fileno()}\n"
        try:
            done = subprocess.run([shell, "-c", script], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, pass_fds=(dump.fileno(),), timeout=60)
        except (OSError, subprocess.TimeoutExpired) as error:
            return {}, f"cannot source {', '.join(files)} with {shell}: {error}"
        if done.returncode != 0:
            lines = done.stdout.decode(errors="replace").strip().splitlines() or [f"exit code {done.returncode}"]
            return {}, f"sourcing {', '.join(files)} failed: {lines[-1]}"
        dump.seek(0)
        return json.loads(dump.read().decode()), ""


def find_executable(env: dict[str, str], package: str, name: str) -> tuple[str, str]:
    """``<prefix>/lib/<package>/.../<name>`` of the first prefix of AMENT_PREFIX_PATH that has the package
    (as ros2 run finds it), and an error ("" when found)."""
    prefixes = [prefix for prefix in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if prefix]
    for prefix in prefixes:
        if os.path.isfile(os.path.join(prefix, PACKAGES, package)):
            found = []
            for directory, subdirectories, files in os.walk(os.path.join(prefix, "lib", package)):
                subdirectories[:] = sorted(d for d in subdirectories if not d.startswith("."))
                found += [os.path.join(directory, f) for f in sorted(files)
                          if os.access(os.path.join(directory, f), os.X_OK)]
            matches = [path for path in found if os.path.basename(path) == name]
            if matches:
                return matches[0], ""
            names = ", ".join(os.path.basename(path) for path in found) or "none"
            return "", f"package '{package}' has no executable '{name}' (its executables: {names})"
    where = os.pathsep.join(prefixes) or "AMENT_PREFIX_PATH is empty"
    return "", f"package '{package}' is not installed ({where})"


def check(spec: dict) -> int:
    """``mode: check``: whether the setup files source and each (package, executable) is there."""
    env, error = sourced_environment(spec["setup"])
    found, missing = {}, []
    if not error:
        for package, name in spec["executables"]:
            path, problem = find_executable(env, package, name)
            if path:
                found[f"{package}/{name}"] = path
            else:
                missing.append(problem)
    report("checked", error=error, found=found, missing=missing, cwd=os.getcwd(), python=sys.version.split()[0])
    return 0


class Usage:
    """The process's CPU (percent of one core since the last report) and resident memory, from /proc."""

    def __init__(self, pid: int):
        self.pid = pid
        self.ticks, self.at = self._ticks(), time.monotonic()

    def _ticks(self) -> int:
        try:
            with open(f"/proc/{self.pid}/stat") as handle:
                fields = handle.read().rsplit(")", 1)[1].split()
            return int(fields[11]) + int(fields[12])
        except (OSError, IndexError, ValueError):
            return 0

    def report(self) -> None:
        ticks, now = self._ticks(), time.monotonic()
        cpu = 100.0 * (ticks - self.ticks) / os.sysconf("SC_CLK_TCK") / max(now - self.at, 1e-3)
        self.ticks, self.at = ticks, now
        try:
            with open(f"/proc/{self.pid}/statm") as handle:
                rss = int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
        except (OSError, IndexError, ValueError):
            rss = 0
        report("usage", cpu=round(cpu, 1), rss=rss)


def _in_child() -> None:
    """In the child before its exec: the signals the guard ignores back to their defaults, and SIGTERM when
    the guard dies, even by SIGKILL (prctl PR_SET_PDEATHSIG, Linux)."""
    for signum in (signal.SIGINT, signal.SIGHUP):
        signal.signal(signum, signal.SIG_DFL)
    try:
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGTERM)
    except (OSError, AttributeError):
        pass


def watch(process: subprocess.Popen) -> str:
    """Until the process ends (""), roc's end of the session closes or roc goes silent (why)."""
    usage = Usage(process.pid)
    last = next_usage = time.monotonic()
    pending = b""
    while process.poll() is None:
        now = time.monotonic()
        if now - last > SILENCE_SECONDS:
            return f"nothing heard from roc for {SILENCE_SECONDS:g} s"
        wait = max(0.0, min(next_usage, last + SILENCE_SECONDS) - now) + 0.01
        readable, _, _ = select.select([0], [], [], min(wait, 0.2))
        if readable:
            data = os.read(0, 4096)
            if not data:
                return "the SSH session closed"
            last = time.monotonic()
            pending += data
            *lines, pending = pending.split(b"\n")
            for line in lines:
                words = line.split()
                if len(words) == 2 and words[0] == b"signal":
                    try:
                        os.killpg(process.pid, int(words[1]))
                    except (OSError, ValueError):
                        pass
        if time.monotonic() >= next_usage:
            usage.report()
            next_usage = time.monotonic() + USAGE_SECONDS
    return ""


def run(spec: dict) -> int:
    """``mode: run``: start the process, relay, stop it when told to or when roc is gone."""
    env, error = sourced_environment(spec["setup"])
    path = ""
    if not error:
        path, error = find_executable(env, spec["package"], spec["executable"])
    if error:
        report("error", message=error)
        return 2
    env.update(spec["env"])
    env[TOKEN_VARIABLE] = spec["token"]
    command = [path, *spec["arguments"]]
    try:
        process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=1, stderr=1, env=env,
                                   start_new_session=True, preexec_fn=_in_child)
    except OSError as failure:
        report("error", message=f"cannot run '{path}': {failure.strerror}")
        return 2
    report("started", pid=process.pid, cmd=command)
    recorded = {process.pid: start_time(process.pid) or 0}
    lost = ""
    try:
        lost = watch(process)
    finally:  # lost, ended, or the guard itself told to stop (SIGTERM)
        try:
            os.killpg(process.pid, signal.SIGTERM)  # at once; the sweep then looks for the rest
        except OSError:
            pass
        sweep(spec["token"], recorded, {process.pid}, GRACE_SECONDS)
    code = process.wait()
    report("exited", code=code, reason=lost)
    return code if code >= 0 else 128 - code


def _stop(signum: int, _frame) -> None:
    raise SystemExit(128 + signum)  # through run's finally: the sweep


def main(spec: dict) -> int:
    signal.signal(signal.SIGPIPE, signal.SIG_IGN)  # a closed session must not kill the guard before its sweep
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _stop)
    return check(spec) if spec["mode"] == "check" else run(spec)
