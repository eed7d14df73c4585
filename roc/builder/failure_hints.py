"""How to go on after a CMake configure failed for a reason roc recognises in its error output.

CMake names what it could not find, never that only the tests need it, nor how to build without it:
- a test tool that is not installed: ament_lint_auto, ament_lint_common, an ``ament_cmake_<linter>``
  (CMake's "Could not find a package configuration file provided by ..."), the linter program such a
  package runs ("ament_cppcheck() could not find program 'ament_cppcheck'", as upstream interface
  packages' ``ADD_LINTER_TESTS`` ask for), or any other test-only dependency of the package;
- a package of the workspace that is not built (``--packages-select`` of a package whose dependency was
  never built).
"""

from __future__ import annotations

import re
from collections.abc import Collection

from roc.workspace.package import Package

# CMake's find_package error, in either of its wordings; the words may be wrapped onto new lines.
MISSING_PACKAGE = re.compile(r'package\s+configuration\s+file\s+provided\s+by\s+"([^"]+)"')
# ament_cmake_<linter>'s function when the linter itself (a Python package of the same name) is missing.
MISSING_PROGRAM = re.compile(r"ament_\w+\(\)\s+could\s+not\s+find\s+program\s+'(ament_\w+)'")
# ament's test tools, test dependencies or not: ament_lint_auto finds each test dependency itself, and
# rosidl's ADD_LINTER_TESTS finds linters the package does not declare.
TEST_TOOL = re.compile(r"ament_lint_\w+|ament_cmake_(copyright|cppcheck|cpplint|flake8|lint_cmake|mypy|pclint|pep257|"
                       r"pycodestyle|pyflakes|uncrustify|xmllint|clang_format|clang_tidy|gtest|gmock|google_benchmark|"
                       r"pytest)")
WITHOUT_TESTS = "build without tests (--cmake-args -DBUILD_TESTING=OFF)"


def _found(pattern: re.Pattern, output: str) -> list[str]:
    return list(dict.fromkeys(pattern.findall(output)))


def _installable(names: list[str], distribution: str | None) -> str:
    """The packages to install: by the name both Debian's ROS packages and ROS's PyPI wheels use."""
    if distribution is None:
        return " ".join(names)
    return " ".join(f"ros-{distribution}-{name.replace('_', '-')}" for name in names)


def failure_hint(output: str, package: Package, workspace: Collection[str], distribution: str | None) -> str:
    """What to do about ``package``'s failed configure, from its error ``output`` (stderr); '' when
    roc does not recognise the failure. ``workspace``: the workspace's package names; ``distribution``:
    the ROS 2 distribution (jazzy), which names the packages to install."""
    missing = _found(MISSING_PACKAGE, output)
    needed = package.dependencies.get("build", set()) | package.dependencies.get("run", set())
    test_only = package.dependencies.get("test", set()) - needed
    unbuilt = [name for name in missing if name in workspace]
    if unbuilt:
        hint = (f"{', '.join(unbuilt)} {'is' if len(unbuilt) == 1 else 'are'} in the workspace but not built: "
                f"build {'it' if len(unbuilt) == 1 else 'them'} too (--packages-up-to {package.name})")
        return hint + (f", or {WITHOUT_TESTS}" if set(unbuilt) <= test_only else "")
    tools = [name for name in missing if TEST_TOOL.fullmatch(name) or name in test_only]
    tools += [name for name in _found(MISSING_PROGRAM, output) if name not in tools]
    if not tools:
        return ""
    what = f"the test tool {tools[0]} is" if len(tools) == 1 else f"the test tools {', '.join(tools)} are"
    return f"{what} not installed: {WITHOUT_TESTS}, or install {_installable(tools, distribution)}"
