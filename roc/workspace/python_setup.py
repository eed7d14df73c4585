"""Read a Python package's name and requirements from setup.cfg / setup.py without running it.

colcon runs every setup.py in a subprocess to learn its name; roc reads the file statically and only
runs it when the name is computed at run time.
"""

from __future__ import annotations

import ast
import configparser
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

from roc.errors import ManifestError

_REQUIREMENT_NAME = re.compile(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)")
# setup() keyword -> dependency category, as colcon maps them.
REQUIREMENT_CATEGORIES = {"setup_requires": "build", "install_requires": "run", "tests_require": "test"}
TEST_EXTRAS = ("test", "tests", "testing")


@dataclass
class PythonProject:
    name: str | None
    version: str | None = None
    maintainers: list[str] = field(default_factory=list)
    dependencies: dict[str, set[str]] = field(default_factory=dict)


def requirement_name(requirement: str) -> str | None:
    match = _REQUIREMENT_NAME.match(requirement)
    return match.group(1) if match else None


def _requirements(value) -> list[str]:
    if isinstance(value, str):
        value = value.replace(";", "\n").splitlines() if "\n" in value else [value]
    return [name for item in value or [] if (name := requirement_name(str(item)))]


def read_setup_cfg(setup_cfg: Path) -> PythonProject | None:
    """The project in setup.cfg, or None when it does not name one."""
    parser = configparser.ConfigParser(interpolation=None)
    try:
        parser.read(setup_cfg, encoding="utf-8")
    except configparser.Error as error:
        raise ManifestError(str(setup_cfg), f"malformed setup.cfg: {error}".splitlines()[0]) from None
    name = parser.get("metadata", "name", fallback="").strip()
    if not name:
        return None
    project = PythonProject(name=name, version=parser.get("metadata", "version", fallback=None))
    for key, category in REQUIREMENT_CATEGORIES.items():
        text = parser.get("options", key, fallback="")
        project.dependencies.setdefault(category, set()).update(_requirements(text.strip().splitlines()))
    if parser.has_section("options.extras_require"):
        for extra in TEST_EXTRAS:
            text = parser.get("options.extras_require", extra, fallback="")
            project.dependencies["test"].update(_requirements(text.strip().splitlines()))
    for role in ("maintainer", "author"):
        name_value = parser.get("metadata", role, fallback="").strip()
        email = parser.get("metadata", f"{role}_email", fallback="").strip()
        if email:
            project.maintainers.append(f"{name_value} <{email}>" if name_value else email)
    return project


def setup_cfg_is_sufficient(setup_py: Path) -> bool:
    """colcon reads only setup.cfg when setup.py calls setup() without arguments (or only cmdclass)."""
    content = setup_py.read_text(errors="replace")
    return "setup()" in content or "setup(cmdclass=cmdclass)" in content


def read_setup_py(setup_py: Path) -> PythonProject:
    """The setup() arguments of setup.py, read statically; runs the file only for a computed name."""
    try:
        tree = ast.parse(setup_py.read_bytes(), filename=str(setup_py))
    except SyntaxError as error:
        raise ManifestError(str(setup_py), f"invalid Python: {error.msg}", error.lineno) from None
    constants = _module_constants(tree)
    call = _find_setup_call(tree)
    keywords = {k.arg: k.value for k in call.keywords if k.arg} if call else {}
    name = _literal(keywords.get("name"), constants)
    if not isinstance(name, str):
        name = _run_setup_name(setup_py)
    project = PythonProject(name=name)
    version = _literal(keywords.get("version"), constants)
    project.version = version if isinstance(version, str) else None
    for key, category in REQUIREMENT_CATEGORIES.items():
        value = _literal(keywords.get(key), constants)
        project.dependencies.setdefault(category, set()).update(_requirements(value if value else []))
    return project


def _module_constants(tree: ast.Module) -> dict[str, object]:
    constants: dict[str, object] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            value = _literal(node.value, constants)
            if value is not None:
                constants[node.targets[0].id] = value
    return constants


def _find_setup_call(tree: ast.Module) -> ast.Call | None:
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", None)
            if name == "setup":
                return node
    return None


def _literal(node: ast.AST | None, constants: dict[str, object]):
    """The value of a literal expression (names of module constants resolved), else None."""
    if node is None:
        return None
    if isinstance(node, ast.Name):
        return constants.get(node.id)
    if isinstance(node, (ast.List, ast.Tuple)):
        items = [_literal(e, constants) for e in node.elts]
        return None if any(i is None for i in items) else items
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _literal(node.left, constants), _literal(node.right, constants)
        if type(left) is type(right) and isinstance(left, (str, list)):
            return left + right
        return None
    try:
        return ast.literal_eval(node)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return None


def _run_setup_name(setup_py: Path) -> str:
    try:
        result = subprocess.run(
            [sys.executable, "setup.py", "--name"], cwd=setup_py.parent, capture_output=True, text=True, timeout=60
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        raise ManifestError(str(setup_py), f"could not run it to learn the package name: {error}") from None
    lines = [line.strip() for line in result.stdout.splitlines() if line.strip()]
    if result.returncode != 0 or not lines:
        raise ManifestError(
            str(setup_py), "cannot determine the package name; pass name='...' to setup() or add a setup.cfg"
        )
    return lines[-1]
