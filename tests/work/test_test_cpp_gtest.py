"""``roc work test`` on a C++ package whose gtest tests use rclcpp (the C++ stack built by roc,
tests/helpers/cpp.py), built in a workspace on top of the stack: the tests link rclcpp and run as
colcon's do, and the results in test-result are colcon's."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from helpers.build import BIN, ros_domain_id, ros_env
from helpers.cpp import require_stack, sourced

pytestmark = [pytest.mark.slow, pytest.mark.cpp, pytest.mark.colcon]

SLOT = 43  # the tests' nodes, in a domain of their own

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>cpp_node_tests</name>
  <version>0.1.0</version>
  <description>gtest tests of an rclcpp node</description>
  <maintainer email="dev@example.com">dev</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <depend>rclcpp</depend>
  <depend>std_msgs</depend>
  <test_depend>ament_cmake_gtest</test_depend>
  <export><build_type>ament_cmake</build_type></export>
</package>
"""
CMAKELISTS = """cmake_minimum_required(VERSION 3.8)
project(cpp_node_tests)
find_package(ament_cmake REQUIRED)
find_package(rclcpp REQUIRED)
find_package(std_msgs REQUIRED)
if(BUILD_TESTING)
  find_package(ament_cmake_gtest REQUIRED)
  ament_add_gtest(test_node test/test_node.cpp)
  target_link_libraries(test_node rclcpp::rclcpp ${std_msgs_TARGETS})
endif()
ament_package()
"""
TEST_SOURCE = """#include <gtest/gtest.h>
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/string.hpp>

class NodeTest : public ::testing::Test {
protected:
  static void SetUpTestCase() { rclcpp::init(0, nullptr); }
  static void TearDownTestCase() { rclcpp::shutdown(); }
};

TEST_F(NodeTest, node_has_its_name) {
  auto node = std::make_shared<rclcpp::Node>("tested");
  EXPECT_EQ(std::string(node->get_name()), "tested");
}

TEST_F(NodeTest, publisher_counts_no_subscriber) {
  auto node = std::make_shared<rclcpp::Node>("tested");
  auto publisher = node->create_publisher<std_msgs::msg::String>("unheard", 10);
  EXPECT_EQ(publisher->get_subscription_count(), 0u);
}

TEST_F(NodeTest, arithmetic_fails_on_purpose) {
  EXPECT_EQ(1 + 1, 3);
}
"""


def package(workspace: Path) -> Path:
    source = workspace / "src" / "cpp_node_tests"
    (source / "test").mkdir(parents=True)
    (source / "package.xml").write_text(PACKAGE_XML)
    (source / "CMakeLists.txt").write_text(CMAKELISTS)
    (source / "test" / "test_node.cpp").write_text(TEST_SOURCE)
    return workspace


def comparable(results: str) -> str:
    """test-result's lines with CTest's time-stamped folder made the same."""
    return re.sub(r"Testing/\d{8}-\d{4}/", "Testing/STAMP/", results)


def run(tool: str, *args: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / tool), *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


def test_gtest_tests_of_an_rclcpp_package_run_and_report_as_colcon_s(tmp_path: Path) -> None:
    require_stack()
    env = sourced(ros_env(ROS_DOMAIN_ID=ros_domain_id(SLOT), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST"))
    ours = package(tmp_path / "roc")
    theirs = tmp_path / "colcon"
    shutil.copytree(ours, theirs)
    built = run("roc", "work", "build", cwd=ours, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    tested = run("roc", "work", "test", cwd=ours, env=env)
    assert tested.returncode == 0, tested.stdout + tested.stderr
    assert "1 package had test failures: cpp_node_tests" in tested.stdout, tested.stdout

    assert run("colcon", "build", cwd=theirs, env=env).returncode == 0
    assert run("colcon", "test", cwd=theirs, env=env).returncode == 0
    expected = run("colcon", "test-result", "--all", cwd=theirs, env=env).stdout
    got = run("roc", "work", "test-result", "--all", cwd=ours, env=env).stdout
    assert "test_node.gtest.xml: 3 tests, 0 errors, 1 failure, 0 skipped" in expected  # and CTest's own file
    assert comparable(got) == comparable(expected)
    report = ours / "build" / "cpp_node_tests" / "test_results" / "cpp_node_tests" / "test_node.gtest.xml"
    assert 'name="arithmetic_fails_on_purpose"' in report.read_text()
