"""The middleware suite (tests marked ``rmw``): ``bash scripts/test.sh --rmw cyclonedds`` runs them with
ROC_TEST_RMW=rmw_cyclonedds_cpp (the processes they start get RMW_IMPLEMENTATION=rmw_cyclonedds_cpp), on the rmw_cyclonedds that ``bash scripts/setup.sh
--with-cyclonedds`` builds with roc in .rmw-stack/; the whole suite runs them on Fast DDS, the wheels' own.
A test that needs rmw_cyclonedds (the suite's, or a Cyclone process beside Fast DDS ones) calls
``require_cyclonedds``: without the build it is skipped with the reason ``rmw_cyclonedds is not built:
...`` (conftest.py sums these up), except in CI, which builds it: there it fails."""

from __future__ import annotations

import os
from pathlib import Path

from helpers.oracles import REPO, skip_or_fail

STACK = REPO / ".rmw-stack"
CYCLONEDDS = "rmw_cyclonedds_cpp"
FASTRTPS = "rmw_fastrtps_cpp"
CYCLONEDDS_PREFIX = STACK / "stack" / "install" / CYCLONEDDS
SETUP_COMMAND = "bash scripts/setup.sh --with-cyclonedds"
MISSING = f"rmw_cyclonedds is not built: run {SETUP_COMMAND}"


def suite_middleware() -> str:
    """The RMW this run's graph tests use: ROC_TEST_RMW's (test.sh --rmw), Fast DDS without it. pytest's
    own processes stay on the wheels' Fast DDS (their librcl links it and checks RMW_IMPLEMENTATION as it
    loads); the processes the tests start get it (``suite_environment``)."""
    return os.environ.get("ROC_TEST_RMW") or FASTRTPS


def suite_environment() -> dict[str, str]:
    """What an environment the helpers make for a test's processes takes of the suite's middleware."""
    return {"RMW_IMPLEMENTATION": suite_middleware()} if os.environ.get("ROC_TEST_RMW") else {}


def require_cyclonedds() -> Path:
    """rmw_cyclonedds' install prefix; skips the test (fails it in CI) when it is not built."""
    if not (STACK / "ready").is_file():
        skip_or_fail(MISSING, "CI builds it before the middleware suite")
    return CYCLONEDDS_PREFIX


def middleware_prefixes(middleware: str | None = None) -> list[str]:
    """The install prefixes, before the wheels', a process needs to find ``middleware`` (default the
    suite's) in the ament index: rmw_cyclonedds' prefix for Cyclone, none for the wheels' Fast DDS."""
    return [str(CYCLONEDDS_PREFIX)] if (middleware or suite_middleware()) == CYCLONEDDS else []


def on_middleware(env: dict[str, str], middleware: str) -> dict[str, str]:
    """``env`` (with the wheels as underlay, helpers.build.ros_env) for a process on ``middleware``."""
    if middleware == CYCLONEDDS:
        require_cyclonedds()
    prefixes = [*middleware_prefixes(middleware),
                *(entry for entry in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
                  if entry and entry != str(CYCLONEDDS_PREFIX))]
    return {**env, "RMW_IMPLEMENTATION": middleware, "AMENT_PREFIX_PATH": os.pathsep.join(prefixes)}
