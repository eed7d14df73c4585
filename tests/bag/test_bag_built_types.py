"""roc.bag.built_types: which packages a bag's definitions need built, the interface packages written
for them, a build that fails (a clear one-line error, nothing half-written in the cache) or is
stopped by SIGTERM (no process left, nothing in the cache). The
live play of such a bag is in test_bag_live.py."""

from __future__ import annotations

import os
import signal
import subprocess
import time
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest
from helpers.bag import BAG_ONLY_DEFINITION, BAG_ONLY_TYPE, write_bag_only_bag
from helpers.build import BIN, stop_process

from roc.bag.built_types import packages_to_build, write_sources
from roc.bag.definitions import definition
from roc.bag.message import Definition
from roc.errors import RocError


def test_only_packages_nobody_installed_are_built():
    packages = packages_to_build([Definition(BAG_ONLY_TYPE, "ros2msg", BAG_ONLY_DEFINITION),
                                  definition("std_msgs/msg/String")])
    assert packages == {"bagonly_msgs": {"Stamped": "std_msgs/Header header\nbagonly_msgs/Vec3 vec # three numbers\n",
                                         "Vec3": "float64 x\nfloat64 y\nfloat64 z\n"}}
    assert packages_to_build([definition("geometry_msgs/msg/PoseStamped")]) == {}


def test_a_type_an_installed_package_lacks_is_an_error_not_a_rebuild():
    other_version = Definition("std_msgs/msg/Gone", "ros2msg", "int32 data\n")
    with pytest.raises(RocError, match="std_msgs/msg/Gone.*installed package 'std_msgs' does not have"):
        packages_to_build([other_version])


def test_the_written_package_depends_on_what_its_messages_use(tmp_path):
    write_sources(packages_to_build([Definition(BAG_ONLY_TYPE, "ros2msg", BAG_ONLY_DEFINITION)]), tmp_path)
    package = ElementTree.parse(tmp_path / "bagonly_msgs" / "package.xml").getroot()
    assert package.findtext("name") == "bagonly_msgs"
    assert [d.text for d in package.iter("depend")] == ["std_msgs"]  # not itself, not builtin_interfaces
    assert package.findtext("member_of_group") == "rosidl_interface_packages"
    cmake = (tmp_path / "bagonly_msgs" / "CMakeLists.txt").read_text()
    assert '"msg/Stamped.msg"\n  "msg/Vec3.msg"\n  DEPENDENCIES std_msgs\n' in cmake
    assert (tmp_path / "bagonly_msgs" / "msg" / "Vec3.msg").read_text() == "float64 x\nfloat64 y\nfloat64 z\n"


@pytest.mark.slow
def test_a_definition_that_does_not_build_is_a_one_line_error_and_leaves_no_prefix(tmp_path):
    write_bag_only_bag(tmp_path / "broken", 1, definition="std_msgs/Header header\nnot a field at all\n")
    result = subprocess.run([str(BIN / "roc"), "bag", "play", "--disable-keyboard-controls", "broken"],
                            cwd=tmp_path, env={**os.environ, "ROC_CACHE_DIR": str(tmp_path / "cache")},
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    errors = [line for line in result.stderr.splitlines() if line.startswith("roc: error:")]
    assert len(errors) == 1 and "building bagonly_msgs from the bag's definitions failed" in errors[0], result.stderr
    assert "Traceback" not in result.stderr
    left = sorted(p.name for p in (tmp_path / "cache" / "bag-types").iterdir())
    assert len(left) == 1 and left[0].endswith(".failed.log")  # the build's output, no half-built prefix
    assert "bagonly_msgs" in (tmp_path / "cache" / "bag-types" / left[0]).read_text()


def _processes_mentioning(text: str) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and text in (entry / "cmdline").read_bytes().decode(errors="replace"):
                found.append(int(entry.name))
        except OSError:
            continue
    return found


@pytest.mark.slow
def test_sigterm_during_the_build_stops_it_and_leaves_nothing(tmp_path):
    write_bag_only_bag(tmp_path / "source", 1)
    cache = tmp_path / "cache"
    player = subprocess.Popen([str(BIN / "roc"), "bag", "play", "--disable-keyboard-controls", "source"],
                              cwd=tmp_path, env={**os.environ, "ROC_CACHE_DIR": str(cache)},
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not list(cache.glob("bag-types/*.building/build/bagonly_msgs")):  # cmake runs
            assert time.monotonic() < deadline and player.poll() is None, player.communicate()
            time.sleep(0.05)
        player.send_signal(signal.SIGTERM)
        _, stderr = player.communicate(timeout=60)
    finally:
        stop_process(player)
    assert player.returncode == 130 and "roc: interrupted" in stderr and "Traceback" not in stderr, stderr
    assert list((cache / "bag-types").iterdir()) == []
    deadline = time.monotonic() + 10
    while _processes_mentioning(str(cache)):  # the build's processes end with it
        assert time.monotonic() < deadline, _processes_mentioning(str(cache))
        time.sleep(0.1)
