#!/bin/sh
# smoke.sh HARNESS CORPUS MAX_LEN — the fuzz smoke step for one libFuzzer harness: replays every input of
# the committed seed corpus, then fuzzes fresh mutations for MURK_FUZZ_SECONDS (default 10) seconds,
# from the fixed random seed MURK_FUZZ_SEED (default 1; 0: libFuzzer picks one) and without reloading the
# corpus folders: the mutations follow one sequence, and a slower machine runs a prefix of it (a time limit
# makes that prefix vary, so this narrows, not removes, the chance that a run reaches a known bug of a
# library's before a change does; longer runs by hand look for those). Each input is limited to
# 10 s (a slower one is a hang) and 2 GB. New inputs go to a scratch folder, never into the committed corpus.
# Prints one line of figures; fails on any crash, leak, hang or OOM (the reproducer is kept and named).
set -u
h=$1 corpus=$2 max_len=$3
secs=${MURK_FUZZ_SECONDS:-10}
name=$(basename "$h")
# Leaks inside third-party libraries murk cannot fix (each explained in lsan.supp) are not murk's.
LSAN_OPTIONS="suppressions=$(cd "$(dirname "$0")" && pwd)/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export LSAN_OPTIONS
work=$(mktemp -d "${TMPDIR:-/tmp}/murk-fuzz-smoke.XXXXXX")
log=$work/log
# 1. replay: every seed once
"$h" -runs=0 -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$work/" "$corpus" >"$log" 2>&1
rc=$?
seeds=$(ls "$corpus" | wc -l)
if [ $rc -ne 0 ]; then
  tail -n 60 "$log"
  echo "$name: replaying the corpus FAILED (exit $rc); reproducers in $work"
  exit 1
fi
# 2. fresh mutations for a bounded time (fork-free, one job)
mkdir "$work/new"
"$h" -seed="${MURK_FUZZ_SEED:-1}" -reload=0 -max_total_time="$secs" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
     -artifact_prefix="$work/" "$work/new" "$corpus" >"$log" 2>&1
rc=$?
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
line=$(grep -E '^#[0-9]+' "$log" | tail -n 1)
cov=$(echo "$line" | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
ft=$(echo "$line" | sed -n 's/.*ft: \([0-9]*\).*/\1/p')
crashes=$(ls "$work" | grep -c -E '^(crash|leak|oom)-' || true)
hangs=$(ls "$work" | grep -c -E '^(timeout|slow-unit)-' || true)
newin=$(ls "$work/new" | wc -l)
echo "$name: $seeds seeds replayed; ${secs}s fresh: ${execs:-0} executions, cov ${cov:-?} edges, ft ${ft:-?} features, $newin new inputs, crashes $crashes, hangs $hangs"
if [ $rc -ne 0 ] || [ "$crashes" -ne 0 ] || [ "$(ls "$work" | grep -c -E '^timeout-' || true)" -ne 0 ]; then
  tail -n 60 "$log"
  echo "$name: FAILED (exit $rc); reproducers in $work"
  exit 1
fi
rm -rf "$work"
exit 0
