#!/bin/sh
# Runs `morphkit conform` over the shared corpus for one format and precision. Reports itself
# skipped (exit 77) when the corpus is absent, never passed.
# usage: conform_corpus.sh MORPHKIT FILTER PRECISION [OPTION...] (e.g. --gpu)
morphkit="$1"; filter="$2"; precision="$3"; shift 3
corpus="${MORPHKIT_CORPUS:-$MORPHKIT_SOURCE_ROOT/../shared/corpus}"
if [ ! -f "$corpus/cases.json" ]; then
  echo "corpus not found at $corpus (set MORPHKIT_CORPUS)"
  echo "0 passed, 0 failed, 1 skipped"
  exit 77
fi
exec "$morphkit" conform "$corpus/cases.json" --case "$filter" --precision "$precision" "$@"
