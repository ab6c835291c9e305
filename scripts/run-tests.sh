#!/usr/bin/env bash
# Installs, builds and runs the default test set (label "quick"; a few
# minutes). Long validation runs are opt-in: ctest --test-dir build -L validation
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/build.sh"
ctest --test-dir "$here/build" -L quick --output-on-failure -j "$(nproc)" --timeout 900
