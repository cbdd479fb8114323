#!/usr/bin/env bash
# The nightly check, too long for every CI run: the whole test suite under AddressSanitizer and
# UndefinedBehaviorSanitizer (undefined behaviour aborts), then the input fuzz campaign of
# docs/reliability.md against that sanitized binary.
#   tools/nightly.sh [BUILD_DIR]      (default build-asan; on 2 cores about 55 min of build, 20 of
#                                     tests, then the fuzz campaign: docs/reliability.md)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$here/build-asan}
# Optimised with debug information: the sanitizers' reports keep their lines, and the suite runs
# in a fraction of a Debug build's time.
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWINGMAN_ASAN=ON -DWINGMAN_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$(nproc)"
(cd "$build" && ctest -j "$(nproc)" --output-on-failure)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# ASan reserves a large virtual address space: the fuzzer's memory cap must leave room for it.
python3 "$here/tools/fuzz_inputs.py" --wingman "$build/app/wingman" --workdir "$work/fuzz" \
  --scenario-mutants 2000 --dataset-corruptions 300 --baseline-mutants 1000 --jobs "$(nproc)" --mem-gib 0 --timeout 300
