#!/usr/bin/env bash
# Checks that every C++ source of the repository is laid out as .clang-format says (clang-format 14).
# Usage: tests/lint/format.sh [--fix]   (--fix rewrites the files in place)
set -euo pipefail
cd "$(dirname "$0")/../.."
mapfile -t sources < <(git ls-files '*.cpp' '*.hpp' '*.h')
if [[ ${1:-} == --fix ]]; then
  clang-format -i "${sources[@]}"
  exit 0
fi
if ! clang-format --dry-run --Werror "${sources[@]}" 2>/tmp/evldt-format.$$; then
  grep -oE '^[^:]+\.(cpp|hpp|h):' /tmp/evldt-format.$$ | sort -u | sed 's/:$//; s/^/  not formatted: /' >&2
  rm -f /tmp/evldt-format.$$
  echo "clang-format: run tests/lint/format.sh --fix" >&2
  exit 1
fi
rm -f /tmp/evldt-format.$$
echo "clang-format: ${#sources[@]} sources laid out as .clang-format says"
