#!/usr/bin/env bash
# Installs, builds and runs the default test set (label "quick"; a few
# minutes), then the sanitizer job (scripts/run-sanitizers.sh). Long validation
# runs are opt-in: ctest --test-dir build -L validation
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/build.sh"
ctest --test-dir "$here/build" -L quick --output-on-failure -j "$(nproc)" --timeout 900
bash "$here/scripts/run-sanitizers.sh"
