"""The house's static checks, run by the test command: ruff (configured in pyproject.toml), mypy on roc/,
no import cycle between roc's modules (imports inside functions count), and no folder of roc/ with more
than 25 Python files."""

from __future__ import annotations

import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest
import tomllib
from helpers.build import REPO
from helpers.oracles import SHARED, require_oracle

BIN = Path(sys.executable).parent
MOST_FILES_IN_A_FOLDER = 25
# one worker for the whole file: test_each_check_can_fail puts a bad module into roc/ for a moment
pytestmark = pytest.mark.xdist_group("static_checks")


def _run(*command: str) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=300)


def test_ruff_finds_nothing() -> None:
    result = _run(str(BIN / "ruff"), "check", "--no-cache", ".")
    assert result.returncode == 0, result.stdout + result.stderr


def test_mypy_finds_nothing() -> None:
    result = _run(sys.executable, "-m", "mypy", "--cache-dir", str(REPO / ".mypy_cache"))
    assert result.returncode == 0, result.stdout + result.stderr


def test_mypy_finds_nothing_without_the_launch_system(tmp_path: Path) -> None:
    """The launch system (launch, launch_ros) is installed only where ../shared/oracles is, so a fresh
    clone may lack it: mypy passes either way. Here the modules of roc that import it are checked with its
    imports skipped, which is how mypy sees a package that is not installed (Any)."""
    settings = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["mypy"]
    config = tmp_path / "mypy.ini"
    config.write_text("\n".join(["[mypy]", *(f"{key} = {value}" for key, value in settings.items() if key != "files"),
                                 "[mypy-launch.*,launch_ros.*]", "follow_imports = skip", ""]))
    importers = [str(path.relative_to(REPO)) for path in sorted((REPO / "roc").rglob("*.py"))
                 if re.search(r"^\s*(from|import) launch(_ros)?[. ]", path.read_text(), re.MULTILINE)]
    assert "roc/launch/introspect.py" in importers
    result = _run(sys.executable, "-m", "mypy", "--config-file", str(config),
                  "--cache-dir", str(REPO / ".mypy_cache" / "without-launch"), *importers)
    assert result.returncode == 0, result.stdout + result.stderr


def test_no_import_cycle() -> None:
    tool = require_oracle("import cycle checker", SHARED / "tools" / "import_cycles.py")
    result = _run(sys.executable, str(tool), "roc", "--list")
    assert result.returncode == 0 and result.stdout.split()[:1] == ["0"], result.stdout + result.stderr


def test_no_folder_of_roc_holds_more_than_25_python_files() -> None:
    counts = Counter(path.parent.relative_to(REPO) for path in (REPO / "roc").rglob("*.py"))
    crowded = {str(folder): count for folder, count in counts.items() if count > MOST_FILES_IN_A_FOLDER}
    assert not crowded, f"split these folders into packages: {crowded}"


@pytest.mark.parametrize("check", [test_ruff_finds_nothing, test_mypy_finds_nothing])
def test_each_check_can_fail(tmp_path: Path, check) -> None:
    """A file with an unused import and a wrong type is found by both checkers."""
    bad = REPO / "roc" / "_static_checks_probe.py"
    bad.write_text('"""A probe."""\n\nimport os\n\nNUMBER: int = "one"\n')
    try:
        with pytest.raises(AssertionError):
            check()
    finally:
        bad.unlink()
