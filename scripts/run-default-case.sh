#!/usr/bin/env bash
# The main job on the bundled default case: installs, builds, then runs the
# patient example (the synthetic case2-rca phantom) end to end. A second call
# re-runs only what is stale.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/build.sh"
"$here/build/workflows/stentsim" run "$here/examples/patient.yaml" "$@"
