#!/usr/bin/env bash
# The C++ stack for roc's development and CI: rclcpp and what rclcpp_components needs, the demos' and
# examples' C++ nodes (requirements/cpp-stack.txt), built by roc from the upstream sources in
# ../shared/sources on top of .venv's ROS 2 Jazzy wheels. Run by `bash scripts/setup.sh --with-cpp`
# after the venv is set up; the tests marked cpp use it (bash scripts/test.sh --with-cpp).
#
# Two workspaces under .cpp-stack/ (ignored by git): `underlay` (console_bridge, see cpp-stack.txt) and
# `stack` on top of it, both Release with tests off (the wheels have no ament_lint_auto). The sources are
# unpacked again only when cpp-stack.txt or a tarball changed (.cpp-stack/sources.stamp); the builds are
# roc's, so an unchanged re-run costs two no-op builds. `.cpp-stack/stack/install/setup.bash` is the
# stack, ready to source, once `.cpp-stack/ready` exists.
# Environment: ROC_SHARED (the shared folder holding sources/, default ../shared beside the checkout).
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
VENV="$ROOT/.venv"
STACK="$ROOT/.cpp-stack"
LIST="$ROOT/requirements/cpp-stack.txt"
SOURCES="${ROC_SHARED:-$ROOT/../shared}/sources"
ROC="$VENV/bin/roc"

say() { printf 'setup: %s\n' "$*" >&2; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

[ -x "$ROC" ] || die "$ROC is missing: run bash scripts/setup.sh first"
[ -d "$SOURCES" ] || die "the C++ sources are not at $SOURCES (set ROC_SHARED to the folder holding sources/)"
command -v c++ >/dev/null 2>&1 && command -v cmake >/dev/null 2>&1 \
    || die "the C++ stack needs cmake and a C++ compiler (on Debian: apt-get install cmake g++)"

# the lines of cpp-stack.txt: WORKSPACE TARBALL FOLDER...
entries() { grep -v -E '^[[:space:]]*(#|$)' "$LIST"; }

sources_stamp() {
    cat -- "$LIST"
    local workspace tarball folders
    while read -r workspace tarball folders; do
        [ -f "$SOURCES/$tarball" ] || die "$SOURCES/$tarball (named in ${LIST#"$ROOT"/}) does not exist"
        sha256sum -- "$SOURCES/$tarball" | cut -d' ' -f1
    done < <(entries)
}

# Unpack each tarball's package folders into src/<tarball's name>/ of its workspace: into a new folder,
# then swapped in, so an interrupted unpack never leaves half a source tree.
unpack() {
    local workspace tarball folders folder name scratch
    scratch="$(mktemp -d "$STACK/.unpack.XXXXXX")"
    trap 'rm -rf -- "$scratch"' RETURN
    while read -r workspace tarball folders; do
        name="${tarball%.tar.gz}"
        mkdir -p "$scratch/$workspace/src" "$scratch/tar/$name"
        tar -xzf "$SOURCES/$tarball" -C "$scratch/tar/$name" --strip-components=1
        for folder in $folders; do
            [ -e "$scratch/tar/$name/$folder" ] || die "$tarball has no folder '$folder' (${LIST#"$ROOT"/})"
            if [ "$folder" = . ]; then
                mv -- "$scratch/tar/$name" "$scratch/$workspace/src/$name"
            else
                mkdir -p "$scratch/$workspace/src/$name"
                mv -- "$scratch/tar/$name/$folder" "$scratch/$workspace/src/$name/"
            fi
        done
    done < <(entries)
    for workspace in "$scratch"/*/src; do
        workspace="$(basename -- "$(dirname -- "$workspace")")"
        [ "$workspace" = tar ] && continue
        mkdir -p "$STACK/$workspace"
        rm -rf -- "$STACK/$workspace/src.old"
        [ -e "$STACK/$workspace/src" ] && mv -- "$STACK/$workspace/src" "$STACK/$workspace/src.old"
        mv -- "$scratch/$workspace/src" "$STACK/$workspace/src"
        rm -rf -- "$STACK/$workspace/src.old"
    done
}

mkdir -p "$STACK"
rm -f -- "$STACK/ready"
want="$(sources_stamp | sha256sum | cut -d' ' -f1)"
if [ "$(cat -- "$STACK/sources.stamp" 2>/dev/null)" != "$want" ]; then
    say "unpacking the C++ stack's sources into ${STACK#"$ROOT"/} (${LIST#"$ROOT"/})"
    rm -f -- "$STACK/sources.stamp"
    unpack
    printf '%s\n' "$want" >"$STACK/sources.stamp"
fi

start=$SECONDS
release=(--cmake-args -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF)
say "building the C++ stack with roc (the first time takes 10 to 20 minutes on 2 cores)"
# A clean environment of the wheels (what the venv's roc sees with nothing sourced), whatever the caller
# sourced; the stack then chains its underlay and the venv in its own setup scripts.
env -u AMENT_PREFIX_PATH -u COLCON_PREFIX_PATH -u CMAKE_PREFIX_PATH -u ROS_DISTRO \
    "$ROC" -C "$STACK/underlay" work build "${release[@]}" >&2 \
    || die "building the C++ stack's underlay failed (logs: ${STACK#"$ROOT"/}/underlay/log/latest_build)"
# composition_interfaces may already be in the venv (the launch system's installer builds it there).
env -u AMENT_PREFIX_PATH -u COLCON_PREFIX_PATH -u CMAKE_PREFIX_PATH -u ROS_DISTRO bash -c \
    'source "$1/underlay/install/setup.bash" && shift && exec "$@"' _ "$STACK" \
    "$ROC" -C "$STACK/stack" work build --allow-overriding composition_interfaces "${release[@]}" >&2 \
    || die "building the C++ stack failed (logs: ${STACK#"$ROOT"/}/stack/log/latest_build)"
printf '%s\n' "$want" >"$STACK/ready"
say "C++ stack ready in $((SECONDS - start)) s: source ${STACK#"$ROOT"/}/stack/install/setup.bash"
