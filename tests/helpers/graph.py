"""Helpers for the graph tests: test nodes in subprocesses, roc and the real ros2 CLI in one environment."""

from __future__ import annotations

import json
import os
import queue
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

from helpers.build import BIN, DISTRO, REQUIREMENTS, ros_domain_id, stop_process
from helpers.build import roc as roc_build
from helpers.oracles import SHARED, require_oracle
from helpers.rmw import middleware_prefixes, suite_environment
from roc.middleware import process_environment

NODE_SCRIPT = Path(__file__).resolve().parents[1] / "nodes" / "graph_node.py"
# the real ros2 CLI, in a venv of the tests' distribution's wheels (Jazzy's keeps its first name)
ORACLE_VENV = (Path(os.environ.get("ROC_TEST_CACHE", Path.home() / ".cache" / "roc-tests"))
               / ("ros2cli-venv" if DISTRO == "jazzy" else f"ros2cli-venv-{DISTRO}"))
REPO = Path(__file__).resolve().parents[2]

# The demo graph of shared/reference/ros2cli, in three processes.
DEMO_GRAPH = [
    [{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]},
     {"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}],
    [{"name": "odom_pub", "namespace": "/robot1",
      "publishers": [{"topic": "odom", "type": "nav_msgs/msg/Odometry", "reliability": "best_effort", "depth": 5}]},
     {"name": "map_server", "publishers": [{"topic": "map", "type": "nav_msgs/msg/OccupancyGrid",
                                             "durability": "transient_local", "depth": 1}]}],
    [{"name": "motor_controller", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"},
                                               {"name": "~/reset", "type": "std_srvs/srv/Trigger"}],
      "parameters": {"max_speed": 1.5, "robot_name": "demo_bot", "update_rate_hz": 50, "use_encoder": True,
                     "pid_gains": [1.0, 0.1, 0.01], "wheel_names": ["left_wheel", "right_wheel"]}},
     {"name": "fibonacci_server", "actions": [{"name": "fibonacci"}]}],
]


def graph_env(slot: int, runtime_dir: Path, **extra: str) -> dict[str, str]:
    """A private ROS domain (the test file's slot, see helpers.build.ros_domain_id), localhost discovery,
    a private daemon directory and the middleware suite's RMW (helpers.rmw)."""
    env = dict(os.environ)
    env.pop("ROS_LOCALHOST_ONLY", None)
    env.update(ROS_DOMAIN_ID=ros_domain_id(slot), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               XDG_RUNTIME_DIR=str(runtime_dir), AMENT_PREFIX_PATH=os.pathsep.join([*middleware_prefixes(), str(ORACLE_VENV), sys.prefix]),
               PATH=f"{BIN}{os.pathsep}{env.get('PATH', '/usr/bin:/bin')}", **suite_environment())
    env.update(extra)
    return env


def start_nodes(specs: list, env: dict[str, str]) -> list[subprocess.Popen]:
    """One process per entry of ``specs``, on the middleware ``env`` names (as roc run starts a node:
    roc.middleware); returns once each printed "ready"."""
    processes = []
    env = process_environment(env)
    for spec in specs:
        process = subprocess.Popen([sys.executable, str(NODE_SCRIPT), json.dumps(spec)], env=env,
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        processes.append(process)
    for process in processes:
        assert process.stdout.readline().strip() == "ready"
        _lines(process)  # read from now on: a node that prints what it hears never blocks on a full pipe
    return processes


def _lines(process: subprocess.Popen) -> queue.SimpleQueue:
    """The lines of a process's stdout, read by a thread of their own from the first call on."""
    lines = getattr(process, "_roc_lines", None)
    if lines is None:
        lines = process._roc_lines = queue.SimpleQueue()

        def pump() -> None:
            for line in process.stdout:
                lines.put(line)
            lines.put("")
        threading.Thread(target=pump, daemon=True).start()
    return lines


def read_line(process: subprocess.Popen, timeout: float = 20.0) -> str | None:
    """The next line of a process's stdout ("" once it has ended), or None when none came within
    ``timeout`` seconds: a test that waits for output fails instead of hanging. Once used on a process,
    read its stdout only through this."""
    lines = _lines(process)
    try:
        line = lines.get(timeout=max(0.01, timeout))
    except queue.Empty:
        return None
    if line == "":
        lines.put("")  # the end stays the end: the next call returns at once too
    return line


def wait_for(condition, timeout: float = 20.0) -> None:
    """Return once ``condition()`` is true; fail the test when it is not within ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out waiting for the graph"
        time.sleep(0.2)


def threads(process: subprocess.Popen) -> list[tuple[str, Path]]:
    """Each thread of ``process`` (Linux): its name and its /proc task directory."""
    return [(task.joinpath("comm").read_text().strip(), task) for task in Path(f"/proc/{process.pid}/task").iterdir()]


def component_prefix(root: Path) -> Path:
    """An install prefix registering demo_components' two components and rclcpp_components' container
    executable (tests/nodes/container_node.py), as an rclcpp install would."""
    index = root / "share" / "ament_index" / "resource_index"
    for package in ("demo_components", "rclcpp_components", "no_components"):
        (index / "packages").mkdir(parents=True, exist_ok=True)
        (index / "packages" / package).write_text("")
    (index / "rclcpp_components").mkdir(exist_ok=True)
    (index / "rclcpp_components" / "demo_components").write_text(
        "demo_components::Talker;lib/libtalker.so\ndemo_components::Listener;lib/liblistener.so\n")
    container = root / "lib" / "rclcpp_components" / "component_container"
    container.parent.mkdir(parents=True, exist_ok=True)
    container.write_text(f"#!/bin/sh\nexec {sys.executable} {NODE_SCRIPT.with_name('container_node.py')} \"$@\"\n")
    container.chmod(0o755)
    return root


def stop_all(processes: list[subprocess.Popen]) -> None:
    for process in processes:
        stop_process(process)


def roc(*args: str, env: dict[str, str], timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, capture_output=True, text=True, timeout=timeout)


def ros2(*args: str, env: dict[str, str], timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(ORACLE_VENV / "bin" / "ros2"), *args], env=env, capture_output=True, text=True,
                          timeout=timeout)


# The message packages the oracle needs to echo and publish the tests' types, as requirements/ros-DISTRO.txt pins them.
ORACLE_INTERFACES = tuple(f"ros-{DISTRO}-{name}" for name in ("std-msgs", "common-interfaces", "std-srvs", "test-msgs"))


# The oracles' installers take the wheels of the venv's distribution, which an empty venv does not tell
INSTALLER_ENV = {**os.environ, "ROS_WHEELS_DISTRO": DISTRO}


def install_oracle(launch: bool = False) -> str | None:
    """Install the real ros2 CLI and the tests' message packages into the cached venv (with ``launch``, also
    the real launch system and ``ros2 launch``); the reason it failed, or None. One installer at a time
    (pytest-xdist workers share the venv). Each part is marked installed once it is all there (INSTALLED):
    a venv whose ros2 CLI is not marked (an install stopped or failed halfway, which the installer would
    take as done) is made again from nothing."""
    import fcntl

    ORACLE_VENV.parent.mkdir(parents=True, exist_ok=True)
    with open(ORACLE_VENV.parent / f"{ORACLE_VENV.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return _install("ros2cli", _install_ros2cli) or (_install("launch", _install_launch) if launch else None)


# The marker of each part of the oracle venv, written when its install has finished.
INSTALLED = ".roc-installed-{part}"


def _install(part: str, install) -> str | None:
    """Run ``install`` unless ``part`` is marked installed; mark it when ``install`` succeeds."""
    marker = ORACLE_VENV / INSTALLED.format(part=part)
    if marker.exists():
        return None
    reason = install()
    if reason is None:
        marker.touch()
    return reason


def _install_ros2cli() -> str | None:
    import shutil

    script = require_oracle("ros2 CLI (its installer)", SHARED / "oracles" / "install_ros2cli.sh")
    shutil.rmtree(ORACLE_VENV, ignore_errors=True)
    base = getattr(sys, "_base_executable", sys.executable)
    made = subprocess.run([base, "-m", "venv", str(ORACLE_VENV)], capture_output=True, text=True)
    if made.returncode != 0:
        return f"cannot create {ORACLE_VENV}: {made.stderr.strip()}"
    installed = subprocess.run(["bash", str(script), str(ORACLE_VENV)], capture_output=True, text=True, timeout=900,
                               env=INSTALLER_ENV)
    if installed.returncode != 0:
        return f"install_ros2cli.sh failed: {installed.stderr.strip()[-300:]}"
    pins = [line.strip() for line in REQUIREMENTS.read_text().splitlines()
            if line.strip().startswith(tuple(f"{name}==" for name in ORACLE_INTERFACES))]
    added = subprocess.run([str(ORACLE_VENV / "bin" / "python"), "-m", "pip", "install", "-q", *pins],
                           capture_output=True, text=True, timeout=900)
    if added.returncode != 0:
        return f"installing {' '.join(pins)} into the oracle failed: {added.stderr.strip()[-300:]}"
    # its message packages' CMake exports repaired as the suite's venv's are: a build whose AMENT_PREFIX_PATH
    # names the oracle first (graph_env) takes them from there
    repaired = subprocess.run([str(ORACLE_VENV / "bin" / "python"), str(REPO / "scripts" / "fix_ros_wheels.py"),
                               "--quiet"], capture_output=True, text=True, timeout=300)
    if repaired.returncode != 0:
        return f"fix_ros_wheels.py in the oracle failed: {(repaired.stderr or repaired.stdout).strip()[-300:]}"
    return None


def _install_launch() -> str | None:
    """``ros2 launch`` in the oracle venv. install_launch.sh builds composition_interfaces with CMake, which
    needs what roc's own venv has for that: the wheels of requirements/ros-DISTRO.txt with their CMake
    fix-ups, and catkin_pkg (ament_cmake reads package.xml with it; roc's venv has it through colcon).
    Every step may run again over a half-done one (the installer completes a half-installed launch)."""
    script = SHARED / "oracles" / "install_launch.sh"
    if not script.is_file():
        return f"no launch installer at {script}"
    python = str(ORACLE_VENV / "bin" / "python")
    steps = [[python, "-m", "pip", "install", "-q", "-r", str(REQUIREMENTS), "catkin-pkg"],
             [python, str(REPO / "scripts" / "fix_ros_wheels.py"), "--quiet"],
             ["bash", str(script), str(ORACLE_VENV)]]
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True, timeout=900, env=INSTALLER_ENV)
        if done.returncode != 0:
            return f"{' '.join(step[:4])} failed: {(done.stderr or done.stdout).strip()[-300:]}"
    return None


def stop_daemon(env: dict[str, str]) -> None:
    """Stop roc's daemon of ``env`` (by its PID if it does not answer), and ros2's."""
    status = roc("daemon", "status", "--format", "json", env=env)
    pid = json.loads(status.stdout).get("pid") if status.returncode == 0 and status.stdout else None
    roc("daemon", "stop", env=env)
    if pid:
        try:
            os.kill(pid, 9)
        except ProcessLookupError:
            pass
    if ros2_daemon_listens(env):  # the oracle started its daemon in this domain
        ros2("daemon", "stop", env=env)


def ros2_daemon_listens(env: dict[str, str]) -> bool:
    """A ros2 daemon serves ``env``'s domain: it listens on 127.0.0.1, port 11511 + ROS_DOMAIN_ID
    (ros2cli.daemon.get_port). Asked before ``ros2 daemon stop``, which takes half a second to start."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.settimeout(1)
        return probe.connect_ex(("127.0.0.1", 11511 + int(env.get("ROS_DOMAIN_ID") or 0))) == 0


def assert_call_and_goal_work(env: dict[str, str]) -> None:
    """A test_msgs/srv/BasicTypes call to /echo_types (graph_node's ``echo`` server) and a Fibonacci goal
    to /fibonacci, both daemon-less in ``env``, get the server's answers (through a bridge, in its tests)."""
    called = roc("service", "call", "/echo_types", "test_msgs/srv/BasicTypes",
                 "{int32_value: 7, string_value: across}", "--format", "json", "--no-daemon", env=env)
    assert called.returncode == 0, called.stderr
    response = json.loads(called.stdout.splitlines()[-1])
    assert (response["response"]["int32_value"], response["response"]["string_value"]) == (7, "across")
    goal = roc("action", "send_goal", "/fibonacci", "test_msgs/action/Fibonacci", "{order: 5}", "--no-daemon", env=env)
    assert goal.returncode == 0, goal.stderr
    assert "sequence:\n- 0\n- 1\n- 1\n- 2\n- 3\n- 5\n" in goal.stdout
    assert "Goal finished with status: SUCCEEDED" in goal.stdout


def with_tf2_msgs(env: dict[str, str]) -> dict[str, str]:
    """``env`` with tf2_msgs sourced: the example workspace's, built by roc once per source and venv
    into the test cache (ROC_TEST_CACHE) and shared by every test file and worker that needs it (a lock
    file: one builds, the others wait), so a run builds it once, not once per file."""
    import fcntl
    import hashlib
    import shutil

    source = REPO / "workspaces" / "example" / "src" / "tf2_msgs"
    digest = hashlib.sha256(sys.prefix.encode())
    for path in sorted(source.rglob("*")):
        if path.is_file():
            digest.update(str(path.relative_to(source)).encode() + path.read_bytes())
    cache = ORACLE_VENV.parent / f"tf2_msgs-{digest.hexdigest()[:16]}"
    cache.parent.mkdir(parents=True, exist_ok=True)
    with open(cache.parent / f"{cache.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (cache / "built").exists():
            shutil.rmtree(cache, ignore_errors=True)
            shutil.copytree(source, cache / "src" / "tf2_msgs")
            built = roc_build("work", "build", cwd=cache, timeout=900)
            assert built.returncode == 0, built.stdout + built.stderr
            (cache / "built").touch()
    dumped = subprocess.run(["bash", "-c", f'source "{cache}/install/setup.bash" && env -0'], env=env,
                            capture_output=True, timeout=60)
    assert dumped.returncode == 0, dumped.stderr
    return dict(item.split("=", 1) for item in dumped.stdout.decode().split("\0") if "=" in item)
