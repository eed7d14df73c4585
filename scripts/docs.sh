#!/usr/bin/env bash
# Build the manual (docs/, MkDocs with mkdocs-material) into site/, with warnings as errors:
#   bash scripts/docs.sh          # site/index.html
#   bash scripts/docs.sh serve    # preview at http://127.0.0.1:8000, rebuilt on every change
# Sets up .venv first (scripts/setup.sh, quick when nothing changed): mkdocs comes with the test extra.
set -euo pipefail

ROOT="$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd -P)"
cd "$ROOT"
bash "$ROOT/scripts/setup.sh"
export NO_MKDOCS_2_WARNING=1  # mkdocs-material's notice about MkDocs 2, printed at every build

case "${1:-build}" in
    build) exec "$ROOT/.venv/bin/mkdocs" build --strict "${@:2}" ;;
    serve) exec "$ROOT/.venv/bin/mkdocs" serve --strict "${@:2}" ;;
    *) echo "docs: error: unknown command '$1' (use: build, serve)" >&2; exit 2 ;;
esac
