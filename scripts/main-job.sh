#!/usr/bin/env bash
# The main job on its built-in default: installs dependencies, builds, then runs
# `colonflat run` (no INPUT: generates the full phantom, seed 1) into ./colonflat_out.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh -DCOLONFLAT_BUILD_TESTS=OFF -DCOLONFLAT_BUILD_BENCH=OFF
./build/apps/colonflat run -o colonflat_out "$@"
