#!/usr/bin/env bash
# roc as users install it, outside the checkout, with none of the test tools:
#   bash scripts/test_wheel.sh [DIR]      (.ci/run runs it)
# DIR: where it works and logs, kept; by default a new folder in /tmp, removed when every check passed.
# 1. builds the sdist and, from it, the wheel (python -m build), and checks what the wheel holds;
# 2. makes the ROS venv: python3 -m venv with the ROS 2 Jazzy wheels, colcon and Jazzy's setuptools 68.1.2
#    (Ubuntu 24.04's), and a venv of roc's wheel alone (the two installs run side by side, from pip's cache);
# 3. the wheels' way: roc's wheel installed into the ROS venv, which must leave setuptools and colcon as they
#    are (colcon then builds and tests a package), `roc doctor --fix` repairs the wheels (and doctor names the
#    pip install of ament_package once it is taken out), the launch system
#    goes in (../shared/oracles/install_launch.sh, when it is there), and the smoke test runs in it, activated;
# 4. pipx's way: roc taken out of the ROS venv again, which then plays /opt/ros/jazzy, reached as a sourced
#    setup.bash reaches it (PYTHONPATH, AMENT_PREFIX_PATH, LD_LIBRARY_PATH), and the smoke test runs with
#    the roc of roc's own venv.
# The smoke test: roc doctor, a Python package with a node and a C++ library package (ament_cmake, no
# rclcpp: the wheels have none) created, built and tested, the node run and echoed, roc launch of a launch
# file (of a roc.toml system without the launch system), roc bag record and info, roc tui's first screen in
# tmux (skipped without tmux), roc completion bash, and roc idl's one line without its extra.
# Ends with 'N passed, N failed'; exit 1 when a check failed.
set -uo pipefail
ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
KEEP=${1:+1}  # a folder of the caller's is kept; a temporary one is removed when every check passed
WORK="${1:-$(mktemp -d /tmp/roc-wheel-test.XXXXXX)}"
mkdir -p "$WORK" && WORK="$(cd -- "$WORK" && pwd -P)"
PYTHON="${PYTHON:-python3}"
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_INPUT=1
# nodes on this host only, in a domain of their own (the tests' base when set, as other test runs use)
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_DOMAIN_ID="${ROC_TEST_DOMAIN_BASE:-77}"
unset AMENT_PREFIX_PATH CMAKE_PREFIX_PATH PYTHONPATH COLCON_PREFIX_PATH VIRTUAL_ENV RMW_IMPLEMENTATION ROS_DISTRO
passed=0 failed=0 started=$SECONDS pids=()

say() { printf 'wheel: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }
# check NAME COMMAND...: run it, its output in $WORK/logs/NAME.log, shown when it fails
check() {
    local name=$1; shift
    local log="$WORK/logs/$scenario-$name.log"
    "$@" >"$log" 2>&1
    local rc=$?
    if [ "$rc" = 0 ]; then
        passed=$((passed + 1)); say "ok      $scenario: $name"
    else
        failed=$((failed + 1)); say "FAILED  $scenario: $name (exit $rc; $log):"; tail -25 "$log" | sed 's/^/    /' >&2
    fi
}
stop_all() {
    local pid
    for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null; done
    pids=()
}
trap 'stop_all' EXIT
mkdir -p "$WORK/logs"
scenario=build

# ---- 1. the sdist and the wheel ----------------------------------------------------------------
say "building the sdist and the wheel in $WORK/dist"
"$PYTHON" -m venv "$WORK/tools" && "$WORK/tools/bin/pip" install -q build >"$WORK/logs/tools.log" 2>&1 \
    || die "could not install 'build' ($WORK/logs/tools.log)"
rm -rf "$WORK/dist"
# the wheel is built from the sdist: a file the sdist lacks is missing from the wheel too
"$WORK/tools/bin/python" -m build --outdir "$WORK/dist" "$ROOT" >"$WORK/logs/build.log" 2>&1 \
    || { tail -30 "$WORK/logs/build.log" >&2; die "python -m build failed ($WORK/logs/build.log)"; }
WHEEL=$(ls "$WORK"/dist/roc_ros2-*.whl)
say "built $(cd "$WORK/dist" && ls)"
wheel_holds() {
    "$WORK/tools/bin/python" - "$WHEEL" <<'EOF'
import sys, zipfile
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
wanted = ["roc/_version.py", "roc/create/templates/python/node.py.j2", "roc/create/license_texts/MIT.txt",
          "roc/shell/templates/setup.sh.j2", "roc/ros/vendors/fastdds_participant.xml", "roc/ros/vendors/fastdds3_participant.xml"]
missing = [name for name in wanted if name not in names]
missing += [] if any(n.endswith(".data/scripts/roc") for n in names) else ["the roc script"]
missing += [] if any(n.endswith("/licenses/LICENSE") for n in names) else ["LICENSE"]
leaked = sorted({top for top in (n.split("/")[0] for n in names)
                 if top != "roc" and not top.endswith((".dist-info", ".data"))})
print("missing:", missing, "not roc's:", leaked)
sys.exit(1 if missing or leaked else 0)
EOF
}
check "wheel holds templates, profiles, script, licence" wheel_holds

# ---- 2. the venvs, side by side -------------------------------------------------------------------
ROS="$WORK/ros" OWN="$WORK/roc"
rm -rf "$ROS" "$OWN"
say "making the ROS venv (Jazzy wheels, colcon, setuptools 68.1.2) and roc's own venv"
( "$PYTHON" -m venv "$ROS" && "$ROS/bin/pip" install -q -r "$ROOT/requirements/ros-jazzy.txt" \
      colcon-common-extensions pytest "setuptools==68.1.2" ) >"$WORK/logs/ros-venv.log" 2>&1 &
ros_venv=$!
( "$PYTHON" -m venv "$OWN" && "$OWN/bin/pip" install -q "$WHEEL" ) >"$WORK/logs/own-venv.log" 2>&1 \
    || { cat "$WORK/logs/own-venv.log" >&2; die "pip install of the wheel into a fresh venv failed"; }
wait "$ros_venv" || { tail -30 "$WORK/logs/ros-venv.log" >&2; die "the ROS venv's install failed"; }
SITE=$("$ROS/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
say "venvs ready after $((SECONDS - started)) s"

# ---- the smoke test, in the current directory's ws/ with roc and ROS as the scenario set them -------
launch_file() {
    cat > talk.launch.xml <<'EOF'
<launch>
  <node pkg="py_pkg" exec="talker" name="launched_talker">
    <param name="max_count" value="3"/>
    <param name="period" value="0.2"/>
  </node>
</launch>
EOF
    # runs until Ctrl+C (exit 0), as ros2 launch
    local out; out=$(timeout -s INT 10 roc launch talk.launch.xml 2>&1)
    printf '%s\n' "$out"
    grep -q "Hello from py_pkg: 3" <<<"$out"
}
launch_system() {  # a roc.toml system: roc launch without the launch library
    cat > roc.toml <<'EOF'
[[launch.talk.process]]
package = "py_pkg"
executable = "talker"
parameters = { max_count = 3, period = 0.2 }
EOF
    local out; out=$(timeout -s INT 10 roc launch talk 2>&1)
    printf '%s\n' "$out"
    grep -q "Hello from py_pkg: 3" <<<"$out"
}
tui_first_screen() {
    local socket="$WORK/tmux-$scenario.sock" screen=""
    tmux -S "$socket" new-session -d -x 120 -y 35 -s roc "env TERM=xterm-256color roc tui; sleep 30"
    for _ in $(seq 1 150); do
        screen=$(tmux -S "$socket" capture-pane -p -t roc 2>/dev/null)
        grep -q "/chatter" <<<"$screen" && grep -q "/talker" <<<"$screen" && break
        sleep 0.2
    done
    printf '%s\n' "$screen"
    tmux -S "$socket" send-keys -t roc q
    sleep 1
    tmux -S "$socket" kill-server 2>/dev/null
    grep -q "/chatter" <<<"$screen" && grep -q "/talker" <<<"$screen"
}
completion_bash() {
    roc completion bash >completion.bash && bash -c 'source completion.bash && complete -p roc' \
        && grep -q "roc completion --names\|_roc" completion.bash
}
idl_without_extra() {
    printf 'syntax = "proto3";\nmessage Pose { double x = 1; }\n' > pose.proto
    local out; out=$(roc idl protobuf pose.proto 2>&1); local rc=$?
    printf '%s\n' "$out"
    [ "$rc" = 1 ] && [ "$(wc -l <<<"$out")" = 1 ] && grep -q "pip install grpcio-tools" <<<"$out"
}
smoke() {
    rm -rf "$WORK/$scenario" && mkdir -p "$WORK/$scenario/ws/src" && cd "$WORK/$scenario/ws" || return
    check "roc is the wheel's" bash -c "command -v roc | grep -q '^$1/bin/roc\$' && roc --version | grep -q '^roc 0\\.'"
    check "roc doctor" roc doctor
    check "create a Python package" roc work create --build-type ament_python py_pkg --node-name talker
    check "create a C++ library package" roc work create --build-type ament_cmake cpp_lib --library-name greeter --tests
    check "build" roc work build
    check "test the C++ package" roc work test --packages-select cpp_lib
    # shellcheck disable=SC1091
    check "source and run the node" bash -c "source install/setup.bash && \
        timeout 30 roc run py_pkg talker --ros-args -p max_count:=2 -p period:=0.1 2>&1 | grep 'Hello from py_pkg: 2'"
    ( source install/setup.bash && exec roc run py_pkg talker --ros-args -p period:=0.1 ) >talker.log 2>&1 &
    pids+=($!)
    check "roc topic echo" bash -c "timeout 30 roc topic echo /chatter --once | grep \"^data: 'Hello from py_pkg: \""
    check "roc bag record" bash -c "timeout -s INT 4 roc bag record -o bag /chatter; [ -f bag/metadata.yaml ]"
    check "roc bag info" bash -c "roc bag info bag | grep -E 'Topic: /chatter \\| Type: std_msgs/msg/String \\| Count: [1-9]'"
    if command -v tmux >/dev/null; then
        check "roc tui first screen" tui_first_screen
    else
        say "skipped $scenario: roc tui first screen (tmux is not installed)"
    fi
    stop_all
    roc daemon stop >/dev/null 2>&1
    if python -c 'import launch_xml' 2>/dev/null; then
        check "roc launch a launch file" bash -c "source install/setup.bash && $(declare -f launch_file); launch_file"
    else
        say "no launch system: roc launch of a roc.toml system instead"
        check "roc launch a roc.toml system" bash -c "source install/setup.bash && $(declare -f launch_system); launch_system"
    fi
    check "roc completion bash" completion_bash
    check "roc idl without the idl extra" idl_without_extra
    cd "$WORK" || return
}

# ---- 3. the wheels' way: roc in the ROS venv ------------------------------------------------------
scenario=wheels
say "roc's wheel into the ROS venv (colcon, setuptools 68.1.2)"
"$ROS/bin/pip" freeze --all | sort >"$WORK/ros-before.txt"
check "pip install into the ROS venv" "$ROS/bin/pip" install -q "$WHEEL"
check "setuptools is still 68.1.2" "$ROS/bin/python" -c \
    'import setuptools, sys; print(setuptools.__version__); sys.exit(setuptools.__version__ != "68.1.2")'
# roc only adds: no package of ROS's or colcon's is upgraded, downgraded or removed
nothing_changed() {  # the packages installed before, each still at its version (the lines that went are printed)
    ! "$ROS/bin/pip" freeze --all | sort | comm -23 "$WORK/ros-before.txt" - | grep .
}
check "no installed package changed" nothing_changed
check "pip check" "$ROS/bin/pip" check
colcon_works() {
    rm -rf "$WORK/colcon" && mkdir -p "$WORK/colcon/src" && cd "$WORK/colcon" || return
    "$ROS/bin/roc" work create --build-type ament_python --tests py_tested >/dev/null || return
    # shellcheck disable=SC1091
    source "$ROS/bin/activate" && colcon build && colcon test --event-handlers console_direct+ \
        && colcon test-result --verbose
}
check "colcon builds and tests beside roc" bash -c "$(declare -f colcon_works); ROS=$ROS WORK=$WORK colcon_works"
# the wheels' CMake files break builds until repaired: a warning, which --include-warnings fails on
check "roc doctor warns of the wheels' defects" bash -c "! '$ROS/bin/roc' doctor --include-warnings"
check "roc doctor --fix repairs the wheels" "$ROS/bin/roc" doctor --fix --include-warnings
# the wheels' meta wheels do not install ament_package: without it doctor names the pip install that adds it
doctor_finds_missing_ament_package() {
    "$ROS/bin/pip" uninstall -q -y ros-jazzy-ament-package ros-ament-package || return
    local out rc fix
    out=$("$ROS/bin/roc" doctor --no-daemon --spin-time 0.5); rc=$?
    printf '%s\n' "$out"
    [ "$rc" = 1 ] && grep -Eq "error +ament python: .* cannot import ament_package" <<<"$out" \
        && grep -Eq "error +wheel packages: .*: ament_package" <<<"$out" || return 1
    fix=$(grep -A1 -E "error +wheel packages:" <<<"$out" | sed -n 's/^ *fix: //p')
    echo "running the fix: $fix"
    $fix && "$ROS/bin/roc" doctor --no-daemon --spin-time 0.5
}
check "roc doctor names the pip install of a missing wheel" doctor_finds_missing_ament_package
LAUNCH_INSTALLER="$ROOT/../shared/oracles/install_launch.sh"
if [ -f "$LAUNCH_INSTALLER" ]; then
    check "install the launch system" bash "$LAUNCH_INSTALLER" "$ROS"
else
    say "no $LAUNCH_INSTALLER: the smoke tests launch a roc.toml system"
fi
(
    # shellcheck disable=SC1091
    source "$ROS/bin/activate" && smoke "$ROS"
    echo "$passed $failed" >"$WORK/counts"
)
read -r passed failed <"$WORK/counts"

# ---- 4. pipx's way: roc in its own venv, ROS in another prefix ------------------------------------
scenario=prefix
check "pip uninstall roc from the ROS venv" "$ROS/bin/pip" uninstall -q -y roc-ros2
(
    libs="$ROS/lib$(printf ':%s' "$SITE"/ros_*.libs)"
    export PATH="$OWN/bin:$PATH" PYTHONPATH="$SITE" AMENT_PREFIX_PATH="$ROS" LD_LIBRARY_PATH="$libs"
    smoke "$OWN"
    echo "$passed $failed" >"$WORK/counts"
)
read -r passed failed <"$WORK/counts"

say "done in $((SECONDS - started)) s ($WORK)"
echo "wheel: $passed passed, $failed failed"
[ "$failed" = 0 ] || exit 1
[ -n "$KEEP" ] || rm -rf "$WORK"
