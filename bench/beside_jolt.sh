#!/bin/bash
# The awake pile beside Jolt in the same minute: Jolt's jolt_pile and one or more tumble-run
# builds, alternated round by round, mean ms per step over the first 1.5 s (90 steps).
#
# Usage: bench/beside_jolt.sh JOLT_PILE N THREADS ROUNDS TUMBLE_RUN [TUMBLE_RUN ...]
#   JOLT_PILE   a program stepping the S1 pile in Jolt, built outside the tree (docs/PERFORMANCE.md,
#               "Beside Jolt", says what it prints)
#   TUMBLE_RUN  tumble-run of each build to compare (e.g. build/apps/tumble-run and an older one)
set -euo pipefail
if [ $# -lt 5 ]; then
  sed -n '2,8p' "$0" >&2
  exit 2
fi
jolt=$1 boxes=$2 threads=$3 rounds=$4
shift 4
for round in $(seq "$rounds"); do
  line="pile:$boxes threads $threads round $round: jolt $("$jolt" "$boxes" 90 "$threads" awake |
    grep -o 'mean_ms=[0-9.]*' | cut -d= -f2)"
  for run in "$@"; do
    ms=$("$run" --standard "pile:$boxes" --no-sleep --duration 1.5 --threads "$threads" 2>&1 |
      grep -o '([0-9.]* ms per step' | tr -d '(' | cut -d' ' -f1)
    line="$line | $run $ms"
  done
  echo "$line"
done
