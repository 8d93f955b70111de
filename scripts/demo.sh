#!/usr/bin/env bash
# `make demo`: convert, spawn, run and validate the bundled humanoid, as a user would type it.
set -euo pipefail
ROBOT=$(python -c "import scenarios; print(scenarios.HUMANOID)")
echo "\$ twin convert humanoid.urdf.xacro -o twin_out/humanoid"
twin convert "$ROBOT" -o twin_out/humanoid

# The used-by flow against a running world (a world of its own, stopped on any exit).
export TWIN_WORLD="${TWIN_WORLD:-demo}"
trap 'twin stop >/dev/null 2>&1 || true' EXIT
echo "\$ twin spawn humanoid.urdf.xacro -z 1.2"
NAME=$(twin spawn "$ROBOT" -z 1.2)
echo "$NAME"
echo "\$ twin stats -d 2"
twin stats -d 2
echo "\$ twin gravity --moon"
twin gravity --moon
echo "\$ twin gravity"
twin gravity
echo "\$ twin list"
twin list
echo "\$ twin pose $NAME"
twin pose "$NAME"
echo "\$ twin delete $NAME"
twin delete "$NAME"
echo "\$ twin stop"
twin stop
trap - EXIT

# The physics checklist, in-process, as CI would run it.
echo "\$ twin validate humanoid.urdf.xacro --junit twin_out/validate.xml"
twin validate "$ROBOT" --junit twin_out/validate.xml
