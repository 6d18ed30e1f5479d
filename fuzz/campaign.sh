#!/usr/bin/env bash
# Fuzz each named target for SECONDS of wall time on one core (one libFuzzer process), one after
# the other, and append a line per run to fuzz/campaign.log: the date, the commit, the target,
# the wall and CPU seconds (user + system of the fuzzing alone, the target built before; a niced
# run on a busy machine gets less CPU than wall time, so CPU-hours are summed from this column), libFuzzer's executions, coverage
# and features, and the corpus's size after the run. Crashes stop the run and are left in
# fuzz/artifacts/<target>/. Runs resume from the corpus, so short runs add up.
#
# Usage (from the repository root, after `bash fuzz/seed.sh`):
#   RUSTC_BOOTSTRAP=1 bash fuzz/campaign.sh 3600 hdr exr      # one CPU-hour each
# Two campaigns over disjoint targets use both cores of a 2-core machine. NICE (default 10) is the
# runs' nice level: 0 when the machine is left to the fuzzers. Never pause a fuzzer (SIGSTOP):
# libFuzzer's -timeout counts wall time, so a paused input is reported as a time-out.
set -uo pipefail
secs=$1
shift
log=fuzz/campaign.log
commit=$(git rev-parse --short HEAD)
for t in "$@"; do
  mkdir -p "fuzz/corpus/$t" "fuzz/artifacts/$t"
  out=$(mktemp)
  start=$(date -u +%Y-%m-%dT%H:%MZ)
  cpu=$(mktemp)
  # Built first, outside the timed run, so the CPU column is fuzzing alone.
  nice -n "${NICE:-10}" cargo fuzz build -O "$t" >"$out" 2>&1
  /usr/bin/time -f "%U %S" -o "$cpu" nice -n "${NICE:-10}" cargo fuzz run -O "$t" -- \
    -max_total_time="$secs" -rss_limit_mb=4096 -timeout=30 -print_final_stats=1 >"$out" 2>&1
  rc=$?
  cpu_s=$(awk 'END {printf "%.0f", $1 + $2}' "$cpu")
  rm -f "$cpu"
  done_line=$(grep -E '^#[0-9]+[[:space:]]+DONE' "$out" | tail -1)
  execs=$(grep -E '^stat::number_of_executed_units' "$out" | awk '{print $2}')
  files=$(find "fuzz/corpus/$t" -type f | wc -l)
  bytes=$(du -sb "fuzz/corpus/$t" | cut -f1)
  crashes=$(find "fuzz/artifacts/$t" -type f | wc -l)
  echo "$start $commit $t wall=${secs}s cpu=${cpu_s}s rc=$rc execs=${execs:-?} corpus=${files}files/${bytes}B artifacts=$crashes | ${done_line:-no DONE line}" | tee -a "$log"
  [ "$rc" -eq 0 ] || tail -40 "$out" >"fuzz/artifacts/$t/last-run.txt"
  rm -f "$out"
done
