#!/usr/bin/env bash
# The project's own metric regression check (docs/check.md): the CI scenes run and judged
# against the baselines committed in baselines/.
#   tools/ci_baselines.sh check WINGMAN OUT   run the scenes into OUT (fresh) and `wingman check`
#                                             each; JUnit and Markdown reports in OUT/reports/.
#                                             Exit 0 when all pass, 1 when one regressed, 2 for bad input.
#   tools/ci_baselines.sh make WINGMAN OUT    run them and write baselines/ anew (after a change
#                                             that is meant to move the metrics; review the diff).
# Scenes: the synthetic smoke scene (one run; synthetic results are the same on every machine),
# the rendered smoke scene (one run, judged by the `mean` rule against a baseline of seeds 1-6:
# llvmpipe on another CPU may draw slightly other pixels, which moves a single run's metrics by
# less than a seed does), and a 4-seed Monte Carlo of the smoke scene (judged seed by seed).
set -euo pipefail
mode=${1:?usage: tools/ci_baselines.sh check|make WINGMAN OUT}
wingman=$(realpath "${2:?wingman binary}")
out=${3:?output directory}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

case "$mode" in check|make) ;; *) echo "usage: tools/ci_baselines.sh check|make WINGMAN OUT" >&2; exit 2 ;; esac
rm -rf "$out"
mkdir -p "$out/reports"

"$wingman" run scenes/smoke.yaml --out "$out/smoke" --no-plots -q
"$wingman" montecarlo scenes/smoke.yaml --runs 4 --out "$out/smoke_montecarlo" --no-plots -q
if [ "$mode" = make ]; then
  "$wingman" montecarlo scenes/rendered_smoke.yaml --runs 6 --out "$out/rendered_smoke" --no-plots -q
  "$wingman" baseline "$out/rendered_smoke" --rule mean --out baselines/rendered_smoke.yaml --force
  "$wingman" baseline "$out/smoke" --out baselines/smoke.yaml --force
  "$wingman" baseline "$out/smoke_montecarlo" --out baselines/smoke_montecarlo.yaml --force
  exit 0
fi
"$wingman" run scenes/rendered_smoke.yaml --out "$out/rendered_smoke" --no-plots -q

rc=0
for name in smoke rendered_smoke smoke_montecarlo; do
  set +e
  "$wingman" check "$out/$name" --baseline "baselines/$name.yaml" \
    --junit "$out/reports/$name.xml" --markdown "$out/reports/$name.md" --json "$out/reports/$name.json"
  r=$?
  set -e
  [ "$r" -gt "$rc" ] && rc=$r
done
exit "$rc"
