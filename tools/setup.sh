# shellcheck shell=bash
# Steps shared by tools/demo.sh and tools/test.sh. Sourced, not run: each function is one step.

# The Debian packages artcal builds with (README.md, "Setup").
ARTCAL_PACKAGES=(build-essential cmake ninja-build libeigen3-dev libnlopt-cxx-dev
                 nlohmann-json3-dev libcli11-dev libgtest-dev libbenchmark-dev
                 liburdfdom-dev libtinyxml2-dev)

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
# and builds everything there.
build_in() {
  local dir=$1
  shift
  echo "==> building in $dir"
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  cmake --build "$dir" -j 2
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
