"""roc work create: every template and option; the generated packages built with roc (and colcon),
sourced and run, on a ROS graph of their own."""

from __future__ import annotations

import ast
import datetime
import os
import re
import subprocess
import sys
from pathlib import Path
from xml.etree import ElementTree

import pytest
from catkin_pkg.package import parse_package
from helpers.build import (
    BIN,
    colcon,
    comparable_install_files,
    copy_fixture,
    in_sourced_shell,
    installed_files,
    package_dsv_files,
    roc,
    ros_domain_id,
    ros_env,
    sourced_values,
    stop_process,
    without_own_underlay,
)
from helpers.fixture_workspaces import Result, run_roc_inprocess

MAINTAINER = ("--maintainer-name", "Ada Lovelace", "--maintainer-email", "ada@example.com")
OPTIONS = ("--build-type", "--dependencies", "--node-name", "--library-name", "--license", "--maintainer-name",
           "--maintainer-email", "--description", "--package-format", "--destination-directory", "--interfaces",
           "--tests", "--parents")
LICENSES = {  # SPDX id -> (a line of the real text, its minimum length)
    "Apache-2.0": ("Version 2.0, January 2004", 11000),
    "BSD-2-Clause": ("Redistributions in binary form must reproduce the above copyright notice,", 1200),
    "BSD-3-Clause": ("3. Neither the name of the copyright holder nor the names of its", 1400),
    "BSL-1.0": ("Boost Software License - Version 1.0 - August 17th, 2003", 1300),
    "GPL-3.0-only": ("GNU GENERAL PUBLIC LICENSE", 35000),
    "LGPL-3.0-only": ("GNU LESSER GENERAL PUBLIC LICENSE", 7500),
    "MIT": ("Permission is hereby granted, free of charge, to any person obtaining a copy", 1000),
    "MIT-0": ("MIT No Attribution", 900),
    "MPL-2.0": ("Mozilla Public License Version 2.0", 16000),
}


def _env(**extra: str) -> dict[str, str]:
    """roc's environment with git's user configuration under the test's control."""
    return ros_env(**{"GIT_CONFIG_NOSYSTEM": "1", "GIT_CONFIG_GLOBAL": os.devnull, **extra})


def create(cwd: Path, *args: str, env: dict[str, str] | None = None) -> Result:
    """``roc work create ARGS`` in ``cwd`` with ``env`` as its whole environment, run in this process (this
    file creates some 60 packages: as processes, 10 s of the quick loop). test_create_runs_as_the_roc_command
    runs it as a process."""
    return run_roc_inprocess(["work", "create", *args], cwd, env or _env())


def created(cwd: Path, *args: str) -> Result:
    result = create(cwd, *args, *MAINTAINER)
    assert result.returncode == 0, result.stderr
    return result


def workspace(tmp_path: Path) -> Path:
    (tmp_path / "src").mkdir(parents=True)
    return tmp_path


def build(ws: Path) -> None:
    result = roc("work", "build", "--parallel-workers", "2", cwd=ws)
    assert result.returncode == 0, result.stdout + result.stderr


def sourced(ws: Path, script: str, strict: bool = True) -> str:
    ran = in_sourced_shell(ws, f"export ROS_DOMAIN_ID={ros_domain_id(7)}; {script}", strict=strict)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    return ran.stdout


def ctest(ws: Path, package: str) -> str:
    """Run a built package's tests; returns ctest's output."""
    output = sourced(ws, f"ctest --test-dir build/{package} --output-on-failure")
    assert re.search(r"100% tests passed, 0 tests failed out of [1-9]", output), output
    return output


# ---- generated packages, built and used --------------------------------------------------------
# The interface package is the slowest build (~40 s): it comes first so that a pytest-xdist worker
# starts on it at once.

@pytest.mark.slow
def test_interface_package_used_by_a_python_package(tmp_path):
    ws = workspace(tmp_path)
    created(ws, "demo_ifc", "--interfaces", "--tests")
    created(ws, "ifc_user", "--build-type", "ament_python", "--dependencies", "demo_ifc", "--library-name", "texts")
    # The user package's module uses the generated message.
    (ws / "src/ifc_user/ifc_user/texts.py").write_text(
        "from demo_ifc.msg import Greeting\n\n\ndef greeting(name):\n"
        "    return Greeting(text=f'Hello, {name}!', count=7)\n")
    build(ws)
    output = sourced(ws, "python -c 'from ifc_user.texts import greeting; g = greeting(\"ifc\"); "
                         "print(g.text, g.count, type(g).__module__)'; "
                         "python -c 'from demo_ifc.srv import SetGreeting; from demo_ifc.action import Countdown; "
                         "print(SetGreeting.Response(success=True).success, Countdown.Goal(start=3).start)'")
    assert output.splitlines() == ["Hello, ifc! 7 demo_ifc.msg._greeting", "True 3"]
    assert "test_interfaces" in ctest(ws, "demo_ifc")
    results = (ws / "build/demo_ifc/test_results/demo_ifc/test_interfaces.xunit.xml").read_text()
    assert 'tests="3"' in results and 'failures="0"' in results and 'errors="0"' in results
    manifest = parse_package(ws / "src/demo_ifc")
    assert [g.name for g in manifest.member_of_groups] == ["rosidl_interface_packages"]
    assert {d.name for d in manifest.build_depends} >= {"builtin_interfaces", "std_msgs", "action_msgs"}


@pytest.mark.slow
def test_ament_cmake_library_found_by_a_dependent_and_tested(tmp_path):
    assert (Path(sys.prefix) / "share/gtest_vendor").is_dir(), \
        "ament_cmake_gtest needs gtest_vendor: the environment must install ros-jazzy-gtest-vendor"
    ws = workspace(tmp_path)
    created(ws, "cpp_lib", "--library-name", "filter", "--dependencies", "std_msgs")
    created(ws, "cpp_user", "--library-name", "user_lib", "--dependencies", "cpp_lib", "--tests")
    created(ws, "cpp_empty", "--tests")
    # cpp_user's library now delegates to cpp_lib: its generated gtest passes only if that links.
    source = ws / "src/cpp_user/src/user_lib.cpp"
    text = source.read_text().replace('return "Hello, " + name_ + "!";', "return cpp_lib::Filter(name_).greeting();")
    source.write_text('#include "cpp_lib/filter.hpp"\n' + text)
    build(ws)
    assert "test_user_lib" in ctest(ws, "cpp_user")
    assert "test_cpp_empty" in ctest(ws, "cpp_empty")
    installed = installed_files(ws / "install/cpp_lib")
    assert {"include/cpp_lib/cpp_lib/filter.hpp", "include/cpp_lib/cpp_lib/visibility_control.h",
            "lib/libfilter.so", "share/cpp_lib/cmake/export_cpp_libExport.cmake"} <= installed
    linked = sourced(ws, "ldd install/cpp_user/lib/libuser_lib.so")
    assert f"{ws}/install/cpp_lib/lib/libfilter.so" in linked


@pytest.mark.slow
def test_cmake_library_config_found_by_a_dependent(tmp_path):
    ws = workspace(tmp_path)
    created(ws, "plain_lib", "--build-type", "cmake", "--library-name", "calc", "--node-name", "calc_demo",
            "--tests")
    created(ws, "plain_user", "--build-type", "cmake", "--dependencies", "plain_lib", "--node-name", "user_demo",
            "--tests")
    (ws / "src/plain_user/src/user_demo.cpp").write_text(
        '#include <cstdio>\n\n#include "plain_lib/calc.hpp"\n\n'
        'int main()\n{\n  std::printf("%s\\n", plain_lib::Calc("user").greeting().c_str());\n  return 0;\n}\n')
    build(ws)
    assert (ws / "install/plain_lib/share/plain_lib/cmake/plain_libConfig.cmake").is_file()
    output = sourced(ws, "install/plain_lib/lib/plain_lib/calc_demo; install/plain_user/lib/plain_user/user_demo")
    assert output.splitlines() == ["Hello, calc_demo!", "Hello, user!"]
    assert "test_calc" in ctest(ws, "plain_lib")
    assert "run_user_demo" in ctest(ws, "plain_user")


@pytest.mark.slow
def test_python_node_publishes_on_the_ros_graph(tmp_path):
    ws = workspace(tmp_path)
    created(ws, "py_talker", "--build-type", "ament_python", "--node-name", "talker", "--library-name", "words",
            "--tests")
    created(ws, "py_plain", "--build-type", "ament_python", "--tests")
    build(ws)
    tests = sourced(ws, "python -m pytest -q -p no:cacheprovider src/py_talker/test src/py_plain/test")
    assert "3 passed" in tests, tests
    # It stops by itself after max_count messages.
    alone = sourced(ws, "timeout 60 install/py_talker/lib/py_talker/talker --ros-args -p max_count:=3 "
                        "-p period:=0.05 2>&1")
    assert re.findall(r"Publishing '(.*)'", alone) == ["Hello, talker! 1", "Hello, talker! 2", "Hello, talker! 3"]
    # A listener in another process receives its messages.
    env = {"HOME": os.environ.get("HOME", "/tmp"), "PATH": f"{BIN}:/usr/bin:/bin", "ROS_DOMAIN_ID": ros_domain_id(7),
           "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}
    listener_code = (
        "import time, rclpy\nfrom rclpy.node import Node\nfrom std_msgs.msg import String\n"
        "rclpy.init()\nnode = Node('listener')\nreceived = []\n"
        "node.create_subscription(String, 'chatter', lambda m: received.append(m.data), 10)\n"
        "deadline = time.monotonic() + 45\n"
        "while len(received) < 3 and time.monotonic() < deadline:\n    rclpy.spin_once(node, timeout_sec=0.1)\n"
        "print('\\n'.join(received))\nraise SystemExit(0 if len(received) >= 3 else 1)\n")
    (ws / "listener.py").write_text(listener_code)
    source = "set -eu; source install/setup.bash; exec "
    talker = subprocess.Popen(["bash", "-c", source + "install/py_talker/lib/py_talker/talker --ros-args "
                               "-p max_count:=1000 -p period:=0.1"], cwd=ws, env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    listener = subprocess.Popen(["bash", "-c", source + "python listener.py"], cwd=ws, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        output, _ = listener.communicate(timeout=60)
    finally:
        stop_process(listener)
        stop_process(talker)
    assert listener.returncode == 0, output
    assert len(re.findall(r"^Hello, talker! \d+$", output, re.MULTILINE)) >= 3, output


@pytest.mark.slow
def test_rclcpp_node_package_is_valid_up_to_rclcpp(tmp_path):
    """No rclcpp here: configure the C++ node package and expect exactly the missing rclcpp; with a
    stand-in rclcpp config package the rest of the configuration must succeed."""
    created(tmp_path, "cpp_node", "--node-name", "talker", "--library-name", "greeter", "--tests")
    package = tmp_path / "cpp_node"
    manifest = parse_package(package)
    assert {d.name for d in manifest.build_depends} == {"rclcpp", "std_msgs"}
    node = (package / "src/talker.cpp").read_text()
    assert '#include "rclcpp/rclcpp.hpp"' in node and "class Talker : public rclcpp::Node" in node
    env = _env(CMAKE_PREFIX_PATH=sys.prefix)
    configure = ["cmake", "-S", str(package), "-B", str(tmp_path / "build")]
    result = subprocess.run(configure, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode != 0
    line = (package / "CMakeLists.txt").read_text().splitlines().index("find_package(rclcpp REQUIRED)") + 1
    errors = re.findall(r"CMake Error at (\S+) \((\w+)\)", result.stderr)
    assert errors == [(f"CMakeLists.txt:{line}", "find_package")], result.stderr
    assert 'package configuration file provided by "rclcpp"' in result.stderr
    stand_in = tmp_path / "stand_in/share/rclcpp/cmake"
    stand_in.mkdir(parents=True)
    (stand_in / "rclcppConfig.cmake").write_text("set(rclcpp_FOUND TRUE)\n")
    env["CMAKE_PREFIX_PATH"] = f"{tmp_path / 'stand_in'}:{sys.prefix}"
    result = subprocess.run(configure, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "Generating done" in result.stdout


@pytest.mark.colcon
@pytest.mark.slow
def test_generated_packages_build_the_same_with_colcon(tmp_path):
    trees = {}
    for tool in ("roc", "colcon"):
        ws = workspace(tmp_path / tool)
        created(ws, "par_py", "--build-type", "ament_python", "--node-name", "talker", "--library-name", "words",
                "--tests")
        created(ws, "par_lib", "--library-name", "filter", "--dependencies", "std_msgs")
        created(ws, "par_plain", "--build-type", "cmake", "--library-name", "calc", "--node-name", "calc_demo")
        result = roc("work", "build", cwd=ws) if tool == "roc" else colcon("build", cwd=ws)
        assert result.returncode == 0, result.stdout + result.stderr
        trees[tool] = ws
    ours, theirs = (trees[tool] / "install" for tool in ("roc", "colcon"))
    assert comparable_install_files(ours) == comparable_install_files(theirs)
    assert package_dsv_files(ours) == package_dsv_files(theirs)
    ours_env = without_own_underlay(sourced_values(trees["roc"]))
    theirs_env = sourced_values(trees["colcon"], strict=False)
    theirs_env["LD_LIBRARY_PATH"] = theirs_env["LD_LIBRARY_PATH"].rstrip(":")  # colcon's empty entry
    assert ours_env == theirs_env
    output = sourced(trees["colcon"], "install/par_py/lib/par_py/talker --ros-args -p max_count:=1 "
                                      "-p period:=0.01 2>&1", strict=False)  # colcon's scripts: no set -u
    assert "Publishing 'Hello, talker! 1'" in output


# ---- what gets written ---------------------------------------------------------------------------

CPP_LIBRARY = {"include/pkg/lib.hpp", "include/pkg/visibility_control.h", "src/lib.cpp"}
INTERFACES = {"CMakeLists.txt", "msg/Greeting.msg", "srv/SetGreeting.srv", "action/Countdown.action"}
PYTHON = {"setup.py", "setup.cfg", "resource/pkg", "pkg/__init__.py"}
COMBINATIONS = [  # (build type, options) -> the files besides package.xml and LICENSE
    (("ament_cmake",), {"CMakeLists.txt"}),
    (("ament_cmake", "--library-name", "lib"), {"CMakeLists.txt", *CPP_LIBRARY}),
    (("ament_cmake", "--node-name", "node"), {"CMakeLists.txt", "src/node.cpp"}),
    (("ament_cmake", "--node-name", "node", "--library-name", "lib", "--tests"),
     {"CMakeLists.txt", *CPP_LIBRARY, "src/node.cpp", "test/test_lib.cpp"}),
    (("ament_cmake", "--tests"), {"CMakeLists.txt", "test/test_pkg.py"}),
    (("ament_cmake", "--library-name", "lib", "--tests"), {"CMakeLists.txt", *CPP_LIBRARY, "test/test_lib.cpp"}),
    (("ament_cmake", "--interfaces"), INTERFACES),
    (("ament_cmake", "--interfaces", "--tests"), {*INTERFACES, "test/test_interfaces.py"}),
    (("ament_python",), PYTHON),
    (("ament_python", "--node-name", "node"), {*PYTHON, "pkg/node.py"}),
    (("ament_python", "--library-name", "lib", "--tests"), {*PYTHON, "pkg/lib.py", "test/test_pkg.py"}),
    (("ament_python", "--node-name", "node", "--library-name", "lib", "--tests"),
     {*PYTHON, "pkg/node.py", "pkg/lib.py", "test/test_pkg.py"}),
    (("cmake",), {"CMakeLists.txt"}),
    (("cmake", "--library-name", "lib"), {"CMakeLists.txt", *CPP_LIBRARY, "cmake/pkgConfig.cmake.in"}),
    (("cmake", "--node-name", "node", "--tests"), {"CMakeLists.txt", "src/node.cpp", "test/test_pkg.cpp"}),
    (("cmake", "--node-name", "node", "--library-name", "lib", "--tests"),
     {"CMakeLists.txt", *CPP_LIBRARY, "src/node.cpp", "cmake/pkgConfig.cmake.in", "test/test_lib.cpp"}),
]


@pytest.mark.parametrize("combination, expected", COMBINATIONS, ids=["-".join(c) for c, _ in COMBINATIONS])
def test_every_combination_writes_its_files_and_a_valid_manifest(tmp_path, combination, expected):
    build_type, *options = combination
    type_option = () if "--interfaces" in options else ("--build-type", build_type)
    result = created(tmp_path, "pkg", *type_option, *options, "--license", "MIT")
    package = tmp_path / "pkg"
    files = {str(p.relative_to(package)) for p in package.rglob("*") if p.is_file()}
    assert files == expected | {"package.xml", "LICENSE"}
    # The file list is printed.
    assert result.stdout.splitlines() == [f"created package pkg ({build_type}) in pkg:",
                                          *(f"  {f}" for f in sorted(files))]
    manifest = parse_package(package)
    assert (manifest.name, manifest.package_format, manifest.version) == ("pkg", 3, "0.0.0")
    assert manifest.get_build_type() == build_type
    assert [str(m) for m in manifest.maintainers] == ["Ada Lovelace <ada@example.com>"]
    for path in files:
        if path.endswith(".py"):
            ast.parse((package / path).read_text(), path)


def test_package_format_2(tmp_path):
    created(tmp_path, "old_style", "--package-format", "2", "--build-type", "ament_python")
    assert parse_package(tmp_path / "old_style").package_format == 2
    result = create(tmp_path, "old_ifc", "--interfaces", "--package-format", "2", *MAINTAINER)
    assert result.returncode == 2 and "--package-format 3" in result.stderr
    assert not (tmp_path / "old_ifc").exists()


def test_quotes_and_markup_in_values_stay_text(tmp_path):
    description = 'He said "it\'s <fine> & done" \\ ${CMAKE_VAR} """ end'
    name = "Zoë O'Brien <&> \"Q\""
    result = create(tmp_path, "quoted", "--build-type", "ament_python", "--description", description,
                    "--maintainer-name", name, "--maintainer-email", "zoe@example.com", "--license",
                    'Custom "licence" <v2>')
    assert result.returncode == 0, result.stderr
    manifest = parse_package(tmp_path / "quoted")  # raises on XML that does not parse
    # catkin_pkg returns the description as (XHTML) markup; the XML text is the plain value.
    assert ElementTree.parse(tmp_path / "quoted/package.xml").findtext("description") == description
    assert manifest.maintainers[0].name == name
    assert manifest.licenses == ['Custom "licence" <v2>']
    setup = ast.parse((tmp_path / "quoted/setup.py").read_text(encoding="utf-8"))
    keywords = {k.arg: k.value for node in ast.walk(setup) if isinstance(node, ast.Call)
                for k in node.keywords}
    assert ast.literal_eval(keywords["description"]) == description
    assert ast.literal_eval(keywords["maintainer"]) == name
    created(tmp_path, "quoted_cpp", "--description", description, "--library-name", "lib")
    assert ElementTree.parse(tmp_path / "quoted_cpp/package.xml").findtext("description") == description
    assert "CMAKE_VAR" not in (tmp_path / "quoted_cpp/CMakeLists.txt").read_text()


# ---- names, errors and defaults ------------------------------------------------------------------

@pytest.mark.parametrize("option, name, suggestion", [
    (None, "My-Pkg", "my_pkg"), (None, "MyPkg", "my_pkg"), (None, "my__pkg", "my_pkg"), (None, "pkg_", "pkg"),
    (None, "_pkg", "pkg"), (None, "9lives", "lives"), (None, "class", "class_pkg"),
    ("--node-name", "Talker", "talker"), ("--node-name", "my node", "my_node"),
    ("--library-name", "My-Lib", "my_lib"), ("--library-name", "import", "import_library"),
])
def test_invalid_names_are_refused_with_a_suggestion(tmp_path, option, name, suggestion):
    args = (name,) if option is None else ("good_pkg", option, name)
    result = create(tmp_path, *args, *MAINTAINER)
    assert result.returncode == 2
    assert result.stderr.startswith("roc: error: ") and len(result.stderr.splitlines()) == 1
    assert f"try '{suggestion}'" in result.stderr
    kind = {None: "package", "--node-name": "node", "--library-name": "library"}[option]
    assert f"'{name}'" in result.stderr and f"{kind} name" in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, message", [
    (("--interfaces", "--build-type", "ament_python"), "--interfaces makes an ament_cmake package"),
    (("--interfaces", "--node-name", "talker"), "cannot be combined with --node-name"),
    (("--build-type", "ament_python"), "cannot be named 'test'"),
    (("--dependencies", "python3-numpy"), "not a CMake package name"),
    (("--dependencies", "test"), "cannot depend on itself"),
    (("--maintainer-email", "not-an-address"), "not a valid e-mail address"),
    (("--description", " "), "--description must not be empty"),
])
def test_usage_errors_write_nothing(tmp_path, args, message):
    result = create(tmp_path, "test", *MAINTAINER, *args)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and result.stderr.startswith("roc: error: ")
    assert list(tmp_path.iterdir()) == []


def test_rosdep_keys_are_dependencies_of_python_packages(tmp_path):
    created(tmp_path, "py_numpy", "--build-type", "ament_python", "--dependencies", "python3-numpy", "rclpy")
    assert [d.name for d in parse_package(tmp_path / "py_numpy").build_depends] == ["python3-numpy", "rclpy"]


def test_node_named_like_the_library_is_renamed(tmp_path):
    result = created(tmp_path, "same", "--node-name", "worker", "--library-name", "worker",
                     "--build-type", "ament_python")
    assert "'worker_node'" in result.stderr
    assert (tmp_path / "same/same/worker_node.py").is_file() and (tmp_path / "same/same/worker.py").is_file()


def test_an_existing_directory_is_never_overwritten(tmp_path):
    ws = workspace(tmp_path)
    existing = ws / "src" / "taken"
    existing.mkdir()
    (existing / "notes.txt").write_text("mine\n")
    result = create(ws, "taken", *MAINTAINER)
    assert result.returncode == 1
    assert result.stderr == f"roc: error: {existing} already exists; remove it or choose another name or " \
                            "--destination-directory\n"
    assert [p.name for p in (ws / "src").iterdir()] == ["taken"]
    assert [p.name for p in existing.iterdir()] == ["notes.txt"] and (existing / "notes.txt").read_text() == "mine\n"
    (ws / "src" / "empty").mkdir()  # even an empty one
    assert create(ws, "empty", *MAINTAINER).returncode == 1 and list((ws / "src" / "empty").iterdir()) == []


@pytest.mark.parametrize("failure", [KeyboardInterrupt, OSError])
def test_an_interrupted_write_leaves_nothing(tmp_path, monkeypatch, failure):
    from roc.create import write
    from roc.errors import RocError

    written = []

    def write_text(self, text, **options):
        if written:
            raise failure(28, "No space left on device")
        written.append(self)
        with Path.open(self, "w", **options) as handle:
            return handle.write(text)

    monkeypatch.setattr(write.Path, "write_text", write_text)
    with pytest.raises(KeyboardInterrupt if failure is KeyboardInterrupt else RocError):
        write.write_package(tmp_path, "half", {"package.xml": "<package/>", "CMakeLists.txt": "project(half)"})
    assert written and list(tmp_path.iterdir()) == []


def test_create_runs_as_the_roc_command(tmp_path):
    """The roc command prints, writes and exits as this file's in-process runs do, errors included."""
    def files(root: Path) -> dict[str, bytes]:
        return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}

    for args, code in [(("pkg", "--build-type", "ament_python", "--node-name", "talker", "--license", "MIT"), 0),
                       (("My-Pkg",), 2)]:
        process_dir, in_process_dir = tmp_path / f"process{code}", tmp_path / f"in_process{code}"
        process_dir.mkdir()
        in_process_dir.mkdir()
        as_process = roc("work", "create", *args, *MAINTAINER, cwd=process_dir, env=_env())
        in_process = create(in_process_dir, *args, *MAINTAINER)
        assert (as_process.returncode, as_process.stdout, as_process.stderr) == \
            (in_process.returncode, in_process.stdout, in_process.stderr)
        assert as_process.returncode == code and as_process.stdout.startswith("created package pkg" if code == 0 else "")
        assert files(process_dir) == files(in_process_dir)


def test_destination_defaults_to_the_workspace_src(tmp_path):
    ws = workspace(tmp_path / "ws")
    deep = ws / "src" / "some_pkg" / "sub"
    deep.mkdir(parents=True)
    (ws / "src" / "some_pkg" / "package.xml").write_text("<package/>")
    result = created(deep, "from_inside")
    assert (ws / "src" / "from_inside" / "package.xml").is_file()
    assert result.stdout.startswith(f"created package from_inside (ament_cmake) in {ws / 'src' / 'from_inside'}:")
    outside = tmp_path / "outside"
    outside.mkdir()
    created(outside, "here")
    assert (outside / "here" / "package.xml").is_file()
    created(outside, "there", "--destination-directory", "new/dir", "--parents")
    assert (outside / "new" / "dir" / "there" / "package.xml").is_file()


@pytest.mark.parametrize("license_id", sorted(LICENSES))
def test_known_licences_get_their_full_text(tmp_path, license_id):
    created(tmp_path, "licensed", "--license", license_id.lower() if license_id == "MIT" else license_id)
    assert parse_package(tmp_path / "licensed").licenses == [license_id]
    text = (tmp_path / "licensed" / "LICENSE").read_text()
    phrase, length = LICENSES[license_id]
    assert phrase in text and len(text) >= length
    assert "<copyright holders>" not in text
    if license_id.startswith(("MIT", "BSD")):
        assert f"{datetime.date.today().year} Ada Lovelace" in text.splitlines()[0 if "BSD" in license_id else 2]


def test_unknown_licence_goes_to_package_xml_only(tmp_path):
    result = created(tmp_path, "proprietary", "--license", "LicenseRef-Acme")
    assert parse_package(tmp_path / "proprietary").licenses == ["LicenseRef-Acme"]
    assert not (tmp_path / "proprietary" / "LICENSE").exists()
    assert "roc: note: licence 'LicenseRef-Acme' is in package.xml but no LICENSE file was written" in result.stderr
    listed = create(tmp_path, "x", "--license", "?")
    assert listed.returncode == 0 and listed.stdout.split() == sorted(LICENSES)
    assert not (tmp_path / "x").exists()


def test_maintainer_defaults_come_from_git_config(tmp_path):
    config = tmp_path / "gitconfig"
    config.write_text("[user]\n\tname = Grace Hopper\n\temail = grace@example.org\n")
    (tmp_path / "work").mkdir()
    result = create(tmp_path / "work", "from_git", env=_env(GIT_CONFIG_GLOBAL=str(config)))
    assert result.returncode == 0, result.stderr
    assert [str(m) for m in parse_package(tmp_path / "work/from_git").maintainers] == \
        ["Grace Hopper <grace@example.org>"]
    result = create(tmp_path / "work", "no_git", env=_env(LOGNAME="tester", USER="tester"))
    assert result.returncode == 0, result.stderr
    assert [str(m) for m in parse_package(tmp_path / "work/no_git").maintainers] == ["tester <tester@todo.todo>"]


def test_help_documents_every_option(tmp_path):
    import argparse

    from roc.commands.work import create as work_create

    parser = argparse.ArgumentParser()
    work_create.add_arguments(parser)
    options = {o for action in parser._actions if action.help != argparse.SUPPRESS and action.option_strings
               for o in action.option_strings if o.startswith("--") and o != "--help"}
    assert options == set(OPTIONS)
    assert all(action.help for action in parser._actions)
    result = roc("work", "create", "--help", cwd=tmp_path)
    assert result.returncode == 0
    for option in OPTIONS:
        assert re.search(rf"^  {option}\b", result.stdout, re.MULTILINE), option
    for choice in ("{ament_cmake,ament_python,cmake}", "{2,3}", "NAME", "default: ament_cmake", "default: 3"):
        assert choice in result.stdout


def test_create_refuses_a_missing_parent_unless_asked(tmp_path: Path) -> None:
    missing = tmp_path / "nonexistent" / "dir"
    refused = create(tmp_path, "pkg_a", "--destination-directory", str(missing))
    assert refused.returncode == 2
    assert refused.stderr.startswith(f"roc: error: --destination-directory {missing}: {missing.parent} does not "
                                     "exist; create it, or add --parents")
    assert not (tmp_path / "nonexistent").exists()
    made = create(tmp_path, "pkg_a", "--destination-directory", str(missing), "--parents")
    assert made.returncode == 0, made.stderr
    assert (missing / "pkg_a" / "package.xml").is_file()
    # the destination itself may be new, as with mkdir
    assert create(tmp_path, "pkg_b", "--destination-directory", "new").returncode == 0


def test_create_refuses_a_name_the_workspace_already_has(tmp_path: Path) -> None:
    workspace = copy_fixture("selection", tmp_path / "ws")
    before = sorted(p.relative_to(workspace) for p in workspace.rglob("*"))
    for destination in ("src", "src/new_group"):
        result = create(workspace, "core", "--build-type", "ament_python", "--destination-directory", destination)
        assert result.returncode == 2
        assert result.stderr.startswith(f"roc: error: the workspace {workspace} already has a package named "
                                        f"'core' (in {workspace / 'src' / 'core'}); choose another name")
    assert sorted(p.relative_to(workspace) for p in workspace.rglob("*")) == before
