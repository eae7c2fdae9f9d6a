#!/usr/bin/env bash
# Formatting and lint checks, as the test command runs them (.ci/test).
#
#   bash tools/check_format.sh          ruff check (lint rules in pyproject.toml [tool.ruff.lint])
#   bash tools/check_format.sh --all    also clang-format --dry-run --Werror and ruff format --check
#
# The test command (.ci/test) runs --all: the tree is formatted (the one formatting commit is listed
# in .git-blame-ignore-revs), so unformatted code fails the tests. ruff is pinned in .ci/setup.
# To format: clang-format-14 -i <files>  and  ruff format python experiments tests benchmarks examples docs tools.
set -euo pipefail
cd "$(dirname "$0")/.."
PY_DIRS="python experiments tests benchmarks examples docs tools"
echo "[format] ruff check $PY_DIRS"
python3 -m ruff check $PY_DIRS
if [ "${1:-}" = "--all" ]; then
  echo "[format] ruff format --check $PY_DIRS"
  python3 -m ruff format --check $PY_DIRS
  CLANG_FORMAT="${CLANG_FORMAT:-clang-format-14}"
  echo "[format] $CLANG_FORMAT --dry-run --Werror on the C++ sources"
  git ls-files -- '*.cpp' '*.hpp' | xargs "$CLANG_FORMAT" --dry-run --Werror
fi
