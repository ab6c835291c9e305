#!/usr/bin/env bash
# Contact benchmark at the paper's scale: the 11-ring stent (588
# Hermite elements, 6 Gauss points each: 3,528 beam points per beam pair, 7,056
# over both) against the 18 mm balloon (35 x 79 = 2,765 hex8, its outer face)
# and a tet10 wall tube around them; the balloon's outer face against the wall
# by surface-to-surface contact. Writes the device files with the stentsim
# stages, then times search, evaluation + assembly per Newton iteration next
# to one direct solve of the whole system (bench_contact.cpp).
#   bash solver/bench/bench_contact.sh [BUILD_DIR]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$here/build}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
ninja -C "$build" stentsim bench_contact > /dev/null
cat > "$work/device.yaml" <<'YAML'
stent: {rings: 11}
balloon: {length: 18.0, elements_around: 35, elements_along: 79}
YAML
"$build/workflows/stentsim" stent --device "$work/device.yaml" --out "$work/stent.vtu" > /dev/null
"$build/workflows/stentsim" balloon --device "$work/device.yaml" --out "$work/balloon.vtu" > /dev/null
"$build/solver/bench_contact" "$work/stent.vtu" "$work/balloon.vtu" "${@:2}"
