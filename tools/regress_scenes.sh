#!/usr/bin/env bash
# Runs every shipped scene (or those named) with one wingman binary, seed 1, every variant:
# synthetic scenes whole, rendered ones over their first 20 s. Compare two such trees, made
# before and after a change, with `wingman check A --against B` (every data file, timings
# aside; docs/check.md) to show that the change leaves results unchanged.
#   tools/regress_scenes.sh WINGMAN OUTDIR [scenes/X.yaml ...]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ $# -ge 2 ] || { sed -n 2,6p "$0"; exit 2; }
wingman=$(realpath "$1"); out=$2; shift 2
[ -e "$out" ] && { echo "regress_scenes: $out exists; choose a new directory" >&2; exit 2; }
mkdir -p "$out"
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$here"/scenes/*.yaml)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for s in "${scenes[@]}"; do
  name=$(basename "$s" .yaml)
  scn=$s
  if grep -q '^measurements: *rendered' "$s"; then
    scn=$tmp/$name.yaml
    python3 "$here/tools/truncate_scenario.py" "$s" 20 "$scn"
  fi
  start=$(date +%s)
  if "$wingman" run "$scn" --seed 1 --out "$out/$name" --no-plots -q > "$out/$name.log" 2>&1; then
    echo "$name: ran in $(( $(date +%s) - start )) s"
  else
    echo "$name: FAILED (exit $?), see $out/$name.log"
  fi
done
