#!/usr/bin/env bash
# The full check, which CI runs (.ci/run): the test command (tools/test.sh: missing packages,
# Release build, every test), then the AddressSanitizer + UndefinedBehaviorSanitizer build of the
# test suite (tools/sanitize.sh, build-asan/) and a bounded libFuzzer run of the plan and spec
# parsers (tools/fuzz.sh, build-fuzz/; installs clang when missing). Within CI's 15 minutes on a
# 2-core machine. Each step stops the script on failure with its status.
#   tools/check.sh [FUZZ_SECONDS]   (default 60)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash tools/test.sh
echo "==> sanitizers (ASan + UBSan test suite, build-asan/)"
bash tools/sanitize.sh
echo "==> fuzz (plan and spec parsers, ${1:-60} s, build-fuzz/)"
bash tools/fuzz.sh "${1:-60}"
