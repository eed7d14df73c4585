"""The tests' ROS domains: one setting (ROC_TEST_DOMAIN_BASE) moves every domain the suite uses, and no
two slots or workers share one."""

from __future__ import annotations

import re

import pytest
from helpers.build import DOMAIN_MAX, DOMAIN_SLOTS, TESTS, ros_domain_id


def _domains(monkeypatch, base: str, workers: int) -> list[int]:
    monkeypatch.setenv("ROC_TEST_DOMAIN_BASE", base)
    monkeypatch.setenv("PYTEST_XDIST_WORKER_COUNT", str(workers))
    domains = []
    for worker in range(workers):
        monkeypatch.setenv("PYTEST_XDIST_WORKER", f"gw{worker}")
        domains += [int(ros_domain_id(slot)) for slot in range(DOMAIN_SLOTS)]
    return domains


def test_the_base_moves_every_domain_and_none_is_shared(monkeypatch):
    default = _domains(monkeypatch, "20", 2)
    moved = _domains(monkeypatch, "90", 2)
    assert len(set(default)) == len(default) == 2 * DOMAIN_SLOTS
    assert sorted(moved) == [d + 70 for d in sorted(default)]
    assert min(default) == 20 and max(moved) <= DOMAIN_MAX


def test_a_base_too_high_or_not_a_number_is_refused(monkeypatch):
    with pytest.raises(ValueError, match="choose a lower base"):
        _domains(monkeypatch, "220", 2)
    with pytest.raises(ValueError, match="expected a ROS domain id"):
        _domains(monkeypatch, "x", 1)


def test_no_test_hard_codes_a_domain():
    """Every test that sets ROS_DOMAIN_ID takes it from a slot (ros_domain_id or graph_env, given as a number
    or a file's SLOT constant), and no two test files share a slot."""
    owners: dict[int, set[str]] = {}
    for path in TESTS.rglob("test_*.py"):
        text = path.read_text()
        assert not re.search(r"ROS_DOMAIN_ID[\"']?\s*[:=]\s*[\"']?\d", text.replace('"ROS_DOMAIN_ID", "7"', "")
                             .replace('"ROS_DOMAIN_ID": "3"', "")), path.name
        for called, constant in re.findall(r"(?:ros_domain_id|graph_env)\((\d+)|^SLOT = (\d+)", text, re.MULTILINE):
            owners.setdefault(int(called or constant), set()).add(path.name)
    shared = {slot: files for slot, files in owners.items() if len(files) > 1}
    assert not shared, f"domain slots used by several test files: {shared}"


@pytest.mark.slow  # a few seconds (the quick loop stays under 45 s)
def test_an_xdist_group_runs_on_one_worker(tmp_path):
    """scripts/test.sh's --dist loadgroup keeps the tests of an xdist_group on one worker (the bridge
    tests' busy processes apart from timing tests; each ported ros2cli file's graph started once). A
    pytest that pytest-xdist cannot read the group of would spread them silently."""
    import subprocess
    import sys

    (tmp_path / "test_grouped.py").write_text(
        "import os, pytest\n\n\n@pytest.mark.xdist_group('g')\n@pytest.mark.parametrize('i', range(6))\n"
        "def test_worker(i):\n    print('worker', os.environ['PYTEST_XDIST_WORKER'])\n")
    run = subprocess.run([sys.executable, "-m", "pytest", "-n", "2", "--dist", "loadgroup", "-rA", "-q",
                          "-p", "no:cacheprovider", str(tmp_path / "test_grouped.py")],
                         capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    workers = set(re.findall(r"worker (gw\d+)", run.stdout))
    assert len(workers) == 1, run.stdout
