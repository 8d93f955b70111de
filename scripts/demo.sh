#!/usr/bin/env bash
# The main job on the bundled humanoid; grows with each feature.
set -euo pipefail
ROBOT=$(python -c "import scenarios; print(scenarios.HUMANOID)")
twin convert "$ROBOT" -o twin_out/humanoid
