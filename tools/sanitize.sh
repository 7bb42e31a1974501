#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the whole test suite, run with ctest.
#   tools/sanitize.sh
# Builds in build-asan/ (-DARTCAL_SANITIZE=ON, RelWithDebInfo at -O1 with asserts on: quicker to build than -O2,
# far quicker to run than -O0). Any report fails the run: UBSan does not recover
# (-fno-sanitize-recover=all), ASan and LeakSanitizer abort the test that trips them.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build-asan"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DARTCAL_SANITIZE=ON \
  -DARTCAL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j 2 >"$build/build.log" 2>&1 || { tail -40 "$build/build.log" >&2; exit 1; }

export ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir "$build" --output-on-failure -j 2
