#!/usr/bin/env bash
# Runs the libFuzzer harnesses that a -DSONARBENCH_FUZZ=ON build made, as many at once as there
# are cores, each until SECONDS pass or RUNS inputs ran, on its seed corpus (fuzz/corpus/NAME,
# read only). New inputs and findings go under BUILD_DIR/fuzz-out/NAME/. Prints a line per
# harness: executions, coverage, and the finding; exits 1 if any harness found something.
# SEED=N fixes libFuzzer's seed (0, the default, draws one); RUNS=0 replays the corpus only.
#
#   fuzz/run.sh BUILD_DIR SECONDS [RUNS] [NAME...]       e.g. fuzz/run.sh build-fuzz 30
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "$1" && pwd)"
seconds="$2"
runs="${3:--1}"
shift $(($# < 3 ? $# : 3))
names=("$@")
if [ ${#names[@]} -eq 0 ]; then names=(scene sensor_model criteria mat_log mesh dataset octomap rosbag labels mapper); fi

run_one() {
  local name="$1" out="$build/fuzz-out/$1"
  rm -rf "$out" && mkdir -p "$out/new"
  local dict=()
  case "$name" in scene | sensor_model | criteria) dict=(-dict="$here/dict/yaml.dict") ;; esac
  # A finding: a crash, a sanitizer report, a leak, an input slower than 1 s, an allocation over
  # 512 MB, or the process past 512 MB.
  if "$build/fuzz/fuzz_$name" "${dict[@]}" -timeout=1 -malloc_limit_mb=512 -rss_limit_mb=512 \
      -max_total_time="$seconds" -runs="$runs" -seed="${SEED:-0}" -print_final_stats=1 \
      -artifact_prefix="$out/" "$out/new" "$here/corpus/$name" > "$out/log" 2>&1; then
    status=ok
  else
    status="FOUND $(ls "$out" | grep -E '^(crash|leak|oom|timeout|slow-unit)-' | head -1)"
  fi
  local execs cov
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$out/log" | tail -1 || true)  # none uninstrumented
  printf '%-13s %10s executions  %-20s %s\n' "$name" "${execs:-?}" "${cov:-}" "$status" \
    | tee "$out/summary"
  [ "$status" = ok ]
}

export LSAN_OPTIONS="suppressions=$here/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
jobs=$(nproc)
running=0
failed=0
for name in "${names[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  run_one "$name" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
if [ "$failed" -ne 0 ]; then
  echo "fuzz/run.sh: a harness found an input that breaks the contract; see $build/fuzz-out/" >&2
  grep -h -A3 -E '^==[0-9]+==ERROR|^SUMMARY' "$build"/fuzz-out/*/log | head -40 >&2 || true
fi
exit "$failed"
