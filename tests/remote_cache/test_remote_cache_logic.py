"""Fast unit tests of the remote cache's logic: settings, keys, entries, archives, the engine's restore
step and the console's lines. The servers themselves are in tests/remote_cache/test_remote_cache.py."""

from __future__ import annotations

import io
import json
import os
import tarfile
from pathlib import Path

import pytest

from roc.builder.artefact import Places, unpack
from roc.engine.events import RunFinished, TaskFinished, TaskQueued, TaskRestoring, TaskStarted, TaskWarning, Tick
from roc.engine.executor import execute
from roc.engine.ready import Task
from roc.errors import UsageError
from roc.handlers.console import ConsoleHandler
from roc.remote_cache.cache import RemoteCache, _read_entry
from roc.remote_cache.keys import RemoteKeys, placed_key, tool_content
from roc.remote_cache.settings import redact, remote_settings
from roc.workspace.package import Package


def test_settings_modes_environment_and_bad_values(monkeypatch) -> None:
    monkeypatch.delenv("ROC_REMOTE_CACHE", raising=False)
    monkeypatch.delenv("ROC_REMOTE_CACHE_MODE", raising=False)
    assert remote_settings(None, None, None) is None
    settings = remote_settings("http://cache:8080/roc/", None, None)
    assert settings and settings.mode == "read" and not settings.writes and settings.url == "http://cache:8080/roc"
    assert remote_settings("http://cache/roc", "off", None) is None
    monkeypatch.setenv("ROC_REMOTE_CACHE", "s3://bucket/prefix")
    monkeypatch.setenv("ROC_REMOTE_CACHE_MODE", "read-write")
    from_env = remote_settings(None, None, 2.5)
    assert from_env and from_env.url == "s3://bucket/prefix" and from_env.writes and from_env.timeout == 2.5
    for url, mode, timeout, message in (("ftp://x/y", None, None, "not an http://"), ("http://x", "write", None,
                                        "not one of read, read-write, off"), ("http://x", None, 0, "more than 0")):
        with pytest.raises(UsageError, match=message):
            remote_settings(url, mode, timeout)


def test_credentials_never_shown() -> None:
    assert redact("https://user:secret@cache.example:8443/roc?token=abc") == "https://cache.example:8443/roc"
    settings = remote_settings("http://me:pw@127.0.0.1:1/roc", None, None)
    assert settings and "pw" not in settings.shown and "me" not in settings.shown


def test_tool_identity_is_by_content_not_by_place_or_time(tmp_path) -> None:
    one, two, three = tmp_path / "one", tmp_path / "two", tmp_path / "three"
    for folder, content in ((one, b"compiler v1"), (two, b"compiler v1"), (three, b"compiler v2")):
        folder.mkdir()
        (folder / "cc").write_bytes(content)
        (folder / "cc").chmod(0o755)
    os.utime(two / "cc", (1, 1))
    assert tool_content("cc", str(one)) == tool_content("cc", str(two)) != tool_content("cc", str(three))


def _parts(**changes) -> dict:
    parts = {"sources": {"a.c": "x:0"}, "options": {"merge-install": False}, "toolchain": {"variable CC": None},
             "dependencies": {}, "underlay": {}}
    parts.update(changes)
    return parts


def test_remote_keys_follow_dependencies_and_need_their_keys(tmp_path) -> None:
    keys = RemoteKeys({"PATH": ""}, [], tmp_path)
    base = keys.key("base", _parts())
    top = keys.key("top", _parts(dependencies={"base": "local fingerprint"}))
    assert base and top and base != top
    other = RemoteKeys({"PATH": ""}, [], tmp_path)
    other.key("base", _parts(sources={"a.c": "y:0"}))
    assert other.key("top", _parts(dependencies={"base": "local fingerprint"})) != top  # a dependency changed
    merged = RemoteKeys({"PATH": ""}, [], tmp_path).key("base", _parts(options={"merge-install": True}))
    assert merged != base  # the layout is part of the key
    lonely = RemoteKeys({"PATH": ""}, [], tmp_path)
    assert lonely.key("top", _parts(dependencies={"never_built": None})) is None
    assert lonely.missing_dependency(_parts(dependencies={"never_built": None})) == "never_built"
    places = Places(Path("/a"), Path("/a/build"), Path("/a/install"))
    assert placed_key(base, places) != placed_key(base, Places(Path("/b"), Path("/b/build"), Path("/b/install")))


def test_entries_are_checked_before_use(tmp_path) -> None:
    good = {"format": 1, "sha256": "a" * 64, "size": 10,
            "built_at": {"workspace": "/w", "build_base": "/w/build", "install_base": "/w/install"}}
    path = tmp_path / "entry"
    path.write_text(json.dumps(good))
    assert _read_entry(path) == good
    for bad, problem in (('{"format": 1, "sha2', "not JSON"), (json.dumps({**good, "format": 99}), "another format"),
                         (json.dumps({**good, "sha256": "../../etc"}), "malformed"),
                         (json.dumps({**good, "built_at": {**good["built_at"], "workspace": "w"}}), "malformed")):
        path.write_text(bad)
        assert problem in str(_read_entry(path))


def _archive(path: Path, members: dict[str, bytes], links: dict[str, str] | None = None) -> Path:
    with tarfile.open(path, "w:gz") as tar:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
        for name, target in (links or {}).items():
            info = tarfile.TarInfo(name)
            info.type, info.linkname = tarfile.SYMTYPE, target
            tar.addfile(info)
    return path


@pytest.mark.parametrize("members, links, problem", [
    ({"install/pkg/../../escaped": b"x"}, None, "outside"),
    ({"install/other/file": b"x"}, None, "outside the package's install"),
    ({"build/other/roc_state.json": b"{}"}, None, "outside"),
    ({"/etc/passwd": b"x"}, None, "outside"),
    ({"install/pkg/share/pkg/x": b"x"}, {"install/pkg/lib/evil": "/etc/passwd"}, "unreadable"),
])
def test_unpacking_refuses_paths_that_leave_the_package(tmp_path, members, links, problem) -> None:
    places = Places(tmp_path, tmp_path / "build", tmp_path / "install")
    archive = _archive(tmp_path / "a.tar.gz", members, links)
    package = Package(name="pkg", path=Path("src/pkg"), type="cmake")
    reason = unpack(archive, package, places, places, merged=False)
    assert reason and problem in reason
    assert not (tmp_path / "install" / "pkg").exists() and not (tmp_path / "escaped").exists()


class _Context:
    def __init__(self):
        self.name, self.kind, self.events = "pkg", "build", []

    def emit(self, event):
        self.events.append(event)


class _DownStore:
    def get(self, path, destination):
        from roc.remote_cache.store import StoreUnavailable

        raise StoreUnavailable("connection refused")


def test_a_server_that_fails_warns_once_and_is_not_asked_again(tmp_path) -> None:
    settings = remote_settings("http://127.0.0.1:1/x", None, None)
    assert settings
    cache = RemoteCache(settings, Places(tmp_path, tmp_path / "build", tmp_path / "install"), False, _DownStore())
    package = Package(name="pkg", path=Path("src/pkg"), type="cmake")
    first, second = _Context(), _Context()
    assert "unavailable (connection refused)" in str(cache.restore(package, "k" * 64, first))
    assert "unavailable" in str(cache.restore(package, "k" * 64, second))
    assert [type(e) for e in first.events] == [TaskWarning] and second.events == []


def _run(task: Task) -> list:
    seen: list = []
    execute([task], [lambda e: None if isinstance(e, Tick) else seen.append(e)], workers=1)
    return seen


def test_engine_restore_hit_skips_the_action_and_a_miss_adds_its_reason() -> None:
    ran: list[str] = []
    hit = _run(Task("a", set(), lambda context: ran.append("a"), check=lambda: ["never built"],
                    restore=lambda context: None))
    assert [type(e) for e in hit] == [TaskQueued, TaskRestoring, TaskFinished, RunFinished]
    assert hit[2].restored and ran == []
    miss = _run(Task("b", set(), lambda context: ran.append("b"), check=lambda: ["never built"],
                     restore=lambda context: "not in the remote cache"))
    started = next(e for e in miss if isinstance(e, TaskStarted))
    assert started.reasons == ("never built", "not in the remote cache") and ran == ["b"]

    def broken(context):
        raise OSError("disk full")

    failed = _run(Task("c", set(), lambda context: ran.append("c"), check=lambda: ["x"], restore=broken))
    assert "restore failed: OSError: disk full" in next(e for e in failed if isinstance(e, TaskStarted)).reasons
    assert ran == ["b", "c"]


def test_console_prints_restored_packages_and_counts_them(capsys) -> None:
    stream = io.StringIO()
    console = ConsoleHandler(stream)
    for event in (TaskQueued("a"), TaskQueued("b"), TaskQueued("c"), TaskRestoring("a"),
                  TaskFinished("a", duration=0.4, restored=True), TaskStarted("b"), TaskFinished("b", duration=2.0),
                  TaskFinished("c", cached=True), TaskWarning("b", message="remote cache x: down"),
                  RunFinished("")):
        console(event)
    text = stream.getvalue()
    assert "Restored <<< a [from cache, 0.40s]" in text and "Starting >>> a" not in text
    assert "3 packages finished" in text and "(1 built, 1 restored from the remote cache, 1 up to date)" in text
    assert "roc: warning: b: remote cache x: down" in capsys.readouterr().err


def test_compiler_cache_settings(tmp_path, monkeypatch) -> None:
    from roc.builder.compiler_cache import compiler_cache

    tools = tmp_path / "bin"
    tools.mkdir()
    for name in ("ccache", "sccache"):
        (tools / name).write_text("#!/bin/sh\n")
        (tools / name).chmod(0o755)
    monkeypatch.setenv("PATH", str(tools))
    monkeypatch.setenv("AWS_ENDPOINT_URL", "http://127.0.0.1:9000")
    monkeypatch.delenv("AWS_REGION", raising=False)
    monkeypatch.delenv("AWS_DEFAULT_REGION", raising=False)
    root = tmp_path / "ws"
    assert compiler_cache("none", None, root, root / "build") is None
    read = remote_settings("https://u:p@cache.example/team", None, None)
    ccache = compiler_cache("ccache", "cache-dir", root, root / "build", read)
    assert ccache and ccache.cmake_arguments() == [f"-DCMAKE_C_COMPILER_LAUNCHER={tools}/ccache",
                                                   f"-DCMAKE_CXX_COMPILER_LAUNCHER={tools}/ccache"]
    assert ccache.environment == {"CCACHE_BASEDIR": str(root), "CCACHE_DIR": str(Path("cache-dir").absolute()),
                                  "CCACHE_STATSLOG": str(root / "build" / "ccache-stats.log"),
                                  "CCACHE_REMOTE_STORAGE": "https://cache.example/team/ccache|read-only"}
    sccache = compiler_cache("sccache", None, root, root / "build", read)
    assert sccache and sccache.environment["SCCACHE_WEBDAV_ENDPOINT"] == "https://cache.example/team"
    assert sccache.environment["SCCACHE_WEBDAV_RW_MODE"] == "READ_ONLY"
    assert len(sccache.environment["SCCACHE_SERVER_UDS"]) < 100 and "p" not in sccache.environment.get(
        "SCCACHE_WEBDAV_PASSWORD", "")
    s3 = compiler_cache("sccache", None, root, root / "build", remote_settings("s3://bucket/ci", "read-write", None))
    assert s3 and {k: v for k, v in s3.environment.items() if k.startswith("SCCACHE_") and "UDS" not in k
                   and "BASEDIRS" not in k} == {
        "SCCACHE_BUCKET": "bucket", "SCCACHE_S3_KEY_PREFIX": "ci/sccache", "SCCACHE_S3_RW_MODE": "READ_WRITE",
        "SCCACHE_REGION": "auto", "SCCACHE_ENDPOINT": "127.0.0.1:9000", "SCCACHE_S3_USE_SSL": "false"}
    monkeypatch.setenv("PATH", str(tmp_path / "nothing"))
    with pytest.raises(UsageError, match="'sccache' is not on PATH; install it"):
        compiler_cache("sccache", None, root, root / "build")


def test_which_paths_make_a_package_depend_on_its_place(tmp_path) -> None:
    from roc.builder.artefact import path_dependent_file

    places = Places(tmp_path, tmp_path / "build", tmp_path / "install")
    lib = places.install_base / "pkg" / "lib"
    lib.mkdir(parents=True)
    debug_only = lib / "libdebug.so"
    debug_only.write_bytes(b"\x7fELF\0\0" + str(places.build_base / "pkg" / "gen.c").encode())  # __FILE__
    header_code = lib / "libheader.so"  # __FILE__ of a dependency's inline code, isolated and merged
    header_code.write_bytes(b"\x7fELF\0\0" + str(places.install_base / "dep" / "include" / "dep" / "x.hpp").encode()
                            + b"\0" + str(places.install_base / "include" / "y.hpp").encode())
    archive = lib / "libstatic.a"
    archive.write_bytes(b"!<arch>\n" + str(tmp_path / "src" / "pkg" / "a.c").encode())
    manifest = places.install_base / "pkg" / "share" / "pkg" / "install_manifest.txt"
    manifest.parent.mkdir(parents=True)
    manifest.write_text(str(places.install_base / "pkg" / "lib" / "libdebug.so") + "\n")  # rewritten on unpack
    files = [debug_only, header_code, archive, manifest]
    assert path_dependent_file(files, places.install_base, places) is None
    rpath = lib / "librpath.so"
    rpath.write_bytes(b"\x7fELF\0\0" + str(lib).encode())  # the install path in a binary: it matters
    assert path_dependent_file([*files, rpath], places.install_base, places) == "pkg/lib/librpath.so"
    data_path = lib / "libdata.so"  # a path to installed data, beside a header's: it matters
    data_path.write_bytes(b"\x7fELF\0\0" + str(places.install_base / "dep" / "include" / "x.hpp").encode()
                          + b"\0" + str(places.install_base / "pkg" / "share" / "pkg" / "include").encode())
    assert path_dependent_file([*files, data_path], places.install_base, places) == "pkg/lib/libdata.so"
    config = places.install_base / "pkg" / "share" / "pkg" / "where.txt"
    config.write_text(f"sources at {tmp_path / 'src'}\n")  # any path in another text file matters
    assert path_dependent_file([*files, config], places.install_base, places) == "pkg/share/pkg/where.txt"


@pytest.mark.parametrize("arguments, message", [
    (["--remote-cache", "ftp://cache/x"], "--remote-cache: 'ftp://cache/x' is not an http://, https:// or s3://BUCKET"),
    (["--remote-cache", "http://u:secret@cache/x", "--remote-cache-timeout", "0"], "more than 0 seconds"),
    (["--compiler-cache", "ccache"], "--compiler-cache ccache: 'ccache' is not on PATH; install it"),
])
def test_bad_settings_are_usage_errors_before_anything_is_written(tmp_path, arguments, message) -> None:
    from helpers.build import roc, ros_env

    (tmp_path / "src" / "pkg").mkdir(parents=True)
    (tmp_path / "src" / "pkg" / "CMakeLists.txt").write_text("cmake_minimum_required(VERSION 3.14)\nproject(pkg)\n")
    (tmp_path / "empty").mkdir()
    env = ros_env(PATH=str(tmp_path / "empty"))  # no ccache; refused before anything runs
    result = roc("work", "build", *arguments, cwd=tmp_path, env=env)
    assert result.returncode == 2 and result.stderr.startswith("roc: error: ") and message in result.stderr
    assert "secret" not in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "build").exists() and not (tmp_path / "install").exists()


def test_byte_code_is_compiled_again_for_the_place_it_is_restored_at(tmp_path) -> None:
    """A package restored at another path keeps the byte-code caches a local build leaves, each naming
    its source where it is now (as the build's optimisation level and invalidation mode made it)."""
    import importlib.util
    import marshal
    import py_compile
    import sys

    from roc.builder.artefact import pack

    built, here = (Places(tmp_path / ws, tmp_path / ws / "build", tmp_path / ws / "install") for ws in ("a", "b"))
    module = built.install_base / "pkg" / "lib" / "site-packages" / "mod.py"
    module.parent.mkdir(parents=True)
    module.write_text("WHERE = __file__\n")
    flags = {py_compile.PycInvalidationMode.TIMESTAMP: 0, py_compile.PycInvalidationMode.CHECKED_HASH: 3}  # PEP 552
    caches = {py_compile.compile(str(module), optimize=level, invalidation_mode=mode, doraise=True): flags[mode]
              for level, mode in enumerate(flags)}
    (built.install_base / "pkg" / "lib" / "site-packages" / "__pycache__" / "other.cpython-20.pyc").write_bytes(b"x")
    archive = tmp_path / "pkg.tar.gz"
    pack(archive, "pkg", built, merged=False)
    package = Package(name="pkg", path=Path("src/pkg"), type="cmake")
    assert unpack(archive, package, built, here, merged=False) is None
    restored = here.install_base / "pkg" / "lib" / "site-packages"
    assert sorted(p.name for p in (restored / "__pycache__").iterdir()) == sorted(Path(c).name for c in caches)
    for cache, flag in caches.items():
        data = (restored / "__pycache__" / Path(cache).name).read_bytes()
        assert data[:4] == importlib.util.MAGIC_NUMBER and int.from_bytes(data[4:8], "little") == flag
        assert marshal.loads(data[16:]).co_filename == str(restored / "mod.py")
    assert sys.implementation.cache_tag in Path(next(iter(caches))).name


def test_an_archive_is_packed_at_gzips_default_level_not_its_slowest(tmp_path) -> None:
    """tarfile's level 9 took 3 to 4 times as long as gzip's default 6 for the same size (rclcpp)."""
    from roc.builder.artefact import pack

    built = Places(tmp_path, tmp_path / "build", tmp_path / "install")
    (built.install_base / "pkg" / "share").mkdir(parents=True)
    (built.install_base / "pkg" / "share" / "data.txt").write_text("some data\n" * 1000)
    archive = tmp_path / "pkg.tar.gz"
    pack(archive, "pkg", built, merged=False)
    header = archive.read_bytes()[:10]
    assert header[:3] == b"\x1f\x8b\x08" and header[8] == 0, header  # XFL: 2 is level 9, 4 is level 1
    with tarfile.open(archive) as tar:
        assert tar.getnames() == ["install/pkg/share/data.txt"]
