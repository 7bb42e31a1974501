#!/usr/bin/env bash
# Fresh Debian machine, as root: installs the missing packages, builds Release in build/ and runs
# the whole test suite. Each step is one line; a failing step stops the script with its status.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source tools/setup.sh

install_missing_packages
build_in build
echo "==> ctest"
ctest --test-dir build --output-on-failure -j 2
echo "==> sanitizers (ASan + UBSan test suite, build-asan/)"
bash tools/sanitize.sh
echo "==> fuzz (plan and spec parsers, 60 s, build-fuzz/)"
bash tools/fuzz.sh 60
