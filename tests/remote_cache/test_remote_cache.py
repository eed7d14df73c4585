"""The remote build cache end to end, against real servers on localhost: a WebDAV server (wsgidav on
cheroot, with basic authentication from a netrc file) and an S3-compatible one (moto's server).

A CI checkout builds read-write; developer checkouts at other paths restore from it and run what
they restored. Damaged entries, a server that is down or hangs, and two writers at once fall back to
building locally.
"""

from __future__ import annotations

import json
import os
import shutil
import threading

import pytest
from helpers.build import FIXTURES, in_sourced_shell, roc, ros_env, without_suite_compiler_cache
from helpers.idl import CONVERT
from helpers.remote_servers import free_port, s3, silent_server, webdav

pytestmark = pytest.mark.slow

USER, PASSWORD = "ci-user", "s3cret-dav-pass"
RUN_ALL = ("install/app/lib/app/app; plain; install/pyp/lib/pyp/hello; "
           "python -c 'import pyp, sys; print(pyp.__file__)'")


def _events(ws) -> list[dict]:
    return [json.loads(line) for line in (ws / "log" / "latest_build" / "events.log").read_text().splitlines()]


def _started(ws) -> set[str]:
    return {e["task"] for e in _events(ws) if e["event"] == "TaskStarted"}


def _restored(ws) -> set[str]:
    return {e["task"] for e in _events(ws) if e["event"] == "TaskFinished" and e["restored"]}


def _checkout(base, name):
    """Sources only, as a fresh clone has them."""
    ws = base / name
    shutil.copytree(FIXTURES / "build_small" / "src", ws / "src")
    return ws


@pytest.fixture(scope="module")
def dav(tmp_path_factory):
    """A WebDAV server with basic authentication; credentials in a netrc file (never on the command
    line). Yields (url base without credentials, the server's root folder, environment)."""
    base = tmp_path_factory.mktemp("dav")
    root = base / "files"
    root.mkdir()
    netrc = base / "netrc"
    netrc.write_text(f"machine 127.0.0.1 login {USER} password {PASSWORD}\n")
    netrc.chmod(0o600)
    with webdav(root, USER, PASSWORD) as port:
        # no suite-wide ccache: its base directory would make the paths compiled into programs relative
        yield f"http://127.0.0.1:{port}", root, without_suite_compiler_cache(ros_env(NETRC=str(netrc)))


@pytest.fixture(scope="module")
def warm(dav, tmp_path_factory):
    """A CI checkout built read-write into ``<server>/main``."""
    url, root, env = dav
    ci = _checkout(tmp_path_factory.mktemp("ci"), "ci")
    built = roc("work", "build", "--remote-cache", f"{url}/main", "--remote-cache-mode", "read-write", cwd=ci,
                env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    assert len(list((root / "main" / "ac").iterdir())) == 4 and len(list((root / "main" / "cas").iterdir())) == 4
    return ci


@pytest.mark.distro
def test_fresh_checkout_elsewhere_restores_everything_and_runs(dav, warm, tmp_path):
    url, _, env = dav
    dev = _checkout(tmp_path / "another place", "dev checkout")  # another path, with spaces
    explained = roc("work", "build", "--explain", "--remote-cache", f"{url}/main", cwd=dev, env=env)
    assert explained.returncode == 0
    assert explained.stdout.count("in the remote cache") == 4 and "it would be restored" in explained.stdout
    built = roc("work", "build", "--remote-cache", f"{url}/main", cwd=dev, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    assert "Starting >>>" not in built.stdout and built.stdout.count("Restored <<< ") == 4
    assert "Restored <<< core [from cache, " in built.stdout
    assert "(0 built, 4 restored from the remote cache, 0 up to date)" in built.stdout
    assert _restored(dev) == {"app", "core", "plain", "pyp"} and _started(dev) == set()
    ran = in_sourced_shell(dev, RUN_ALL)
    assert ran.returncode == 0, ran.stderr
    assert "core says 42" in ran.stdout and "plain ok" in ran.stdout and "hello from pyp" in ran.stdout
    assert f"{dev}/install/pyp/lib/python3.11/site-packages/pyp/__init__.py" in ran.stdout
    assert str(warm) not in (dev / "install" / "core" / "share" / "core" / "package.sh").read_text()
    again = roc("work", "build", "--remote-cache", f"{url}/main", cwd=dev, env=env)
    assert "4 packages up to date" in again.stdout and _started(dev) == set()
    # one edit: that package (and its dependents) miss, say why, and build; the rest stays
    main = dev / "src" / "app" / "src" / "main.cpp"
    main.write_text(main.read_text() + "\n// edited\n")
    explained = roc("work", "build", "--explain", "--remote-cache", f"{url}/main", cwd=dev, env=env)
    assert "app: files changed: src/main.cpp; not in the remote cache (key " in explained.stdout
    rebuilt = roc("work", "build", "--remote-cache", f"{url}/main", cwd=dev, env=env)
    assert rebuilt.returncode == 0 and _started(dev) == {"app"}
    everything = "".join([explained.stdout, explained.stderr, built.stdout, built.stderr, rebuilt.stdout,
                          rebuilt.stderr, *(p.read_text() for p in (dev / "log").rglob("*.log") if p.is_file())])
    assert PASSWORD not in everything and USER not in everything


def _copy_entries(root, source: str, name: str):
    """Another cache prefix on the same server, holding the same entries (to damage)."""
    shutil.copytree(root / source, root / name)
    return root / name


def _entry(folder, package: str) -> tuple:
    for path in (folder / "ac").iterdir():
        entry = json.loads(path.read_text())
        if entry["package"] == package:
            return path, folder / "cas" / entry["sha256"]
    raise AssertionError(f"no entry for {package}")


@pytest.mark.parametrize("damage", ["partial archive", "corrupt archive", "partial entry"])
def test_damaged_entries_are_misses_with_a_warning(dav, warm, tmp_path, damage):
    url, root, env = dav
    prefix = damage.replace(" ", "-")
    folder = _copy_entries(root, "main", prefix)
    entry, archive = _entry(folder, "plain")
    if damage == "partial archive":
        archive.write_bytes(archive.read_bytes()[:200])
    elif damage == "corrupt archive":
        data = bytearray(archive.read_bytes())
        data[len(data) // 2] ^= 0xFF
        archive.write_bytes(bytes(data))
    else:
        entry.write_text(entry.read_text()[:40])
    dev = _checkout(tmp_path, "dev")
    built = roc("work", "build", "--remote-cache", f"{url}/{prefix}", cwd=dev, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    assert _started(dev) == {"plain"} and _restored(dev) == {"app", "core", "pyp"}
    assert "roc: warning: plain: remote cache" in built.stderr
    assert ("damaged" if damage == "partial entry" else "partial or corrupt") in built.stderr
    ran = in_sourced_shell(dev, "plain")
    assert ran.returncode == 0 and "plain ok" in ran.stdout


@pytest.mark.parametrize("server", ["down", "hanging"])
def test_unusable_server_builds_locally_with_one_warning(tmp_path, server):
    dev = _checkout(tmp_path, "dev")
    with silent_server() as hanging:
        port = free_port() if server == "down" else hanging
        built = roc("work", "build", "--remote-cache", f"http://127.0.0.1:{port}/x", "--remote-cache-timeout", "1",
                    cwd=dev)
    assert built.returncode == 0, built.stdout + built.stderr
    assert _started(dev) == {"app", "core", "plain", "pyp"}
    warnings = [line for line in built.stderr.splitlines() if "remote cache" in line]
    assert len(warnings) == 1, built.stderr
    assert ("connection refused" if server == "down" else "no answer within 1 s") in warnings[0]


def test_two_writers_at_once_then_a_reader_restores(dav, tmp_path):
    url, root, env = dav
    results = {}

    def build(name):
        ws = _checkout(tmp_path, name)
        results[name] = roc("work", "build", "--remote-cache", f"{url}/race", "--remote-cache-mode", "read-write",
                            cwd=ws, env=env)

    threads = [threading.Thread(target=build, args=(name,)) for name in ("job1", "job2")]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for result in results.values():
        assert result.returncode == 0 and "warning" not in result.stderr, result.stdout + result.stderr
    reader = _checkout(tmp_path, "reader")
    restored = roc("work", "build", "--remote-cache", f"{url}/race", cwd=reader, env=env)
    assert restored.returncode == 0 and _restored(reader) == {"app", "core", "plain", "pyp"}, restored.stderr


def test_read_mode_uploads_nothing_and_configuration_sources(dav, warm, tmp_path):
    url, root, env = dav
    dev = _checkout(tmp_path, "dev")
    (dev / "roc.toml").write_text(f'[build]\nremote-cache = "{url}/nowhere"\n')
    from_env = roc("work", "build", "--explain", cwd=dev, env={**env, "ROC_REMOTE_CACHE": f"{url}/main"})
    assert from_env.stdout.count("it would be restored") == 4  # the environment wins over roc.toml
    from_toml = roc("work", "build", "--explain", cwd=dev, env=env)
    assert from_toml.stdout.count("not in the remote cache") == 4
    off = roc("work", "build", "--explain", "--remote-cache-mode", "off", cwd=dev, env=env)
    assert "remote cache" not in off.stdout
    built = roc("work", "build", cwd=dev, env=env)  # read mode (the default): builds, uploads nothing
    assert built.returncode == 0 and not (root / "nowhere").exists()


def test_merged_layout(dav, tmp_path):
    url, root, env = dav
    ci = _checkout(tmp_path, "ci")
    built = roc("work", "build", "--merge-install", "--remote-cache", f"{url}/merged", "--remote-cache-mode",
                "read-write", cwd=ci, env=env)
    assert built.returncode == 0, built.stdout + built.stderr
    dev = _checkout(tmp_path / "elsewhere", "dev")
    restored = roc("work", "build", "--merge-install", "--remote-cache", f"{url}/merged", cwd=dev, env=env)
    assert restored.returncode == 0 and _restored(dev) == {"app", "core", "plain", "pyp"}, restored.stdout
    ran = in_sourced_shell(dev, "install/lib/app/app; plain; install/lib/pyp/hello")
    assert ran.returncode == 0, ran.stderr
    assert "core says 42" in ran.stdout and "plain ok" in ran.stdout and "hello from pyp" in ran.stdout
    # an isolated build never takes a merged entry (the layout is part of the key)
    isolated = _checkout(tmp_path, "isolated")
    explained = roc("work", "build", "--explain", "--remote-cache", f"{url}/merged", cwd=isolated, env=env)
    assert explained.stdout.count("not in the remote cache") == 4


PLACED_CMAKE = """cmake_minimum_required(VERSION 3.14)
project(placed NONE)
file(WRITE ${CMAKE_BINARY_DIR}/where.txt "${CMAKE_INSTALL_PREFIX}\\n")
install(FILES ${CMAKE_BINARY_DIR}/where.txt DESTINATION share/placed)
"""


def test_package_holding_its_prefix_is_restored_only_at_the_same_place(dav, tmp_path):
    url, root, env = dav

    def checkout(name):
        ws = tmp_path / name
        (ws / "src" / "placed").mkdir(parents=True)
        (ws / "src" / "placed" / "CMakeLists.txt").write_text(PLACED_CMAKE)
        return ws

    ci = checkout("ci")
    assert roc("work", "build", "--remote-cache", f"{url}/placed", "--remote-cache-mode", "read-write", cwd=ci,
               env=env).returncode == 0
    entry = json.loads(next((root / "placed" / "ac").iterdir()).read_text())
    assert entry["path_dependent"] == "placed/share/placed/where.txt"
    elsewhere = checkout("elsewhere")
    built = roc("work", "build", "--remote-cache", f"{url}/placed", cwd=elsewhere, env=env)
    assert built.returncode == 0 and _started(elsewhere) == {"placed"}
    where = elsewhere / "install" / "placed"
    assert (where / "share" / "placed" / "where.txt").read_text().strip() == str(where)
    shutil.rmtree(ci / "install")
    shutil.rmtree(ci / "build")
    again = roc("work", "build", "--remote-cache", f"{url}/placed", cwd=ci, env=env)
    assert again.returncode == 0 and _restored(ci) == {"placed"}, again.stdout + again.stderr


def test_s3_store(tmp_path):
    import boto3

    with s3() as port:
        env = ros_env(AWS_ENDPOINT_URL=f"http://127.0.0.1:{port}", AWS_ACCESS_KEY_ID="roc-test-key",
                      AWS_SECRET_ACCESS_KEY="roc-test-secret", AWS_DEFAULT_REGION="us-east-1")
        client = boto3.client("s3", endpoint_url=env["AWS_ENDPOINT_URL"], region_name="us-east-1",
                              aws_access_key_id="roc-test-key", aws_secret_access_key="roc-test-secret")
        client.create_bucket(Bucket="builds")
        ci = _checkout(tmp_path, "ci")
        built = roc("work", "build", "--remote-cache", "s3://builds/team/roc", "--remote-cache-mode", "read-write",
                    cwd=ci, env=env)
        assert built.returncode == 0, built.stdout + built.stderr
        keys = [o["Key"] for o in client.list_objects_v2(Bucket="builds")["Contents"]]
        assert len(keys) == 8 and all(k.startswith(("team/roc/ac/", "team/roc/cas/")) for k in keys)
        dev = _checkout(tmp_path / "elsewhere", "dev")
        restored = roc("work", "build", "--remote-cache", "s3://builds/team/roc", cwd=dev, env=env)
        assert restored.returncode == 0 and _restored(dev) == {"app", "core", "plain", "pyp"}, restored.stderr
        ran = in_sourced_shell(dev, RUN_ALL)
        assert ran.returncode == 0 and "core says 42" in ran.stdout, ran.stderr
        denied = _checkout(tmp_path, "denied")
        wrong = roc("work", "build", "--remote-cache", "s3://no-such-bucket/x", cwd=denied, env=env)
        assert wrong.returncode == 0 and _started(denied) == {"app", "core", "plain", "pyp"}
        assert wrong.stderr.count("remote cache") == 1 and "roc-test-secret" not in wrong.stdout + wrong.stderr
    assert os.environ.get("AWS_SECRET_ACCESS_KEY") != "roc-test-secret"


def test_generated_interface_package_restored_elsewhere_runs(dav, tmp_path):
    """A package with an idl task (protobuf sources): rosidl's generated code travels, and the
    conversion code its dependent uses runs at the new path."""
    url, _, env = dav
    ci, dev = tmp_path / "ci", tmp_path / "elsewhere" / "dev"
    for ws in (ci, dev):
        shutil.copytree(FIXTURES / "idl" / "src", ws / "src")
    built = roc("work", "build", "--remote-cache", f"{url}/idl", "--remote-cache-mode", "read-write", cwd=ci,
                env=env, timeout=900)
    assert built.returncode == 0, built.stdout + built.stderr
    restored = roc("work", "build", "--remote-cache", f"{url}/idl", cwd=dev, env=env)
    assert restored.returncode == 0, restored.stdout + restored.stderr
    reasons = [e["reasons"] for e in _events(dev) if e["event"] == "TaskStarted"]
    assert _restored(dev) == {"robot_proto_msgs", "robot_proto_tools"}, (reasons, restored.stderr)
    assert _started(dev) == {"robot_proto_msgs"}
    assert {e["kind"] for e in _events(dev) if e["event"] == "TaskStarted"} == {"idl"}  # only the generation ran
    (tmp_path / "convert.py").write_text(CONVERT)
    ran = in_sourced_shell(dev, f"python {tmp_path / 'convert.py'}")
    assert ran.returncode == 0 and ran.stdout.strip() == "x y theta", ran.stdout + ran.stderr
