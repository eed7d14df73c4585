"""Read a Python package's name and requirements from setup.cfg / setup.py without running it.

colcon runs every setup.py in a subprocess to learn its name and requirements; roc reads the file
statically and runs it only when one of the values it needs is computed at run time.
"""

from __future__ import annotations

import ast
import configparser
import json
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
SETUP_KEYWORDS = ("name", "version", *REQUIREMENT_CATEGORIES, "extras_require")


@dataclass
class PythonProject:
    name: str
    version: str | None = None
    maintainers: list[str] = field(default_factory=list)
    dependencies: dict[str, set[str]] = field(default_factory=dict)


def requirement_name(requirement: str) -> str | None:
    match = _REQUIREMENT_NAME.match(requirement)
    return match.group(1) if match else None


def _requirements(value) -> list[str]:
    """Package names of requirements given as a list or as one requirement a line."""
    if isinstance(value, str):
        value = value.splitlines()
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
    # The maintainers, else the authors, that have an email; both fields may list several, comma-separated.
    role = "maintainer" if parser.has_option("metadata", "maintainer") else "author"
    names = parser.get("metadata", role, fallback="")
    emails = parser.get("metadata", f"{role}_email", fallback="")
    if names and emails:
        project.maintainers = [
            f"{n.strip()} <{e.strip()}>" for n, e in zip(names.split(","), emails.split(","))
        ]
    return project


def setup_cfg_is_sufficient(setup_py: Path) -> bool:
    """colcon reads only setup.cfg when setup.py calls setup() without arguments (or only cmdclass)."""
    content = setup_py.read_text(errors="replace")
    return "setup()" in content or "setup(cmdclass=cmdclass)" in content


def read_setup_py(setup_py: Path) -> PythonProject:
    """The setup() arguments colcon uses, read statically; the file is run (as colcon always does) only
    when one of them is computed at run time."""
    try:
        tree = ast.parse(setup_py.read_bytes(), filename=str(setup_py))
    except SyntaxError as error:
        raise ManifestError(str(setup_py), f"invalid Python: {error.msg}", error.lineno) from None
    constants = _module_constants(tree)
    call = _find_setup_call(tree)
    arguments: dict[str, object] | None = None
    if call is not None and all(k.arg for k in call.keywords):  # no **kwargs
        given = {k.arg: k.value for k in call.keywords if k.arg in SETUP_KEYWORDS}
        arguments = {key: _literal(node, constants) for key, node in given.items()}
        if not isinstance(arguments.get("name"), str) or any(v is None for v in arguments.values()):
            arguments = None
    if arguments is None:
        arguments = _run_setup(setup_py)
    return _project(arguments)


def _project(arguments: dict[str, object]) -> PythonProject:
    version = arguments.get("version")
    project = PythonProject(name=str(arguments["name"]), version=version if isinstance(version, str) else None)
    for key, category in REQUIREMENT_CATEGORIES.items():
        project.dependencies[category] = set(_requirements(arguments.get(key)))
    extras = arguments.get("extras_require")
    if isinstance(extras, dict):
        for extra in TEST_EXTRAS:
            project.dependencies["test"].update(_requirements(extras.get(extra)))
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
    if isinstance(node, ast.Dict):
        keys = [_literal(k, constants) for k in node.keys]  # a None key is a ``**mapping``
        values = [_literal(v, constants) for v in node.values]
        return None if any(i is None for i in keys + values) else dict(zip(keys, values))
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _literal(node.left, constants), _literal(node.right, constants)
        if type(left) is type(right) and isinstance(left, (str, list)):
            return left + right
        return None
    try:
        return ast.literal_eval(node)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return None


# Runs setup.py with setup() replaced by a function that prints the arguments roc needs as JSON.
_CAPTURE_SETUP = """
import json, runpy, sys
import setuptools
captured = {}
def setup(**kwargs):
    captured.update(kwargs)
setuptools.setup = setup
try:
    import distutils.core
    distutils.core.setup = setup
except ImportError:
    pass
sys.argv = ["setup.py"]
runpy.run_path("setup.py", run_name="__main__")
print(json.dumps({key: captured.get(key) for key in %r}, default=str))
"""


def _run_setup(setup_py: Path) -> dict[str, object]:
    try:
        result = subprocess.run(
            [sys.executable, "-c", _CAPTURE_SETUP % (SETUP_KEYWORDS,)],
            cwd=setup_py.parent, capture_output=True, text=True, timeout=60,
        )
    except (OSError, subprocess.TimeoutExpired) as error:
        raise ManifestError(str(setup_py), f"could not run it to read its setup() arguments: {error}") from None
    lines = result.stdout.strip().splitlines()
    arguments = json.loads(lines[-1]) if result.returncode == 0 and lines else {}
    if not isinstance(arguments.get("name"), str):
        error_lines = result.stderr.strip().splitlines()
        detail = f" ({error_lines[-1]})" if error_lines else ""
        raise ManifestError(
            str(setup_py), f"cannot determine the package name{detail}; pass name='...' to setup() or add a setup.cfg"
        )
    return arguments
