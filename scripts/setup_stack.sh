#!/usr/bin/env bash
# A stack of upstream sources built by roc on .venv's ROS 2 Jazzy wheels, for roc's development and CI:
#   bash scripts/setup_stack.sh cpp    rclcpp and what rclcpp_components needs, the demos' and examples'
#                                      C++ nodes (requirements/cpp-stack.txt; the tests marked cpp)
#   bash scripts/setup_stack.sh rmw    rmw_cyclonedds on Debian's cyclonedds-dev (requirements/rmw-stack.txt;
#                                      the tests marked rmw)
# Run by `bash scripts/setup.sh --with-cpp` and `--with-cyclonedds` after the venv is set up.
#
# NAME-stack.txt names the tarballs of ../shared/sources (unchanged upstream sources; MANIFEST.txt there
# says each one's repository, tag and commit), the workspace under .NAME-stack/ (ignored by git) each goes
# to, and the package folders taken from it; its `args` line holds roc's extra build arguments. The
# workspaces are built in the order the list first names them, each on the ones before it (sourced), all
# Release with tests off (the wheels have no ament_lint_auto). The sources are unpacked again only when the
# list's tarball lines or a tarball changed (.NAME-stack/sources.stamp); the builds are roc's, so an unchanged re-run costs
# a no-op build per workspace. The last workspace's install/setup.bash is the stack, ready to source, once
# .NAME-stack/ready exists.
# Environment: ROC_SHARED (the shared folder holding sources/, default ../shared beside the checkout).
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
NAME="${1:?usage: bash scripts/setup_stack.sh cpp|rmw}"
VENV="$ROOT/.venv"
STACK="$ROOT/.$NAME-stack"
LIST="$ROOT/requirements/$NAME-stack.txt"
SOURCES="${ROC_SHARED:-$ROOT/../shared}/sources"
ROC="$VENV/bin/roc"

say() { printf 'setup: %s\n' "$*" >&2; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

[ -f "$LIST" ] || die "no stack named '$NAME' (requirements/$NAME-stack.txt does not exist)"
[ -x "$ROC" ] || die "$ROC is missing: run bash scripts/setup.sh first"
[ -d "$SOURCES" ] || die "the sources are not at $SOURCES (set ROC_SHARED to the folder holding sources/)"
command -v c++ >/dev/null 2>&1 && command -v cmake >/dev/null 2>&1 \
    || die "the $NAME stack needs cmake and a C++ compiler (on Debian: apt-get install cmake g++)"

# the tarball lines of the list: WORKSPACE TARBALL FOLDER...
entries() { grep -v -E '^[[:space:]]*(#|$|args )' "$LIST"; }
read -r -a extra <<<"$(sed -n 's/^args //p' "$LIST")"
mapfile -t workspaces < <(entries | awk '!seen[$1]++ {print $1}')

sources_stamp() {
    entries
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
    for workspace in "${workspaces[@]}"; do
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
    say "unpacking the $NAME stack's sources into ${STACK#"$ROOT"/} (${LIST#"$ROOT"/})"
    rm -f -- "$STACK/sources.stamp"
    unpack
    printf '%s\n' "$want" >"$STACK/sources.stamp"
fi

start=$SECONDS
say "building the $NAME stack with roc (its workspaces: ${workspaces[*]}; a first build of the cpp stack takes 10 to 20 minutes on 2 cores)"
below=()  # the setup scripts of the workspaces built so far
for workspace in "${workspaces[@]}"; do
    # A clean environment of the wheels (what the venv's roc sees with nothing sourced), whatever the caller
    # sourced, with the workspaces below sourced; the stack's setup scripts then chain them and the venv.
    env -u AMENT_PREFIX_PATH -u COLCON_PREFIX_PATH -u CMAKE_PREFIX_PATH -u ROS_DISTRO bash -c \
        'for setup in "${@:2:$1}"; do source "$setup"; done; shift $(($1 + 1)); exec "$@"' _ \
        "${#below[@]}" ${below[@]+"${below[@]}"} \
        "$ROC" -C "$STACK/$workspace" work build ${extra[@]+"${extra[@]}"} \
        --cmake-args -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF >&2 \
        || die "building the $NAME stack's $workspace failed (logs: ${STACK#"$ROOT"/}/$workspace/log/latest_build)"
    below+=("$STACK/$workspace/install/setup.bash")
done
printf '%s\n' "$want" >"$STACK/ready"
say "$NAME stack ready in $((SECONDS - start)) s: source ${STACK#"$ROOT"/}/${workspaces[-1]}/install/setup.bash"
