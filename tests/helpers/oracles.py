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


def require_oracle(what: str, path: Path) -> Path:
    """``path``, which the test needs; when it does not exist, skip the test (fail it in CI)."""
    if not path.exists():
        message = MISSING.format(what=what, path=path)
        if in_ci():
            pytest.fail(f"{message} (CI must have every oracle: set ROC_TEST_SHARED or check out ../shared)",
                        pytrace=False)
        pytest.skip(message)
    return path
