"""The suite's processes stop on SIGINT (the tests' Ctrl+C) even when the suite was started with
SIGINT ignored, as a shell does for a command it runs in the background (``bash scripts/test.sh &``):
an ignored signal stays ignored in every child, a handled one is reset to its default."""

import signal

if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


import pytest  # noqa: E402


@pytest.fixture(scope="session")
def launch_demo_prefix(tmp_path_factory):
    """roc_launch_demo (workspaces/fixtures/launch) built by roc once per test worker: its install prefix."""
    from launch_helpers import build_demo

    return build_demo(tmp_path_factory.mktemp("launch_demo"))
