#!/usr/bin/env bash
# Bounded libFuzzer run of the plan, design-spec, URDF and CSV readers and what runs behind them.
#   tools/fuzz.sh [SECONDS]   (default 60: four harnesses, two side by side at a time, SECONDS/2
#                              each: the whole run takes SECONDS, as with two harnesses before)
# Builds the harnesses in the sanitizer build, build-asan/ (tools/setup.sh build_sanitized, shared
# with tools/sanitize.sh: after it, nothing is rebuilt).
# The seed corpus is copied at run time from plans/, tests/data/ and tests/data/fuzz-regressions/
# into a temporary folder. Exit status non-zero on any finding; the crashing input is kept in
# build-asan/findings/ and belongs in tests/data/fuzz-regressions/ with a test in
# tests/cli/test_hardening.cpp.
set -euo pipefail

seconds=${1:-60}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build-asan"
targets=(fuzz_plan fuzz_spec fuzz_urdf fuzz_csv)
# The JSON harnesses start from the plans and test data, the others from their own corpora.
declare -A seeds_of=(
  [fuzz_plan]="plans tests/data tests/data/fuzz-regressions"
  [fuzz_spec]="plans tests/data tests/data/fuzz-regressions"
  [fuzz_urdf]="tests/fuzz/corpus/urdf tests/data/urdf tests/data/hostile"
  [fuzz_csv]="tests/fuzz/corpus/csv tests/data/mukca"
)
declare -A dict_of=([fuzz_plan]=plan.dict [fuzz_spec]=plan.dict [fuzz_urdf]=urdf.dict
  [fuzz_csv]=csv.dict)
half=$(((seconds + 1) / 2))

cd "$root"
source tools/setup.sh
build_sanitized "$build" "${targets[@]}"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for target in "${targets[@]}"; do
  mkdir -p "$work/$target"
  read -r -a seeds <<<"${seeds_of[$target]}"
  for dir in "${seeds[@]}"; do
    if [ -d "$root/$dir" ] && compgen -G "$root/$dir/*" >/dev/null; then
      find "$root/$dir" -maxdepth 1 -type f -exec cp {} "$work/$target/" \;
    fi
  done
done
# Design specs (docs/plan-format.md, optimize): a plan without placements plus a design block.
cat >"$work/fuzz_spec/spec-2r.json" <<'JSON'
{"format": "artcal-plan/1", "name": "spec-2r",
 "machine": {"model": "planar2r", "parameters": {"l1": 150, "l2": 100, "dt2": 0},
             "joint_limits": [[-180, 180], [-170, 170]]},
 "noise": {"probe": 0.005, "encoder": 0.001},
 "artifacts": {"bar80": {"type": "ball_bar", "length": 80}},
 "workspace": {"samples": 16, "seed": 1},
 "design": {"artifact": "bar80", "placements": 5, "postures": 1,
            "region": {"reach": [55, 245]}, "criterion": "worst-tip", "seed": 1, "starts": 4,
            "time_limit": 5}}
JSON
cat >"$work/fuzz_spec/spec-dh.json" <<'JSON'
{"format": "artcal-plan/1", "name": "spec-dh",
 "machine": {"model": "serial-dh",
             "joints": [{"d": 200, "alpha": 90}, {"alpha": -90}, {"d": 600, "alpha": 90},
                        {"type": "prismatic", "alpha": -90}],
             "joint_limits": [[-180, 180], [-90, 90], [-180, 180], [0, 100]],
             "probe": [0, 0, 100]},
 "noise": {"probe": 0.005, "encoder": [0.001, 0.001, 0.001, 0.0005]},
 "artifacts": {"plate": {"type": "ball_plate", "centers": [[0, 0, 0], [100, 0, 0], [0, 100, 0]]},
               "gauge": {"type": "step_gauge", "positions": [0, 20, 40]}},
 "placements": [{"artifact": "gauge", "pose": {"center": [300, 0, 100], "direction": [1, 0, 0]}}],
 "workspace": {"grid": [2, 2, 2, 2]},
 "design": {"artifact": "plate", "placements": 3, "postures": 2,
            "region": {"box": [[200, -200, 0], [600, 200, 300]]}, "criterion": "D"}}
JSON

mkdir -p "$build/findings"
status=0
# Two rounds of two harnesses side by side (two cores), SECONDS/2 each.
for round in "fuzz_plan fuzz_urdf" "fuzz_spec fuzz_csv"; do
  read -r -a pair <<<"$round"
  pids=()
  for target in "${pair[@]}"; do
    "$build/tests/fuzz/$target" "$work/$target" -dict="$root/tests/fuzz/${dict_of[$target]}" \
      -max_total_time="$half" -timeout=20 -rss_limit_mb=2048 -max_len=65536 \
      -print_final_stats=1 -artifact_prefix="$build/findings/$target-" \
      >"$build/$target.log" 2>&1 &
    pids+=($!)
  done
  for i in "${!pair[@]}"; do
    target=${pair[$i]}
    if wait "${pids[$i]}"; then
      runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$build/$target.log")
      rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$build/$target.log")
      echo "fuzz.sh: $target: no finding in ${half} s, $runs executions ($rate/s)"
    else
      status=1
      echo "fuzz.sh: $target: FINDING (log $build/$target.log, input in $build/findings/)" >&2
      grep -E 'ERROR|fuzz finding|runtime error|==[0-9]+==' "$build/$target.log" | head -5 >&2 || true
    fi
  done
done
exit $status
