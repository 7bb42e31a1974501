#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer run of the whole test suite.
#   tools/sanitize.sh
# Builds with clang in build-asan/ (tools/setup.sh build_sanitized: -O1, line tables, the fuzz
# harnesses in the same build so that tools/fuzz.sh reuses it) and runs the test suite with ctest.
# Any report fails the run: UBSan does not recover (-fno-sanitize-recover=all), ASan and
# LeakSanitizer abort the test that trips them.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source tools/setup.sh

build_sanitized build-asan
export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
echo "==> ctest (sanitizers)"
# The report PDF test renders with Chromium: minutes under the sanitizers for nothing they check
# (the report code runs in the other report tests); it runs in tools/test.sh.
# The installed-package test (label install) is left out: its consumer would link the sanitized
# static libraries without the sanitizer flags of their build. The tests labelled long
# (tests/CMakeLists.txt: Monte-Carlo agreements, loops over every plan, a million placements)
# repeat code that other tests run once; they run in tools/test.sh.
ctest --test-dir build-asan --output-on-failure -j 2 -E '^ReportPdf\.' -LE '^install$|^long$'
