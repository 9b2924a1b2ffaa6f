#!/bin/sh
# Runs a libFuzzer binary for a bounded number of inputs from freshly generated seeds.
# usage: run_fuzzer.sh FUZZER SEED_MAKER|- RUNS [EXTRA_SEED_DIR]   (-: no generated seeds)
fuzzer="$1"; seeds="$2"; runs="$3"; extra="${4:-}"
[ -n "$extra" ] && [ ! -d "$extra" ] && extra=""
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/corpus"
if [ "$seeds" != "-" ]; then
  "$seeds" "$dir/corpus" || { echo "0 passed, 1 failed"; exit 1; }
fi
if "$fuzzer" -runs="$runs" -max_len=1048576 -rss_limit_mb=2048 -timeout=30 -seed=1 -print_final_stats=1 "$dir/corpus" $extra > "$dir/log" 2>&1; then
  grep -E 'stat::number_of_executed_units|Done' "$dir/log" | tail -2
  echo "1 passed, 0 failed"
else
  tail -40 "$dir/log"
  echo "0 passed, 1 failed"
  exit 1
fi
