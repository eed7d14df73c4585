#!/usr/bin/env bash
# Set up roc's development/CI environment for one ROS 2 distribution:
#   bash scripts/setup.sh                   .venv         ROS 2 Jazzy (the default)
#   bash scripts/setup.sh --distro kilted   .venv-kilted  ROS 2 Kilted
#   bash scripts/setup.sh --with-cpp        .venv, then the C++ stack (rclcpp from source) built by roc on
#                                           it in .cpp-stack/ (scripts/setup_stack.sh cpp)
#   bash scripts/setup.sh --with-cyclonedds .venv, then Debian's cyclonedds-dev (apt-get, as root) and
#                                           rmw_cyclonedds built by roc on it in .rmw-stack/
#                                           (scripts/setup_stack.sh rmw)
# Each is
#   - a venv made with python3 -m venv (or $PYTHON -m venv),
#   - roc installed editable with its test extra (pytest, pytest-xdist, colcon as test oracle),
#   - the ROS 2 PyPI wheels of requirements/ros-DISTRO.txt (the two distributions pin the same ros-*
#     wheels at their own versions, so they never share a venv),
#   - the fix-ups of those wheels' CMake files (scripts/fix_ros_wheels.py),
#   - the launch system from ../shared/oracles/install_launch.sh, when it is there.
# Idempotent: when nothing it depends on changed since the last successful run (stamp in
# VENV/.roc-setup-stamp) it only re-checks the fix-ups and prints one line.
# Only the dev/CI environment lives here: roc itself never assumes the venv's paths.
# It changes nothing outside the checkout (and pip's cache) unless asked:
#   ROC_SETUP_TEST_TOOLS=1  also install zsh, fish, tmux, ccache and openssh-server with the system's
#                       package manager (apt-get, as root), so that the tests of roc's zsh/fish setup
#                       scripts and completions, of roc tui in a real terminal, of --compiler-cache ccache
#                       and of roc launch's processes on other hosts (an sshd the test starts) run
#                       instead of skipping; CI sets it (.ci/run). Without
#                       it, missing tools are only reported. roc itself needs none of them.
# Environment: PYTHON (interpreter that creates the venv, default python3),
#              ROC_SETUP_FORCE=1 (redo the pip steps even if the stamp matches),
#              ROC_SETUP_TEST_TOOLS=1 (see above).
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
PYTHON="${PYTHON:-python3}"

# The set-up runs on the wheels' own middleware: their librcl links Fast DDS and exits at load (102) when
# RMW_IMPLEMENTATION names another, as a user's shell may.
unset RMW_IMPLEMENTATION

say() { printf 'setup: %s\n' "$*" >&2; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

DISTRO=jazzy
WITH_CPP=0
WITH_CYCLONEDDS=0
USAGE="usage: bash scripts/setup.sh [--distro jazzy|kilted] [--with-cpp] [--with-cyclonedds]"
while [ "$#" -gt 0 ]; do
    case "$1" in
        --distro) DISTRO="${2:-}"; shift 2 || die "--distro needs a name (jazzy or kilted)" ;;
        --distro=*) DISTRO="${1#--distro=}"; shift ;;
        --with-cpp) WITH_CPP=1; shift ;;
        --with-cyclonedds) WITH_CYCLONEDDS=1; shift ;;
        *) die "unknown argument '$1' ($USAGE)" ;;
    esac
done
case "$DISTRO" in
    jazzy|kilted) ;;
    *) die "roc is set up for the ROS 2 distributions jazzy and kilted, not '$DISTRO'" ;;
esac
[ "$WITH_CPP" = 0 ] || [ "$DISTRO" = jazzy ] \
    || die "--with-cpp builds the Jazzy sources of rclcpp: use it without --distro $DISTRO"
[ "$WITH_CYCLONEDDS" = 0 ] || [ "$DISTRO" = jazzy ] \
    || die "--with-cyclonedds builds the Jazzy sources of rmw_cyclonedds: use it without --distro $DISTRO"
REQUIREMENTS="$ROOT/requirements/ros-$DISTRO.txt"
# Jazzy, the default, in .venv; any other distribution in a venv of its own
if [ "$DISTRO" = jazzy ]; then VENV="$ROOT/.venv"; else VENV="$ROOT/.venv-$DISTRO"; fi
VPY="$VENV/bin/python"
STAMP="$VENV/.roc-setup-stamp"
# pip, without the machine-wide config's warnings about absent local index folders.
pip_q() {
    "$VPY" -m pip "$@" 2>&1 \
        | { grep -v -E "^WARNING: Location 'file://[^']*' is ignored: it is neither a file nor a directory\.\$" || true; } >&2
}

# One setup at a time per venv (e.g. two test runs started together).
if command -v flock >/dev/null 2>&1; then
    LOCK="${TMPDIR:-/tmp}/roc-setup-$(printf '%s' "$VENV" | sha256sum | cut -c1-16).lock"
    exec 9>"$LOCK"
    flock 9
fi

# Everything whose change must redo the set-up.
stamp_inputs() {
    local f
    for f in "$ROOT/scripts/setup.sh" "$ROOT/scripts/fix_ros_wheels.py" "$ROOT/pyproject.toml" "$ROOT/bin/roc" \
             "$REQUIREMENTS"; do
        [ -f "$f" ] && printf '%s\n' "${f#"$ROOT"/}" && cat -- "$f"
    done
    # the interpreter the venv runs on
    "$VPY" -c 'import sys; print(sys.version)' 2>/dev/null || true
}
want_stamp() { stamp_inputs | sha256sum | cut -d' ' -f1; }

# The venv works and its roc is this checkout's.
venv_ok() {
    [ -x "$VPY" ] && "$VPY" -I - "$ROOT" <<'EOF' >/dev/null 2>&1
import os, sys
import roc
sys.exit(0 if os.path.realpath(roc.__file__).startswith(os.path.realpath(sys.argv[1]) + os.sep) else 1)
EOF
}

# ---- test-time tools (opt-in: their tests skip without them): the shells the tests source roc's
# setup scripts in, tmux, which runs roc tui in a real terminal, ccache (a compiler cache) and sshd (the
# SSH server roc launch's remote-process tests start on localhost, never as a service). Installed only with
# ROC_SETUP_TEST_TOOLS=1; otherwise a full set-up says which are missing.
setup_test_tools() {
    local missing=() tool
    # command:package (the package is the command's name unless given)
    for tool in zsh fish tmux ccache sshd:openssh-server; do
        command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool#*:}")
    done
    [ "${#missing[@]}" -gt 0 ] || return 0
    if [ "${ROC_SETUP_TEST_TOOLS:-0}" != 1 ]; then
        [ "$1" = quiet ] || say "${missing[*]} not installed: their tests will be skipped (ROC_SETUP_TEST_TOOLS=1 installs them)"
    elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        say "ROC_SETUP_TEST_TOOLS=1: installing ${missing[*]} with apt-get"
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"; } \
            >/dev/null 2>&1 || say "could not install ${missing[*]}; their tests will be skipped"
    else
        say "ROC_SETUP_TEST_TOOLS=1: install ${missing[*]} yourself (this needs root and apt-get)"
    fi
}

# Cyclone DDS itself for rmw_cyclonedds: Debian's cyclonedds-dev (0.10.2; Jazzy vendors 0.10.5, the same
# API), installed as the test tools are.
install_cyclonedds() {
    dpkg -s cyclonedds-dev >/dev/null 2>&1 && return 0
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        say "installing cyclonedds-dev with apt-get"
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq cyclonedds-dev; } \
            >/dev/null 2>&1 || die "could not install cyclonedds-dev with apt-get"
    else
        die "rmw_cyclonedds needs Cyclone DDS: apt-get install cyclonedds-dev (as root), then run this again"
    fi
}

# The stacks built on the venv that were asked for (--with-cpp, --with-cyclonedds: scripts/setup_stack.sh).
build_stacks() {
    [ "$WITH_CPP" = 0 ] || bash "$ROOT/scripts/setup_stack.sh" cpp
    [ "$WITH_CYCLONEDDS" = 0 ] || { install_cyclonedds && bash "$ROOT/scripts/setup_stack.sh" rmw; }
}

# ---- quick path -------------------------------------------------------------------------
if [ "${ROC_SETUP_FORCE:-0}" != 1 ] && [ -f "$STAMP" ] && venv_ok \
        && [ "$(cat -- "$STAMP")" = "$(want_stamp)" ]; then
    # Cheap safety net in case a wheel was reinstalled by hand: silent when nothing changes.
    "$VPY" "$ROOT/scripts/fix_ros_wheels.py" --quiet
    "$VPY" -m compileall -q "$ROOT/roc" >/dev/null  # only what changed since the last run
    setup_test_tools quiet
    say "environment up to date ($VENV); set ROC_SETUP_FORCE=1 to redo it"
    build_stacks
    exit 0
fi

start=$SECONDS
export PIP_NO_INPUT=1 PIP_DISABLE_PIP_VERSION_CHECK=1
setup_test_tools loud

# ---- venv -------------------------------------------------------------------------------
if [ ! -x "$VPY" ] || ! "$VPY" -c '' >/dev/null 2>&1; then
    command -v "$PYTHON" >/dev/null 2>&1 || die "'$PYTHON' not found (set PYTHON=/path/to/python3.11)"
    if [ -e "$VENV" ]; then
        say "rebuilding the broken venv at $VENV"
        "$PYTHON" -m venv --clear "$VENV" || die "'$PYTHON -m venv' failed (on Debian: apt-get install python3-venv)"
    else
        say "creating the venv at $VENV with $("$PYTHON" --version 2>&1)"
        "$PYTHON" -m venv "$VENV" || die "'$PYTHON -m venv' failed (on Debian: apt-get install python3-venv)"
    fi
fi
rm -f -- "$STAMP"

# ---- packages ---------------------------------------------------------------------------
say "upgrading pip"
pip_q install -q --upgrade pip

say "installing roc (editable, with the test extra) and the ROS 2 $DISTRO wheels (${REQUIREMENTS#"$ROOT"/})"
# 'compat' puts the checkout on sys.path with a plain .pth entry; the default editable mode adds an
# import hook that costs ~10 ms at every roc start. Should setuptools drop 'compat', use the default.
# (setuptools' notice that 'compat' is transitional is left out: it is the comment above)
PYTHONWARNINGS="ignore:Compat editable installs" \
    pip_q install -q --config-settings editable_mode=compat -e "$ROOT[test]" -r "$REQUIREMENTS" \
    || pip_q install -q -e "$ROOT[test]" -r "$REQUIREMENTS"

# ---- the colcon oracle's setuptools -------------------------------------------------------
# colcon reads a setup.py through the setuptools it runs with, and setuptools 72+ (which grpcio-tools
# needs) drops tests_require. The tests run colcon's package identification with Jazzy's platform
# setuptools (Ubuntu 24.04: 68.1.2), kept apart from the venv's (tests/helpers/fixture_workspaces.py).
# pip checks the dependencies of what it installs against the venv's packages even with --target, and
# would report grpcio-tools' need of setuptools>=77 as an ERROR although the venv's setuptools is untouched.
pip_q install -q --no-warn-conflicts --upgrade --target "$VENV/oracle-setuptools" "setuptools==68.1.2"

# ---- fix-ups of the wheels' CMake files ---------------------------------------------------
"$VPY" "$ROOT/scripts/fix_ros_wheels.py"

# ---- the ROS 2 launch system (launch, launch_xml, launch_yaml, launch_ros) and composition_interfaces ----
# Not on PyPI: for roc launch's and roc component's tests and development they come from the shared
# oracles' installer (which builds composition_interfaces from source), when it is beside the checkout.
# Users get them from their ROS 2 installation.
LAUNCH_INSTALLER="$ROOT/../shared/oracles/install_launch.sh"
if [ -f "$LAUNCH_INSTALLER" ] && ! "$VPY" -c 'import launch, launch_ros, composition_interfaces.srv' >/dev/null 2>&1; then
    say "installing the ROS 2 launch system and building composition_interfaces ($LAUNCH_INSTALLER)"
    bash "$LAUNCH_INSTALLER" "$VENV" >"$VENV/install_launch.log" 2>&1 \
        || { tail -20 "$VENV/install_launch.log" >&2; die "$LAUNCH_INSTALLER failed (log: $VENV/install_launch.log)"; }
fi

# ---- byte-code, as a pip install writes it (PYTHONDONTWRITEBYTECODE=1 may be set machine-wide,
# and an editable install would then recompile every roc module on every run) ----------------
"$VPY" -m compileall -q "$ROOT/roc" >/dev/null

# ---- smoke check --------------------------------------------------------------------------
"$VPY" -I -c 'import rclpy, std_msgs.msg, std_srvs.srv, test_msgs.action, roc' \
    || die "the installed environment does not import rclpy/std_msgs/std_srvs/test_msgs/roc"
[ -x "$VENV/bin/roc" ] || die "$VENV/bin/roc is missing"
[ -x "$VENV/bin/colcon" ] || die "$VENV/bin/colcon is missing"

want_stamp >"$STAMP"
say "done in $((SECONDS - start)) s: ROS 2 $DISTRO; run roc as $VENV/bin/roc (or 'source ${VENV#"$ROOT"/}/bin/activate')"
build_stacks
