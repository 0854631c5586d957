#!/usr/bin/env bash
# The one test command: installs dependencies, builds, runs every test with ctest.
# README's "(b)" command and .ci/run call exactly this.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
cd build
ctest --output-on-failure --parallel "$(nproc)" --timeout 600
