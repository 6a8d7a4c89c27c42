#!/usr/bin/env bash
# Installs dependencies, builds, and renders the demo outputs into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
JOBS=${JOBS:-$(nproc)}
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS" --target follicle
FOLLICLE=build/release/apps/cli/follicle
mkdir -p out
"$FOLLICLE" render data/scenes/default.json -o out/default.png
echo "demo: wrote out/default.png"
