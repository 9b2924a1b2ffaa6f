#!/bin/sh
# Proves that every check of mk_asset_open is needed by its corruption tests: for each check
# named in runtime/open.c, runs test_open_checks with MK_OPEN_DISABLE=<check> (the check's
# condition forced false in that test build) and reports what its corruptions do without it:
#   opens                   the corrupted blob is accepted (then used: queries, sampling, eval)
#   caught by <check>       a later check rejects it, with another code or message
#   ASan/UBSan: <error>     the read the check guards happens (in a sanitizer build)
#   crash                   it died of a signal (outside a sanitizer build)
# A check whose corruptions still pass by their code and message alone "DOES NOT BITE".
# usage: prove_open_checks.sh PATH/TO/test_open_checks [SOURCE_ROOT]
# Exit status 1 if some check does not bite.
set -u
exe="$1"
root="${2:-${MORPHKIT_SOURCE_ROOT:-$(dirname "$0")/../..}}"
checks=$(grep -v '^[[:space:]]*\(/\*\|\*\)' "$root/runtime/open.c" |
         sed -n 's/.*FAILS("\([^"]*\)".*/\1/p; s/.*CHECK_ARRAY("\([^"]*\)".*/\1.align\n\1.bounds/p')
log=$(mktemp); trap 'rm -f "$log"' EXIT
status=0
for check in $checks; do
  MK_OPEN_DISABLE="$check" MORPHKIT_SOURCE_ROOT="$root" ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" \
    "$exe" test_every_corruption > "$log" 2>&1
  rc=$?
  outcomes=$(sed -n 's/^  [^ ]* disabled, .*: \([a-z ]*\) from \([^ :]*\): .*/\1|\2/p' "$log" |
             awk -F'|' '{ print ($1 == "ok") ? "opens" : "caught by " $2 }' | sort | uniq -c |
             awk '{ n = $1; $1 = ""; sub(/^ /, ""); printf "%s%s%s", sep, $0, (n > 1 ? " (x" n ")" : ""); sep = ", " }')
  if grep -q 'ERROR: AddressSanitizer' "$log"; then
    result="ASan: $(sed -n 's/.*ERROR: AddressSanitizer: \([^ ]*\).*/\1/p' "$log" | head -1)${outcomes:+ (before it: $outcomes)}"
  elif grep -q 'runtime error:' "$log"; then
    result="UBSan: $(grep -m1 'runtime error:' "$log" | sed 's/.*runtime error: //')"
  elif grep -q '^BITES' "$log"; then
    result="bites: $outcomes"
  elif grep -q '^DOES NOT BITE' "$log"; then
    result="DOES NOT BITE: $(grep 'STILL PASSES' "$log" | head -3)"; status=1
  elif [ "$rc" -ge 128 ]; then
    result="crash (exit $rc)${outcomes:+ after: $outcomes}"
  else
    result="no result (exit $rc): $(tail -3 "$log")"; status=1
  fi
  printf '%-32s %s\n' "$check" "$result"
done
exit $status
