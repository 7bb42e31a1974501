#!/usr/bin/env bash
# The test command (README.md): on a fresh Debian machine, as root, installs the missing packages,
# builds Release in build/ and runs every test (ctest labels `unit` and `stress`; none depends on
# timing). Each step is one line; a failing step stops the script with its status. The full
# check (this, the sanitizer suite and a bounded fuzz run) is tools/check.sh.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source tools/setup.sh

install_missing_packages
build_in build -DARTCAL_BUILD_BENCHMARKS=OFF
echo "==> ctest"
ctest --test-dir build --output-on-failure -j 2
