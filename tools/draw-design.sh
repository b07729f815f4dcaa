#!/usr/bin/env bash
# Draws the design page's diagrams (docs/design/*.dot -> .svg) with graphviz (Debian's graphviz).
set -euo pipefail
cd "$(dirname "$0")/../docs/design"
command -v dot >/dev/null || { echo "graphviz is missing: apt-get install graphviz" >&2; exit 1; }
for source in *.dot; do
  dot -Tsvg "$source" -o "${source%.dot}.svg"
  echo "wrote docs/design/${source%.dot}.svg"
done
