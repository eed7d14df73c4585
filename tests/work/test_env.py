"""roc work env: a package's build environment, printed (only what the build changes, or --all) or
used to run a command, and evaluable by a shell."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from helpers.build import add_plain_package, roc, ros_env


def test_env_without_a_package_is_a_clear_usage_error(tmp_path: Path) -> None:
    result = roc("work", "env", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr == "roc: error: roc work env needs a package: roc work env PKG_NAME [-- CMD...] " \
                            "(see 'roc work env --help')\n"


@pytest.mark.slow
def test_env_prints_only_what_the_build_environment_changes(tmp_path: Path) -> None:
    add_plain_package(tmp_path, "alpha", None)
    add_plain_package(tmp_path, "beta", None, "find_package(alpha REQUIRED)\n")
    env = ros_env(OLDPWD="/somewhere/else", ROC_TEST_UNRELATED="1")
    assert roc("work", "build", cwd=tmp_path, env=env).returncode == 0
    env["OLDPWD"] = "/another/place"  # differs from the saved build environment: still not printed
    printed = roc("work", "env", "beta", cwd=tmp_path, env=env)
    assert printed.returncode == 0, printed.stderr
    names = [line.split("=", 1)[0] for line in printed.stdout.splitlines()]
    assert names == ["export CMAKE_PREFIX_PATH", "export PYTHONHASHSEED"], printed.stdout  # the fixed hash seed
    assert str(tmp_path / "install" / "alpha") in printed.stdout
    everything = roc("work", "env", "beta", "--all", cwd=tmp_path, env=env)
    assert "export PATH=" in everything.stdout and "export ROC_TEST_UNRELATED=1" in everything.stdout
    assert "export OLDPWD=/somewhere/else" in everything.stdout  # --all: the saved environment, as built
    # eval-ing the short form in the current environment gives the build environment's values
    evaluated = subprocess.run(["bash", "-c", 'eval "$1" && echo "$CMAKE_PREFIX_PATH|$PATH"', "_", printed.stdout],
                               capture_output=True, text=True, env=env)
    assert evaluated.stdout.strip() == f"{str(tmp_path / 'install' / 'alpha')}|{env['PATH']}"


def test_env_output_can_be_evaluated_with_exported_functions(tmp_path):
    add_plain_package(tmp_path, "alpha")
    assert roc("work", "build", cwd=tmp_path).returncode == 0
    env = {**ros_env(), "BASH_FUNC_f%%": "() {  :\n}"}
    printed = roc("work", "env", "alpha", "--all", cwd=tmp_path, env=env)
    assert printed.returncode == 0 and "BASH_FUNC" not in printed.stdout
    evaluated = subprocess.run(["bash", "-c", 'eval "$1" && echo ok', "_", printed.stdout], capture_output=True,
                               text=True)
    assert evaluated.stdout.strip() == "ok", evaluated.stderr
