#!/usr/bin/env bash
# `pip install .` as a Python user runs it: into a fresh venv (Debian's numpy through
# --system-site-packages), offline, the wheel built by setup.py from the suite's own CMake build
# folder (EVLDT_CMAKE_BUILD_DIR: only what changed is rebuilt); then an example runs from outside the
# source tree on the installed package. Usage: wheel_test.sh SOURCE_DIR BUILD_DIR PYTHON
set -euo pipefail
root=$1 build=$2 python=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset PYTHONPATH
fail() { echo "FAIL: $*"; exit 1; }

"$python" -m venv --system-site-packages "$work/venv"
EVLDT_CMAKE_BUILD_DIR=$build "$work/venv/bin/pip" install --no-build-isolation --no-index --quiet "$root" >"$work/pip.txt" 2>&1 ||
  fail "pip install: $(cat "$work/pip.txt")"
cd "$work"
where=$("$work/venv/bin/python" -c "import evldt; print(evldt.__file__)")
[[ $where == "$work/venv/"* ]] || fail "evldt imported from $where, not the venv"
out=$("$work/venv/bin/python" "$root/libs/python/examples/evaluate_scene.py" three-lines-fast 0.3)
echo "$out"
f=$(sed -nE 's/^  at 1% of the diagonal: .* F (0\.[0-9]+)$/\1/p' <<<"$out")
[[ -n $f ]] || fail "no F@1% in the example's output"
awk -v f="$f" 'BEGIN { exit !(f >= 0.8) }' || fail "the installed module scores F@1% $f on three-lines-fast (the tools: 0.9)"
"$work/venv/bin/pip" uninstall --yes --quiet evldt
echo "ok: pip install . into a fresh venv, evaluate_scene.py from there: F@1% $f"
