#!/usr/bin/env bash
# Cyclone DDS for roc's development and CI: Debian's cyclonedds-dev (apt-get, as root) and rmw_cyclonedds
# built by roc from ../shared/sources on top of .venv's ROS 2 Jazzy wheels (which ship only Fast DDS's
# RMW). Run by `bash scripts/setup.sh --with-cyclonedds` after the venv is set up; the tests marked rmw
# use it (bash scripts/test.sh --rmw cyclonedds, tests/helpers/rmw.py).
#
# One workspace, .rmw-stack/ (ignored by git), Release with tests off. The sources are unpacked again only
# when the tarball changed (.rmw-stack/sources.stamp); the build is roc's, so an unchanged re-run costs
# a no-op build. `.rmw-stack/install/setup.bash` is the RMW, ready to source, once `.rmw-stack/ready`
# exists.
# Environment: ROC_SHARED (the shared folder holding sources/, default ../shared beside the checkout).
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
VENV="$ROOT/.venv"
STACK="$ROOT/.rmw-stack"
TARBALL="${ROC_SHARED:-$ROOT/../shared}/sources/rmw_cyclonedds-2.2.2.tar.gz"
ROC="$VENV/bin/roc"

say() { printf 'setup: %s\n' "$*" >&2; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

[ -x "$ROC" ] || die "$ROC is missing: run bash scripts/setup.sh first"
[ -f "$TARBALL" ] || die "$TARBALL does not exist (set ROC_SHARED to the folder holding sources/)"
command -v c++ >/dev/null 2>&1 && command -v cmake >/dev/null 2>&1 \
    || die "rmw_cyclonedds needs cmake and a C++ compiler (on Debian: apt-get install cmake g++)"

# Cyclone DDS itself (Debian's 0.10.2; Jazzy vendors 0.10.5, the same API), installed as the test tools are
if ! dpkg -s cyclonedds-dev >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        say "installing cyclonedds-dev with apt-get"
        { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq cyclonedds-dev; } \
            >/dev/null 2>&1 || die "could not install cyclonedds-dev with apt-get"
    else
        die "rmw_cyclonedds needs Cyclone DDS: apt-get install cyclonedds-dev (as root), then run this again"
    fi
fi

mkdir -p "$STACK"
rm -f -- "$STACK/ready"
want="$(sha256sum -- "$TARBALL" | cut -d' ' -f1)"
if [ "$(cat -- "$STACK/sources.stamp" 2>/dev/null)" != "$want" ]; then
    say "unpacking $(basename -- "$TARBALL") into ${STACK#"$ROOT"/}/src"
    rm -f -- "$STACK/sources.stamp"
    # into a new folder, then swapped in, so an interrupted unpack never leaves half a source tree
    scratch="$(mktemp -d "$STACK/.unpack.XXXXXX")"
    tar -xzf "$TARBALL" -C "$scratch"
    rm -rf -- "$STACK/src"
    mv -- "$scratch" "$STACK/src"
    printf '%s\n' "$want" >"$STACK/sources.stamp"
fi

start=$SECONDS
say "building rmw_cyclonedds with roc (about 30 s the first time)"
# A clean environment of the wheels (what the venv's roc sees with nothing sourced), whatever the caller sourced.
env -u AMENT_PREFIX_PATH -u COLCON_PREFIX_PATH -u CMAKE_PREFIX_PATH -u ROS_DISTRO \
    "$ROC" -C "$STACK" work build --cmake-args -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF >&2 \
    || die "building rmw_cyclonedds failed (logs: ${STACK#"$ROOT"/}/log/latest_build)"
printf '%s\n' "$want" >"$STACK/ready"
say "rmw_cyclonedds ready in $((SECONDS - start)) s: source ${STACK#"$ROOT"/}/install/setup.bash"
