"""The setup scripts roc writes: readable by other users, and correct in paths with spaces and
non-ASCII characters under POSIX sh."""

from __future__ import annotations

import shlex
import stat
import subprocess

import pytest
from helpers.build import add_plain_package, roc


@pytest.mark.slow
def test_generated_files_are_readable_by_others(tmp_path):
    add_plain_package(tmp_path, "alpha")
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    for path in (tmp_path / "install" / "setup.sh", tmp_path / "install" / "alpha" / "share" / "alpha" / "package.sh"):
        assert stat.S_IMODE(path.stat().st_mode) & 0o044 == 0o044, path


@pytest.mark.slow
def test_posix_sh_with_spaces_and_non_ascii_in_the_path(tmp_path):
    ws = tmp_path / "my wörk $space"
    add_plain_package(ws, "alpha")
    assert roc("work", "build", cwd=ws).returncode == 0
    result = subprocess.run(["sh", "-c", f'. {shlex.quote(str(ws))}/install/setup.sh; echo "$CMAKE_PREFIX_PATH"'],
                            cwd=tmp_path,
                            capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"{ws}/install/alpha"
