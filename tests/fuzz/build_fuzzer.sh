#!/bin/sh
# Builds one libFuzzer target with clang/clang++, instrumenting every source it is given
# (coverage + ASan + UBSan), so the fuzzer sees inside the code under test.
# usage: build_fuzzer.sh OUT FLAGS... -- SOURCES... -- LINK_FLAGS...
set -eu
out="$1"; shift
flags=""; while [ "$1" != "--" ]; do flags="$flags $1"; shift; done; shift
sources=""; while [ "$1" != "--" ]; do sources="$sources $1"; shift; done; shift
link="$*"
san="-g -O1 -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined"
objdir="$out.objs"; rm -rf "$objdir"; mkdir -p "$objdir"
objs=""; n=0; cxx=0
for s in $sources; do
  n=$((n+1)); o="$objdir/$n.o"
  case "$s" in
    *.cc|*.cpp) clang++ $san -std=c++17 $flags -c "$s" -o "$o"; cxx=1 ;;
    *) clang $san -std=c11 -D_POSIX_C_SOURCE=200809L $flags -c "$s" -o "$o" ;;
  esac
  objs="$objs $o"
done
linker=clang; [ "$cxx" -eq 1 ] && linker=clang++
$linker -fsanitize=fuzzer,address,undefined $objs $link -lm -o "$out"
