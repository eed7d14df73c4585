#!/usr/bin/env bash
# Set up the environment (scripts/setup.sh, quick when already done), then run the test suite on 2 cores
# with pytest-xdist. Extra arguments go to pytest, e.g.
#   bash scripts/test.sh -k graph -x
# --distro NAME (first) runs on that ROS 2 distribution's venv instead of Jazzy's .venv:
#   bash scripts/test.sh --distro kilted          the distribution suite (tests marked distro) on Kilted
# --with-cpp (first) builds the C++ stack (scripts/setup.sh --with-cpp), then runs the C++ suite (tests
# marked cpp); the whole suite runs them too once the stack is built, and skips them while it is not:
#   bash scripts/test.sh --with-cpp
# --rmw cyclonedds|fastrtps (first) runs the middleware suite (tests marked rmw), the graphs and roc's
# processes they start with RMW_IMPLEMENTATION naming that middleware; cyclonedds first builds rmw_cyclonedds (scripts/setup.sh --with-cyclonedds):
#   bash scripts/test.sh --rmw cyclonedds
# (tests/conftest.py: on a distribution other than Jazzy only the tests marked distro run).
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
cd "$ROOT"

distro=jazzy
suite=()  # --with-cpp: the C++ suite, the tests marked cpp; --rmw: the middleware suite, the tests marked rmw
marker=
case "${1:-}" in
    --distro) distro="${2:?test: --distro needs a name (jazzy or kilted)}"; shift 2 ;;
    --distro=*) distro="${1#--distro=}"; shift ;;
    --with-cpp) suite=(--with-cpp); marker=cpp; shift ;;
    --rmw)
        case "${2:-}" in
            cyclonedds) suite=(--with-cyclonedds) ;;
            fastrtps) ;;
            *) echo "test: error: --rmw needs a middleware: cyclonedds or fastrtps" >&2; exit 2 ;;
        esac
        # for the processes the tests start (tests/helpers/rmw.py): pytest's own stay on the wheels' Fast
        # DDS, which their librcl links and checks as it loads (exit 102 on another RMW_IMPLEMENTATION)
        export ROC_TEST_RMW="rmw_${2}_cpp"
        marker=rmw; shift 2 ;;
esac
if [ "$distro" = jazzy ]; then venv="$ROOT/.venv"; else venv="$ROOT/.venv-$distro"; fi

bash "$ROOT/scripts/setup.sh" --distro "$distro" "${suite[@]}"
[ -z "$marker" ] || set -- -m "$marker" "$@"

rc=0
# loadgroup: tests marked xdist_group("busy_or_timing") share one worker, so the bridge tests' busy
# processes never run beside the daemon-less discovery test (which timing under load can fail)
# the whole of tests/, unless ARGS name test files or directories (tests/bag/test_bag_files.py::test_y included)
paths=(tests)
for arg in "$@"; do
    if [ -e "${arg%%::*}" ]; then paths=(); fi
done
"$venv/bin/python" -m pytest -n 2 --dist loadgroup "${paths[@]}" "$@" </dev/null || rc=$?
if [ "$rc" -eq 5 ]; then
    echo "test: error: pytest collected no tests (exit code 5); treating it as a failure" >&2
    exit 1
fi
exit "$rc"
