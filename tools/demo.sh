#!/usr/bin/env bash
# Fresh Debian machine, as root: installs the missing packages, builds Release in build/ and runs
# the seed's example end to end (check and evaluate of plans/paper-2r-5bars.json).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source tools/setup.sh

install_missing_packages
build_in build
run_example plans/paper-2r-5bars.json
