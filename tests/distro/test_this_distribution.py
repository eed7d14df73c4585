"""roc on the distribution that runs the tests (Jazzy in .venv, Kilted in .venv-kilted): what it reads from
the environment, and the differences between the distributions that roc.distribution handles, each seen
where it shows (Fast DDS's profile file and its variable, the fork server's preloads, package conditions,
roc doctor)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import BIN, DISTRO, REQUIREMENTS, ros_domain_id, ros_env

from roc import distribution
from roc.doctor.network import RMEM_MAX
from roc.ros.discovery import INPUT_BUFFER_BYTES


@pytest.mark.distro
def test_the_distribution_is_read_from_the_venvs_rclpy() -> None:
    found = distribution.detected({"AMENT_PREFIX_PATH": sys.prefix})
    assert found is not None and found[0] == DISTRO == REQUIREMENTS.stem.removeprefix("ros-")
    pinned = next(line for line in REQUIREMENTS.read_text().splitlines() if line.startswith(f"ros-{DISTRO}-rclpy=="))
    assert found[1].startswith(f"rclpy {pinned.split('==')[1].rsplit('.', 1)[0]}.")  # the wheel's own patch may differ
    assert distribution.mix({"AMENT_PREFIX_PATH": sys.prefix}) is None
    assert distribution.mix({"AMENT_PREFIX_PATH": sys.prefix, "ROS_DISTRO": "humble"}).startswith("humble (ROS_DISTRO)")


@pytest.mark.distro
@pytest.mark.slow  # roc doctor's participants (the quick loop stays under 45 s)
def test_doctor_reports_the_distribution(tmp_path: Path) -> None:
    done = subprocess.run([str(BIN / "roc"), "doctor", "--no-daemon", "--spin-time", "0.5", "--format", "json"],
                          env=ros_env(ROS_DOMAIN_ID=ros_domain_id(50), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                                      XDG_RUNTIME_DIR=str(tmp_path)), capture_output=True, text=True, timeout=120)
    found = next(f for f in json.loads(done.stdout)["findings"] if f["check"] == "distribution")
    assert found["level"] == "info" and found["message"].startswith(f"{DISTRO} (rclpy "), found


PROFILE_PROBE = """
import json, os, socket
from roc.ros.discovery import is_metatraffic_port
from roc.ros.graph import Graph
from roc.ros.vendors.fastdds import PROFILE_VARIABLES
graph = Graph()
bound = {}
for fd in map(int, os.listdir("/proc/self/fd")):
    try:
        sock = socket.socket(fileno=os.dup(fd))
    except OSError:  # not a socket
        continue
    with sock:
        if sock.type == socket.SOCK_DGRAM:
            bound[sock.getsockname()[1]] = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
# a participant's discovery port has its user-data port above it; Fast DDS's senders are on ephemeral
# ports, which in the tests' domains may be one of the domain's discovery ports
buffers = [size for port, size in bound.items()
           if is_metatraffic_port(port, int(os.environ["ROS_DOMAIN_ID"])) and port + 1 in bound]
print(json.dumps({"variables": {name: os.environ.get(name) for name in PROFILE_VARIABLES}, "buffers": buffers}))
graph.close()
"""


@pytest.mark.distro
@pytest.mark.slow  # a participant of its own (the quick loop stays under 45 s)
def test_roc_s_participants_load_its_fast_dds_profile_without_a_complaint(tmp_path: Path) -> None:
    """Fast DDS 3 (Kilted) rejects a profile file with Fast DDS 2's element names (Jazzy's), and Kilted's rmw
    warns about Fast DDS 2's variable: either one prints on stderr and loses roc's settings (its
    announcement period and input socket buffers)."""
    done = subprocess.run([sys.executable, "-c", PROFILE_PROBE], env=ros_env(ROS_DOMAIN_ID=ros_domain_id(50),
                          ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST"), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    chosen = distribution.current().profiles_variable
    found = json.loads(done.stdout)
    variables = found["variables"]
    profile = Path(variables.pop(chosen))
    assert set(variables.values()) == {None}
    assert profile.name == ("fastdds_participant.xml" if DISTRO == "jazzy" else "fastdds3_participant.xml")
    assert "<leaseAnnouncement><sec>0</sec><nanosec>500000000</nanosec></leaseAnnouncement>" in profile.read_text()
    # roc enlarged its discovery socket (roc.ros.discovery.enlarge_input_buffers; Linux doubles what it grants)
    granted = min(INPUT_BUFFER_BYTES, int(RMEM_MAX.read_text()))
    assert found["buffers"] == [2 * granted], found["buffers"]


@pytest.mark.distro
@pytest.mark.slow  # a fork server of its own (the quick loop stays under 45 s)
def test_the_fork_server_preloads_every_type_a_node_loads() -> None:
    """roc launch's warm start: rclpy and the type support of every built-in endpoint of a node."""
    probe = ("from roc.launch import forkserver as f; "
             "print(f.preload(), len(f.PRELOAD_MODULES) + len(f.PRELOAD_TYPES))")
    done = subprocess.run([sys.executable, "-c", probe], env=ros_env(), capture_output=True, text=True, timeout=120)
    loaded, wanted = done.stdout.split()
    assert loaded == wanted, done.stderr


MANIFEST = """<?xml version="1.0"?><package format="3"><name>{name}</name><version>0.0.1</version>
<description>d</description><maintainer email="roc@example.com">roc</maintainer><license>Apache-2.0</license>
{depends}<export><build_type>cmake</build_type></export></package>"""


@pytest.mark.distro
def test_ros_distro_conditions_see_the_detected_distribution(tmp_path: Path) -> None:
    """ROS 2 from wheels sets no ROS_DISTRO: roc fills in the one it detects, as a sourced ROS 2 would."""
    for name in ("on_jazzy", "on_kilted"):
        (tmp_path / "src" / name).mkdir(parents=True)
        (tmp_path / "src" / name / "package.xml").write_text(MANIFEST.format(name=name, depends=""))
    depends = "".join(f'<depend condition="$ROS_DISTRO == {d}">on_{d}</depend>' for d in ("jazzy", "kilted"))
    (tmp_path / "src" / "app").mkdir()
    (tmp_path / "src" / "app" / "package.xml").write_text(MANIFEST.format(name="app", depends=depends))
    env = ros_env()
    env.pop("ROS_DISTRO", None)
    listed = subprocess.run([str(BIN / "roc"), "work", "list", "-n", "--packages-up-to", "app"], cwd=tmp_path,
                            env=env, capture_output=True, text=True, timeout=60)
    assert listed.returncode == 0, listed.stderr
    assert sorted(listed.stdout.split()) == ["app", f"on_{DISTRO}"]


KEYED = """module keyed_msgs {
  module msg {
    struct Pair {
      @key string name;
      double value;
    };
  };
};
"""


@pytest.mark.distro
def test_an_interface_defined_in_idl_only_is_shown_as_written(tmp_path: Path) -> None:
    """Kilted's wheels have the first ones (test_msgs' keyed types): no .msg, an IDL module with @key."""
    prefix = tmp_path / "prefix"
    (prefix / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (prefix / "share" / "ament_index" / "resource_index" / "packages" / "keyed_msgs").touch()
    (prefix / "share" / "keyed_msgs" / "msg").mkdir(parents=True)
    (prefix / "share" / "keyed_msgs" / "msg" / "Pair.idl").write_text(KEYED)
    env = ros_env(AMENT_PREFIX_PATH=f"{prefix}:{sys.prefix}")
    shown = subprocess.run([str(BIN / "roc"), "interface", "show", "keyed_msgs/msg/Pair"], env=env,
                           capture_output=True, text=True, timeout=60)
    assert (shown.returncode, shown.stdout, shown.stderr) == (0, KEYED, "")
    if DISTRO != "jazzy":
        kilted = subprocess.run([str(BIN / "roc"), "interface", "show", "test_msgs/msg/KeyedString"], env=env,
                                capture_output=True, text=True, timeout=60)
        assert kilted.returncode == 0 and "      @key string key;\n" in kilted.stdout, kilted.stderr


def test_every_distribution_gets_its_facts() -> None:
    """Pure logic (runs on Jazzy only): older distributions take Jazzy's facts, newer ones Kilted's."""
    assert distribution.named("kilted").fastdds_major == 3 and distribution.named("jazzy").fastdds_major == 2
    assert distribution.named("humble").fastdds_major == 2 and distribution.named("lyrical").fastdds_major == 3
    assert distribution.named("lyrical").name == "lyrical"
    assert [distribution.of_rclpy(v) for v in ("7.1.5", "9.1.2", "3.3.16", "42.0.0", "x")] == [
        "jazzy", "kilted", "humble", None, None]


GUARDED_IMPORT = """
import sys
from roc.distribution import MixedDistributions
from roc.rclpy_guard import guard_rclpy_import
guard_rclpy_import()
try:
    import rclpy.node
except MixedDistributions as error:
    print(error, "|", [name for name in sys.modules if name.startswith("rclpy")])
"""


def test_rclpy_is_not_imported_while_two_distributions_are_sourced(tmp_path: Path) -> None:
    """Pure logic (runs on Jazzy only): an rclpy of another distribution first in the ament index stops the
    import of rclpy before any of it is loaded (tests/distro/test_cross_distribution.py: the real mix)."""
    other = tmp_path / "other"
    (other / "share" / "rclpy").mkdir(parents=True)
    (other / "share" / "rclpy" / "package.xml").write_text("<package><version>9.1.2</version></package>")
    env = ros_env(AMENT_PREFIX_PATH=f"{other}:{sys.prefix}")
    done = subprocess.run([sys.executable, "-c", GUARDED_IMPORT], env=env, capture_output=True, text=True, timeout=60)
    assert done.stdout.startswith(f"two ROS 2 distributions are sourced: kilted (rclpy 9.1.2 in {other}) and "
                                  f"{DISTRO} (rclpy "), done.stdout + done.stderr
    assert done.stdout.endswith("| []\n")
    clean = subprocess.run([sys.executable, "-c", GUARDED_IMPORT], env=ros_env(AMENT_PREFIX_PATH=sys.prefix),
                           capture_output=True, text=True, timeout=60)
    assert (clean.returncode, clean.stdout) == (0, ""), clean.stderr
