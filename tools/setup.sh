# shellcheck shell=bash
# Steps shared by tools/demo.sh and tools/test.sh. Sourced, not run: each function is one step.

# The Debian packages artcal builds with (README.md, "Setup").
ARTCAL_PACKAGES=(build-essential cmake ninja-build libeigen3-dev libnlopt-cxx-dev
                 nlohmann-json3-dev libcli11-dev libgtest-dev libbenchmark-dev
                 liburdfdom-dev libtinyxml2-dev
                 pybind11-dev python3-dev python3-numpy python3-pytest python3-hypothesis)

# Prints the packages of ARTCAL_PACKAGES that are not installed, one per line.
missing_packages() {
  local package
  for package in "${ARTCAL_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed'; then
      echo "$package"
    fi
  done
}

# Installs whatever is missing (apt-get as root, or through sudo); silent when nothing is.
install_missing_packages() {
  local missing
  mapfile -t missing < <(missing_packages)
  if ((${#missing[@]} == 0)); then
    return 0
  fi
  local as_root=()
  if ((EUID != 0)); then
    if ! command -v sudo >/dev/null; then
      echo "error: missing packages (${missing[*]}); run as root to install them" >&2
      return 1
    fi
    as_root=(sudo)
  fi
  echo "==> installing ${missing[*]}"
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y -qq --no-install-recommends "${missing[@]}" </dev/null
}

# build_in DIR [CMAKE_OPTION...]: configures a Release build in DIR (more options may override)
# and builds everything there, or only the targets named in ARTCAL_BUILD_TARGETS (a list).
build_in() {
  local dir=$1 target targets=()
  shift
  for target in ${ARTCAL_BUILD_TARGETS:-}; do targets+=(--target "$target"); done
  echo "==> building in $dir${ARTCAL_BUILD_TARGETS:+ (${ARTCAL_BUILD_TARGETS})}"
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DARTCAL_UNITY=ON "$@" >/dev/null
  cmake --build "$dir" -j 2 "${targets[@]}"
}

# run_example PLAN: the walk-through of README.md, check then evaluate, tables printed.
run_example() {
  local plan=$1
  echo "==> artcal check $plan"
  build/tools/artcal check "$plan"
  echo
  echo "==> artcal evaluate $plan"
  build/tools/artcal evaluate "$plan"
}

# True when clang++ can build a libFuzzer harness with ASan and UBSan.
have_libfuzzer() {
  local probe status
  probe=$(mktemp -d)
  echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' \
    >"$probe/p.cpp"
  clang++ -fsanitize=fuzzer,address,undefined "$probe/p.cpp" -o "$probe/p" >/dev/null 2>&1
  status=$?
  rm -rf "$probe"
  return $status
}

# clang and its libFuzzer runtime (Debian: clang, libclang-rt-14-dev), installed when missing.
install_clang_if_missing() {
  if command -v clang++ >/dev/null 2>&1 && have_libfuzzer; then
    return 0
  fi
  local ARTCAL_PACKAGES=(clang libclang-rt-14-dev)
  install_missing_packages
  have_libfuzzer || { echo "error: clang cannot build a libFuzzer harness" >&2; return 1; }
}

# build_sanitized DIR [TARGET...]: the one instrumented build of the full check, with clang:
# AddressSanitizer + UndefinedBehaviorSanitizer on the library, the tests and the libFuzzer
# harnesses (-DARTCAL_FUZZ=ON), -O1 with line tables (quick to build, stack traces with lines).
# The sanitizer suite (tools/sanitize.sh) and the fuzz run (tools/fuzz.sh) share it.
build_sanitized() {
  local dir=$1 target targets=()
  shift
  for target in "$@"; do targets+=(--target "$target"); done
  install_clang_if_missing
  echo "==> building the sanitizer build in $dir"
  cmake -S . -B "$dir" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DARTCAL_FUZZ=ON \
    -DARTCAL_UNITY=ON -DARTCAL_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$dir" -j 2 "${targets[@]}" >"$dir/build.log" 2>&1 ||
    { tail -40 "$dir/build.log" >&2; return 1; }
}
