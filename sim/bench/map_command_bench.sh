#!/usr/bin/env bash
# The whole `sonarbench map LOG.mat` command against the naive OctoMap pipeline, in one run:
# pipeline_bench's naive row first, then the command with `integration: exact` and with
# `integration: rays` (32 x 64), each run REPEATS times: median wall time (bash's clock around the
# command), the stages report.json times (import, map) and the rest (start-up, images, .bt/.ot,
# report), and the peak resident memory (GNU time's maximum RSS) of the median run.
#
#   sim/bench/map_command_bench.sh [BUILD_DIR] [REPEATS] [RESOLUTION_M]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
repeats=${2:-5}
resolution=${3:-0.05}
log=data/cras-tank-static/dataset_static.mat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

naive=$("$build/mapping/bench/pipeline_bench" "$log" --exact-only --repeats 1 \
          --resolution "$resolution" | awk '/^naive OctoMap/ {print $(NF-1)}')
echo "log $log, resolution $resolution m, $(nproc) cores; naive OctoMap pipeline: $naive s"
printf '%-8s %9s %9s %9s %9s %10s %9s\n' integration "median s" "import s" "map s" "rest s" \
  "peak MiB" "vs naive"
for mode in exact rays; do
  printf 'integration: %s\nresolution_m: %s\n' "$mode" "$resolution" > "$work/$mode.yaml"
  rows=()
  for ((r = 0; r < repeats; r++)); do
    start=$EPOCHREALTIME
    /usr/bin/time -f '%M' -o "$work/time" "$build/sim/sonarbench" map "$log" \
      --mapping "$work/$mode.yaml" --out "$work/out-$mode" --no-progress > /dev/null
    wall=$(awk -v start="$start" -v end="$EPOCHREALTIME" 'BEGIN {print end - start}')
    read -r kib < "$work/time"
    stages=$(python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['timing']; \
print(t['import_s'], t['map_s'])" "$work/out-$mode/report.json")
    rows+=("$wall $kib $stages")
  done
  printf '%s\n' "${rows[@]}" | sort -n | awk -v n="$repeats" -v naive="$naive" -v mode="$mode" \
    'NR == int((n + 1) / 2) {printf "%-8s %9.3f %9.3f %9.3f %9.3f %10.0f %8.2fx\n", mode, $1, $3,
       $4, $1 - $3 - $4, $2 / 1024, naive / $1}'
done
