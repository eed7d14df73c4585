"""roc.middleware: a process roc runs or starts gets the middleware RMW_IMPLEMENTATION names, also where the
ROS 2 wheels' librcl links Fast DDS directly (the library loaded first: ctypes in roc's own processes,
LD_PRELOAD for the daemon and the nodes of roc run and roc launch); only where needed; a middleware named
but not loadable is a one-line error naming it and the fix."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN
from helpers.graph import graph_env, roc, start_nodes, stop_all, stop_daemon
from helpers.launch import demo_env, kill_leftovers, roc_launch, wait_for_nodes
from helpers.rmw import CYCLONEDDS, on_middleware, require_cyclonedds

from roc import middleware

SLOT = 47
RESOURCE = Path("share", "ament_index", "resource_index", "rmw_typesupport")


def prefix_with(tmp_path: Path, librcl_needs: list[str], middlewares: dict[str, Path | None]) -> Path:
    """An ament prefix holding a stand-in librcl.so (the names of its dynamic section) and ``middlewares``
    (name -> a library to install as lib/lib<name>.so, None for none)."""
    (tmp_path / "lib").mkdir(parents=True, exist_ok=True)
    (tmp_path / "lib" / "librcl.so").write_bytes(b"\x7fELF\0" + b"\0".join(n.encode() for n in librcl_needs) + b"\0")
    (tmp_path / RESOURCE).mkdir(parents=True, exist_ok=True)
    for name, library in middlewares.items():
        (tmp_path / RESOURCE / name).write_text("rosidl_typesupport_c\n")
        if library is not None:
            shutil.copyfile(library, tmp_path / "lib" / f"lib{name}.so")
    return tmp_path


WHEELS_LIBRCL = ["librmw_fastrtps_cpp.so", "librmw.so", "librmw_fastrtps_shared_cpp.so", "librmw_dds_common.so"]
A_LIBRARY = Path("/lib/x86_64-linux-gnu/libz.so.1")  # any library that loads stands in for a middleware's


def test_another_middleware_than_librcl_links_is_loaded_first_from_the_ament_index(tmp_path: Path) -> None:
    prefix = prefix_with(tmp_path, WHEELS_LIBRCL, {"rmw_fastrtps_cpp": None, "rmw_other_cpp": A_LIBRARY})
    env = {"AMENT_PREFIX_PATH": str(prefix), "RMW_IMPLEMENTATION": "rmw_other_cpp", "LD_PRELOAD": "/x/libmine.so"}
    assert middleware.library_to_load(env) == prefix / "lib" / "librmw_other_cpp.so"
    started = middleware.process_environment(env)
    assert started["LD_PRELOAD"] == f"{prefix}/lib/librmw_other_cpp.so /x/libmine.so"
    assert middleware.process_environment(started)["LD_PRELOAD"] == started["LD_PRELOAD"]  # once


def test_nothing_is_loaded_where_rcl_gets_the_middleware_on_its_own(tmp_path: Path) -> None:
    wheels = prefix_with(tmp_path / "wheels", WHEELS_LIBRCL, {"rmw_other_cpp": A_LIBRARY})
    apt = prefix_with(tmp_path / "apt", ["librmw_implementation.so", "librmw.so"], {"rmw_other_cpp": A_LIBRARY})
    for env in ({"AMENT_PREFIX_PATH": str(wheels)}, {"AMENT_PREFIX_PATH": str(wheels), "RMW_IMPLEMENTATION":
                "rmw_fastrtps_cpp"}, {"AMENT_PREFIX_PATH": str(apt), "RMW_IMPLEMENTATION": "rmw_other_cpp"}):
        assert middleware.library_to_load(env) is None
        assert middleware.process_environment(env) == env


def test_a_middleware_named_but_not_installed_is_a_one_line_error_with_the_fix(tmp_path: Path) -> None:
    prefix = prefix_with(tmp_path, WHEELS_LIBRCL, {})
    with pytest.raises(middleware.MiddlewareNotLoadable) as raised:
        middleware.library_to_load({"AMENT_PREFIX_PATH": str(prefix), "RMW_IMPLEMENTATION": "rmw_nothing_cpp"})
    assert str(raised.value) == (
        "RMW_IMPLEMENTATION=rmw_nothing_cpp: no such middleware is installed in the ament index (AMENT_PREFIX_PATH): "
        "source the setup script of the workspace that built it, or unset RMW_IMPLEMENTATION to use rmw_fastrtps_cpp")


def test_a_verb_with_an_unknown_middleware_says_so_in_one_line(tmp_path: Path) -> None:
    env = {**graph_env(SLOT, tmp_path), "RMW_IMPLEMENTATION": "rmw_nothing_cpp"}
    for words in (("node", "list", "--no-daemon"), ("node", "list")):
        listed = roc(*words, env=env, timeout=30)
        assert listed.returncode != 0
        assert listed.stderr.strip().splitlines() == [
            "roc: error: RMW_IMPLEMENTATION=rmw_nothing_cpp: no such middleware is installed in the ament index "
            "(AMENT_PREFIX_PATH): source the setup script of the workspace that built it, or unset "
            "RMW_IMPLEMENTATION to use rmw_fastrtps_cpp"], listed.stderr


@pytest.mark.slow
@pytest.mark.rmw
def test_roc_and_the_nodes_it_runs_and_launches_are_on_cyclone_dds(tmp_path: Path, launch_demo_prefix) -> None:
    require_cyclonedds()
    env = on_middleware(demo_env(SLOT, tmp_path, launch_demo_prefix), CYCLONEDDS)
    nodes = start_nodes([[{"name": "plain_node"}]], env)
    ran = subprocess.Popen([str(BIN / "roc"), "run", "roc_launch_demo", "talker", "--ros-args", "-r", "__node:=ran"],
                           env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    launcher = roc_launch("roc_launch_demo", "demo.launch.yaml", env=env, log=tmp_path / "launch.log")
    try:
        wait_for_nodes(env, {"/plain_node", "/ran", "/robot1/talker", "/robot1/listener"}, timeout=60)
        for words in (("node", "list", "--no-daemon"), ("node", "list")):
            listed = roc(*words, env=env)
            assert {"/plain_node", "/ran", "/robot1/talker"} <= set(listed.stdout.split()), listed.stderr
        gids = roc("topic", "info", "-v", "/robot1/news", env=env).stdout
        assert "01.10." in gids  # Cyclone's GUID prefixes (Fast DDS's start 01.0f)
    finally:
        launcher.stop()
        ran.terminate()
        ran.wait(timeout=20)
        stop_all(nodes)
        stop_daemon(env)
        kill_leftovers(str(launch_demo_prefix))
    stderr = ran.stderr.read()  # rcl's words when the node got Fast DDS instead (it then exits 102)
    assert "Expected RMW implementation identifier" not in stderr and ran.returncode != 102, stderr


@pytest.mark.slow
@pytest.mark.rmw
def test_loss_is_unknown_on_cyclone_dds_in_echo_and_hz(tmp_path: Path) -> None:
    require_cyclonedds()
    env = on_middleware(graph_env(SLOT, tmp_path), CYCLONEDDS)
    nodes = start_nodes([[{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String",
                                                             "values": {"data": "hi"}, "rate_hz": 20}]}]], env)
    try:
        echoed = roc("topic", "echo", "/chatter", "--once", "--format", "json", "--no-daemon", env=env)
        assert echoed.returncode == 0, echoed.stderr
        assert json.loads(echoed.stdout)["lost"] is None
        assert "lost messages on /chatter are unknown: the middleware gives no publication sequence numbers" in \
            echoed.stderr
    finally:
        stop_all(nodes)
        stop_daemon(env)
