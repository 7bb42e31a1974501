#!/usr/bin/env bash
# The full check, which CI runs (.ci/run): the test command (tools/test.sh: missing packages,
# Release build, every test), then the clang AddressSanitizer + UndefinedBehaviorSanitizer build
# of the test suite and the fuzz harnesses (tools/sanitize.sh, build-asan/; installs clang when
# missing) and a bounded libFuzzer run of the plan and spec parsers in that same build
# (tools/fuzz.sh). Budget: 25 minutes on a fresh clone of a 2-core machine, packages included
# (the sanitizer suite leaves to the Release run the tests labelled long, tests/CMakeLists.txt).
# Each step stops the script on failure with its status.
#   tools/check.sh [FUZZ_SECONDS]   (default 60)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# Headless Chromium and poppler-utils: the report PDF test (tests/report/test_report_pdf.cpp)
# renders the reports of plans/ and reads the PDFs; without them it skips.
(source tools/setup.sh && ARTCAL_PACKAGES=(chromium poppler-utils) && install_missing_packages)
bash tools/test.sh
echo "==> sanitizers (ASan + UBSan test suite, build-asan/)"
bash tools/sanitize.sh
echo "==> fuzz (plan and spec parsers, ${1:-60} s, build-asan/)"
bash tools/fuzz.sh "${1:-60}"
