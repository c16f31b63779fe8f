#!/bin/sh
# One bounded fuzz run for ctest (tests/fuzz/CMakeLists.txt):
#   run_fuzz.sh <fuzzer> <seed folder> <work folder> <seconds> [libFuzzer options...]
# Fuzzes a fresh copy of the seeds in <work folder>/corpus (new inputs stay there, not in
# the source tree); a crashing input lands in <work folder>/artifacts. libFuzzer's exit
# code is the test's. FUZZ_OPTIONS in the environment adds libFuzzer options (CI: -seed=1).
set -eu
# UBSan's reports with their stacks (the build makes every report fatal).
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
# OCCT's own allocations are not leak-checked (lsan.supp says why).
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$(dirname "$0")/lsan.supp}"
fuzzer=$1 seeds=$2 work=$3 seconds=$4
shift 4
rm -rf "$work"
mkdir -p "$work/corpus" "$work/artifacts"
cp "$seeds"/* "$work/corpus/"
exec "$fuzzer" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
  "$@" ${FUZZ_OPTIONS:-} "$work/corpus"
