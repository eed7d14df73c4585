"""package.xml parsing (formats 1, 2 and 3) into the dependency categories colcon uses."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest
from helpers.build import FIXTURES

from roc.errors import ManifestError
from roc.workspace.manifest import parse_manifest

FORMATS = FIXTURES / "formats" / "src"
ROS2 = {"ROS_VERSION": "2", "ROS_PYTHON_VERSION": "3", "ROS_DISTRO": "jazzy"}


def categories(path: Path, variables: dict[str, str] = ROS2) -> dict[str, list[str]]:
    return {c: sorted(deps) for c, deps in parse_manifest(path, variables).category_dependencies().items()}


def write(tmp_path: Path, body: str, fmt: str = ' format="3"') -> Path:
    path = tmp_path / "package.xml"
    path.write_text(f'<?xml version="1.0"?>\n<package{fmt}>\n{body}\n</package>\n')
    return path


HEADER = "<name>p</name><version>1.2.3</version><description>d</description><license>MIT</license>"


def test_format_1_run_depend_is_build_export_and_exec() -> None:
    manifest = parse_manifest(FORMATS / "fmt1_pkg" / "package.xml", ROS2)
    assert (manifest.format, manifest.name, manifest.version, manifest.build_type) == (1, "fmt1_pkg", "1.0.0", "catkin")
    assert categories(FORMATS / "fmt1_pkg" / "package.xml") == {
        "build": ["base_msgs", "catkin", "roscpp"],
        "run": ["base_msgs", "rospy"],
        "test": ["rostest"],
    }
    assert [d.name for d in manifest.dependencies_by_tag("build_export_depend")] == ["base_msgs", "rospy"]
    roscpp = next(d for d in manifest.dependencies if d.name == "roscpp")
    assert roscpp.versions == (("version_gte", "1.2.0"),)


def test_format_2_depend_expands_and_doc_depend_is_no_category() -> None:
    manifest = parse_manifest(FORMATS / "fmt2_pkg" / "package.xml", ROS2)
    assert (manifest.format, manifest.build_type) == (2, "ament_cmake")
    assert categories(FORMATS / "fmt2_pkg" / "package.xml") == {
        "build": ["ament_cmake", "base_msgs", "rclcpp"],
        "run": ["base_msgs", "fmt1_pkg", "rclcpp_headers", "tools"],  # tools: buildtool_export_depend
        "test": ["ament_lint_auto"],
    }
    assert [d.name for d in manifest.dependencies_by_tag("doc_depend")] == ["doxygen"]
    assert manifest.maintainers == ["Two <two@example.com>", "Second Maintainer <second@example.com>"]
    assert manifest.authors == ["Author Without Email"]
    assert manifest.licenses == ["Apache-2.0"]


def test_format_3_conditions_versions_and_groups() -> None:
    path = FORMATS / "fmt3_pkg" / "package.xml"
    manifest = parse_manifest(path, ROS2)
    assert manifest.build_type == "ament_cmake"
    assert categories(path) == {
        "build": ["ament_cmake", "fmt2_pkg"],
        "run": ["fmt2_pkg", "humble_to_rolling", "jazzy_only", "py3_dep"],
        "test": ["quoted_two"],
    }
    fmt2 = next(d for d in manifest.dependencies if d.name == "fmt2_pkg")
    assert dict(fmt2.versions) == {"version_gte": "2.0.0", "version_lt": "3.0.0"}
    assert manifest.group_depends == ["fmt_group"]  # ros1_group's condition does not hold


def test_format_3_under_ros_1() -> None:
    path = FORMATS / "fmt3_pkg" / "package.xml"
    ros1 = {"ROS_VERSION": "1", "ROS_PYTHON_VERSION": "2", "ROS_DISTRO": "noetic"}
    manifest = parse_manifest(path, ros1)
    assert manifest.build_type == "catkin"
    assert categories(path, ros1) == {
        "build": ["catkin", "fmt2_pkg"],
        "run": ["fmt2_pkg", "humble_to_rolling", "not_jazzy", "py3_dep"],  # "humble" <= "noetic" < "rolling"
        "test": [],
    }
    assert manifest.group_depends == ["fmt_group", "ros1_group"]


def test_member_of_group_condition() -> None:
    path = FORMATS / "members" / "member_ros1" / "package.xml"
    assert parse_manifest(path, ROS2).member_of_groups == []
    assert parse_manifest(path, {"ROS_VERSION": "1"}).member_of_groups == ["fmt_group"]


def test_missing_format_is_1_and_whitespace_is_normalised(tmp_path: Path) -> None:
    path = write(tmp_path, "<name>\n  spaced\n</name><version> 1.0.0 </version>"
                           "<description>two\n   lines</description>", fmt="")
    manifest = parse_manifest(path, ROS2)
    assert (manifest.format, manifest.name, manifest.version) == (1, "spaced", "1.0.0")
    assert manifest.description == "two lines"


def test_comments_are_ignored(tmp_path: Path) -> None:
    path = write(tmp_path, HEADER + "<!-- <depend>commented</depend> --><depend>real</depend>")
    assert [d.name for d in parse_manifest(path, ROS2).dependencies] == ["real"]


@pytest.mark.parametrize("body, fmt, message", [
    ("<version>1.0.0</version>", ' format="3"', r"package\.xml:2: <package> has no <name>"),
    ("<name>p</name>", ' format="3"', r"has no <version>"),
    (HEADER, ' format="4"', r"unsupported package format '4'"),
    (HEADER + "<run_depend>x</run_depend>", ' format="2"', r":3: <run_depend> is not allowed in package format 2"),
    (HEADER + "<group_depend>g</group_depend>", ' format="2"', r"<group_depend> is not allowed in package format 2"),
    (HEADER + "<exec_depend>  </exec_depend>", ' format="3"', r"<exec_depend> is empty"),
    (HEADER + '<depend condition="$X ==">x</depend>', ' format="3"', r"invalid condition attribute"),
    (HEADER + "<export><build_type>cmake</build_type><build_type>ament_cmake</build_type></export>", ' format="3"',
     r"more than one <build_type> applies"),
])
def test_invalid_manifests(tmp_path: Path, body: str, fmt: str, message: str) -> None:
    with pytest.raises(ManifestError, match=message):
        parse_manifest(write(tmp_path, body, fmt), ROS2)


def test_malformed_xml_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "package.xml"
    path.write_text('<package format="3">\n<name>p</name>\n<depend>x</dpend>\n</package>\n')
    with pytest.raises(ManifestError) as error:
        parse_manifest(path, ROS2)
    assert (error.value.path, error.value.line) == (str(path), 3)
    assert str(error.value).startswith(f"{path}:3: malformed XML:")


def test_root_must_be_package(tmp_path: Path) -> None:
    path = tmp_path / "package.xml"
    path.write_text("<manifest><name>p</name></manifest>")
    with pytest.raises(ManifestError, match="the root element is <manifest>"):
        parse_manifest(path, ROS2)


@pytest.mark.skipif(importlib.util.find_spec("catkin_pkg") is None,
                    reason="catkin_pkg (from colcon-ros) is not installed")
@pytest.mark.filterwarnings("ignore::DeprecationWarning")
def test_real_manifests_agree_with_catkin_pkg() -> None:
    """Every installed ROS 2 manifest: roc's categories are those colcon-ros builds from catkin_pkg."""
    from catkin_pkg.package import parse_package

    manifests = sorted(Path(sys.prefix, "share").glob("*/package.xml"))
    if len(manifests) < 20:
        pytest.skip("the ROS 2 packages are not installed in this environment")
    for path in manifests:
        reference = parse_package(str(path), warnings=[])
        reference.evaluate_conditions(ROS2)
        names = {
            "build": reference.build_depends + reference.buildtool_depends,
            "run": reference.build_export_depends + reference.buildtool_export_depends + reference.exec_depends,
            "test": reference.test_depends,
        }
        expected = {c: sorted({d.name for d in deps if d.evaluated_condition}) for c, deps in names.items()}
        manifest = parse_manifest(path, ROS2)
        assert categories(path) == expected, path
        assert (manifest.name, manifest.version, manifest.build_type) == (
            reference.name, reference.version, reference.get_build_type()), path
        assert manifest.group_depends == [g.name for g in reference.group_depends if g.evaluated_condition], path
