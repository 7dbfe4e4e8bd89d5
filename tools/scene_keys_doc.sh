#!/usr/bin/env bash
# Regenerate the key table at the end of docs/scene.md from `softpack keys`
# (test_scene checks that the doc holds the program's table verbatim).
# usage: tools/scene_keys_doc.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
line=$(grep -n '^| key | type | unit | default | allowed | meaning |$' docs/scene.md | cut -d: -f1)
[ -n "$line" ] || { echo "docs/scene.md: no key table found" >&2; exit 2; }
{ head -n $((line - 1)) docs/scene.md; "$build/softpack" keys; } > docs/scene.md.tmp
mv docs/scene.md.tmp docs/scene.md
