"""roc's distribution as users install it: its name, metadata and version source (pyproject.toml), the
dependencies that must leave colcon's and ROS's setuptools alone, and CHANGELOG.md. The wheel itself is
built, installed and smoke-tested outside the checkout by scripts/test_wheel.sh (.ci/run)."""

from __future__ import annotations

import re
from pathlib import Path

import tomllib
from packaging.requirements import Requirement
from packaging.version import Version

import roc

REPO = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]


def test_the_distribution_is_roc_ros2_and_the_command_roc() -> None:
    # roc on PyPI is an unrelated XMLRPC library (0.3.2): pip install roc installed the wrong thing
    assert PROJECT["name"] == "roc-ros2"
    assert "bin/roc" in tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["script-files"]


def test_the_metadata_is_complete_and_the_version_comes_from_the_tags() -> None:
    assert PROJECT["readme"] == "README.md" and PROJECT["license"] == "Apache-2.0"
    assert all((REPO / name).is_file() for name in PROJECT["license-files"])
    assert any(c.startswith("Topic :: ") for c in PROJECT["classifiers"])
    assert PROJECT["dynamic"] == ["version"] and "version" not in PROJECT
    build = tomllib.loads((REPO / "pyproject.toml").read_text())["build-system"]["requires"]
    assert any(Requirement(r).name == "setuptools-scm" for r in build)
    Version(roc.__version__)  # the installed one: PEP 440, from the tags (0.1.0.devN+g... before the first)


def test_no_dependency_forces_a_setuptools_colcon_or_jazzy_cannot_take() -> None:
    # grpcio-tools needs setuptools>=77; colcon-core needs <80 and Jazzy's own is 68.1.2
    names = {Requirement(r).name for r in PROJECT["dependencies"]}
    assert not names & {"grpcio-tools", "setuptools"}
    assert [Requirement(r).name for r in PROJECT["optional-dependencies"]["idl"]] == ["grpcio-tools"]


def test_the_changelog_lists_versions_newest_first() -> None:
    headings = re.findall(r"^## (\d+\.\d+\.\d+)\b", (REPO / "CHANGELOG.md").read_text(), flags=re.MULTILINE)
    assert headings and headings == sorted(headings, key=Version, reverse=True)
    assert Version(headings[0]) >= Version(Version(roc.__version__).base_version)


def test_the_python_it_asks_for_has_what_roc_imports() -> None:
    # roc reads roc.toml and [check] files with tomllib, new in Python 3.11
    assert PROJECT["requires-python"] == ">=3.11"
    assert "Programming Language :: Python :: 3.10" not in PROJECT["classifiers"]
