#!/usr/bin/env bash
# Fresh Debian machine, as root: installs the missing packages, builds the program it runs
# (build/tools/artcal: the library and the command line, Release) in build/ and runs the seed's
# example end to end (check and evaluate of plans/paper-2r-5bars.json). The tests, the Python
# module, the URDF module and the benchmarks are not built here: tools/test.sh builds them (or
# `cmake --build build`).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source tools/setup.sh

install_missing_packages
ARTCAL_BUILD_TARGETS=artcal_cli build_in build
run_example plans/paper-2r-5bars.json
