"""Where the tests find their oracles and reference outputs (``../shared`` beside the checkout, or
ROC_TEST_SHARED), and what a missing one means: the test is skipped with the reason ``oracle WHAT not
found at PATH`` (conftest.py sums these up at the end of the run), except in CI (CI=true), which must
have every oracle: there the test fails."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SHARED = Path(os.environ.get("ROC_TEST_SHARED") or REPO.parent / "shared")
MISSING = "oracle {what} not found at {path}"


def in_ci() -> bool:
    return os.environ.get("CI", "").lower() not in ("", "0", "false", "no")


def skip_or_fail(message: str, in_ci_because: str) -> None:
    """Skip the test for want of something, saying ``message``; in CI, which must have it, fail it."""
    if in_ci():
        pytest.fail(f"{message} ({in_ci_because})", pytrace=False)
    pytest.skip(message)


def require_oracle(what: str, path: Path) -> Path:
    """``path``, which the test needs; when it does not exist, skip the test (fail it in CI)."""
    if not path.exists():
        skip_or_fail(MISSING.format(what=what, path=path),
                     "CI must have every oracle: set ROC_TEST_SHARED or check out ../shared")
    return path
