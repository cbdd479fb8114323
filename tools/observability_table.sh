#!/usr/bin/env bash
# Unobservable-mode counts without GPS for configurations 1-3 at Lie orders 1-3, beside the
# paper's Table 2, as the markdown table of docs/observability.md. Every cell is one run of
#   wingman observability --config C --no-gps --order K --uavs 2 --landmarks N --json
# Usage: tools/observability_table.sh [path/to/wingman] [landmarks] [seed]
set -euo pipefail
WINGMAN=${1:-build/app/wingman}
N1=${2:-6}
SEED=${3:-1}
modes() {
  "$WINGMAN" observability --config "$1" --no-gps --order "$2" --uavs 2 --landmarks "$N1" \
    --seed "$SEED" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["unobservable_modes"])'
}
declare -A PAPER=([1]=4 [2]=6 [3]=2)
echo "| configuration (no GPS) | paper, Table 2 | order 1 | order 2 | order 3 |"
echo "| --- | --- | --- | --- | --- |"
for c in 1 2 3; do
  echo "| $c | ${PAPER[$c]} | $(modes $c 1) | $(modes $c 2) | $(modes $c 3) |"
done
echo
echo "2 UAVs, $N1 landmarks all shared, generic state (seed $SEED), rank tolerance 1e-8 (relative)."

# Fig. 4's minimum conditions: the modes with each one removed (orders 1 and 2).
cond() {
  local label=$1; shift
  local m1 m2
  m1=$("$WINGMAN" observability "$@" --order 1 --uavs 2 --landmarks "$N1" --seed "$SEED" --json |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["unobservable_modes"])')
  m2=$("$WINGMAN" observability "$@" --order 2 --uavs 2 --landmarks "$N1" --seed "$SEED" --json |
    python3 -c 'import json,sys; print(json.load(sys.stdin)["unobservable_modes"])')
  echo "| $label | \`$*\` | $m1 | $m2 |"
}
H=$((N1 / 2))
echo
echo "| sensor set | flags | order 1 | order 2 |"
echo "| --- | --- | --- | --- |"
cond "config 3, no GPS" --config 3 --no-gps
cond "− no landmark shared" --config 3 --no-gps --visibility "uav1:0-$((H - 1)),uav2:$H-$((N1 - 1))"
cond "− one landmark shared" --config 3 --no-gps --visibility "uav1:0-$H,uav2:$H-$((N1 - 1))"
cond "− two landmarks shared" --config 3 --no-gps --visibility "uav1:0-$H,uav2:$((H - 1))-$((N1 - 1))"
cond "− lead not seen" --config 3 --no-gps --sees-lead none
cond "− no range" --config 3 --no-gps --range none
cond "− no range, both UAVs see the lead" --config 3 --no-gps --range none --sees-lead uav1,uav2
cond "− no altimeter" --config 3 --no-gps --altimeter none
cond "config 1, GPS" --config 1
cond "− lead not seen" --config 1 --sees-lead none
cond "− no landmark shared" --config 1 --visibility "uav1:0-$((H - 1)),uav2:$H-$((N1 - 1))"
cond "config 1, no GPS, both UAVs see the lead" --config 1 --no-gps --sees-lead uav1,uav2
cond "config 2, GPS" --config 2
cond "− no range" --config 2 --range none
cond "− no altimeter" --config 2 --altimeter none
cond "− no landmark shared" --config 2 --visibility "uav1:0-$((H - 1)),uav2:$H-$((N1 - 1))"
