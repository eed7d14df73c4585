#!/usr/bin/env bash
# Set up the environment (scripts/setup.sh, quick when already done), then run the whole
# test suite on 2 cores with pytest-xdist. Extra arguments go to pytest, e.g.
#   bash scripts/test.sh -k graph -x
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
cd "$ROOT"

bash "$ROOT/scripts/setup.sh"

rc=0
# loadgroup: tests marked xdist_group("busy_or_timing") share one worker, so the bridge tests' busy
# processes never run beside the daemon-less discovery test (which timing under load can fail)
# the whole of tests/, unless ARGS name test files or directories (tests/bag/test_bag_files.py::test_y included)
paths=(tests)
for arg in "$@"; do
    if [ -e "${arg%%::*}" ]; then paths=(); fi
done
"$ROOT/.venv/bin/python" -m pytest -n 2 --dist loadgroup "${paths[@]}" "$@" </dev/null || rc=$?
if [ "$rc" -eq 5 ]; then
    echo "test: error: pytest collected no tests (exit code 5); treating it as a failure" >&2
    exit 1
fi
exit "$rc"
