"""Reading a sqlite3 bag writes nothing beside it: roc bag info, and a bag as convert's input, leave
the bag's directory as it was (no -shm or -wal file, no byte changed), also for a file in
write-ahead-log mode (as rosbag2 writes them) and for a killed recording's log; and a bag in a
truly read-only place (another user's directory, a read-only mount) reads in full."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.build import BIN
from helpers.oracles import SHARED, require_oracle

TALKER = SHARED / "reference" / "rosbag2" / "rosbag2_py" / "test" / "resources" / "sqlite3" / "talker"
KILLED_WRITER = """
import os, signal, sys
from roc.bag.definitions import definition
from roc.bag.metadata import Topic
from roc.bag.qos import default_profile
from roc.bag.writer import BagWriter, WriteOptions
writer = BagWriter(sys.argv[1], WriteOptions(storage="sqlite3"))
writer.add_topic(Topic("/count", "std_msgs/msg/Int32", "cdr", [default_profile()]), definition("std_msgs/msg/Int32"))
for index in range(25):
    writer.write("/count", bytes([0, 1, 0, 0, index, 0, 0, 0]), 1_700_000_000_000_000_000 + index)
writer.flush()
os.kill(os.getpid(), signal.SIGKILL)
"""


def state(directory: Path) -> dict[str, tuple[int, int, bytes]]:
    """Every file below ``directory`` with its size, modification time and content."""
    return {str(p.relative_to(directory)): (p.stat().st_size, p.stat().st_mtime_ns, p.read_bytes())
            for p in sorted(directory.rglob("*")) if p.is_file()}


def info(bag: Path, *prefix: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([*prefix, str(BIN / "roc"), "bag", "info", str(bag), "--format", "json"],
                          capture_output=True, text=True, timeout=120, env=env or dict(os.environ))


@pytest.fixture
def talker(tmp_path) -> Path:
    """rosbag2's talker bag (its .db3 in write-ahead-log mode) in a folder of its own."""
    require_oracle("rosbag2 reference bags", TALKER)
    bag = tmp_path / "talker"
    bag.mkdir()
    for name in ("metadata.yaml", "talker.db3"):  # (a reader of the shared copy may have left more)
        shutil.copy(TALKER / name, bag / name)
    assert (bag / "talker.db3").read_bytes()[18:20] == b"\x02\x02"  # write-ahead-log mode
    return bag


@pytest.fixture
def killed(tmp_path) -> Path:
    """A sqlite3 recording killed after its last commit: 25 messages in its write-ahead log only."""
    bag = tmp_path / "killed"
    subprocess.run([sys.executable, "-c", KILLED_WRITER, str(bag)], timeout=60)
    assert (bag / "killed_0.db3-wal").stat().st_size > 0 and not (bag / "metadata.yaml").exists()
    return bag


@pytest.mark.parametrize("what", ["directory", "file"])
def test_info_of_a_write_ahead_log_bag_leaves_nothing_beside_it(talker, what):
    before = state(talker)
    result = info(talker if what == "directory" else talker / "talker.db3")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["message_count"] == 20
    assert state(talker) == before


def test_convert_reads_its_input_without_writing_beside_it(talker, tmp_path):
    before = state(talker)
    options = tmp_path / "out.yaml"
    options.write_text(f"output_bags:\n- uri: {tmp_path / 'out'}\n  all_topics: true\n")
    result = subprocess.run([str(BIN / "roc"), "bag", "convert", "-i", str(talker), "-o", str(options)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert state(talker) == before


def test_a_killed_recordings_log_is_read_without_its_index(killed):
    (killed / "killed_0.db3-shm").unlink()  # e.g. a bag copied without it
    before = state(killed)
    result = info(killed)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["message_count"] == 25
    assert state(killed) == before


def _read_only(directory: Path) -> list[str]:
    """A command prefix that runs roc where ``directory`` cannot be written: bind-mounted read-only
    over itself in a mount namespace of its own (as root, whom file modes do not stop), else mode 0555."""
    if os.geteuid() != 0:
        directory.chmod(0o555)
        return []
    probe = subprocess.run(["unshare", "-m", "true"], capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.skip(f"root without a mount namespace of its own: {probe.stderr.strip()}")
    return ["unshare", "-m", "--propagation", "private", "sh", "-c",
            f'mount --bind -o ro "{directory}" "{directory}" && ! touch "{directory}/x" 2>/dev/null && exec "$@"',
            "sh"]


@pytest.mark.parametrize("bag", ["talker", "killed", "killed_with_index"])
def test_a_bag_in_a_read_only_place_reads_in_full(request, tmp_path, bag):
    directory = request.getfixturevalue(bag.removesuffix("_with_index"))
    if bag == "killed":
        (directory / "killed_0.db3-shm").unlink()
    before = state(directory)
    try:
        result = info(directory, *_read_only(directory))
    finally:
        directory.chmod(0o755)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["message_count"] == (20 if bag == "talker" else 25)
    assert state(directory) == before


def test_a_plain_read_only_connection_would_leave_files(killed):
    """The control: sqlite's mode=ro alone does leave an index beside a write-ahead-log file."""
    import sqlite3

    (killed / "killed_0.db3-shm").unlink()
    with sqlite3.connect(f"file:{killed / 'killed_0.db3'}?mode=ro", uri=True) as database:
        assert database.execute("SELECT COUNT(*) FROM messages").fetchone() == (25,)
    assert (killed / "killed_0.db3-shm").exists()
