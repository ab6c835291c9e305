#!/usr/bin/env bash
# Installs the Debian packages (if missing), configures and builds stentsim
# in ./build (Release). Usage: bash scripts/build.sh [extra cmake args]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install-deps.sh"
cmake -S "$here" -B "$here/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$here/build" -j "$(nproc)"
