#!/bin/sh
# The runtime library references no allocator and nothing beyond libc/libm: lists its
# undefined symbols and fails on any allocator or non-libc name.
# usage: check_runtime_symbols.sh LIBRARY.a
lib="$1"
passed=0; failed=0
# Undefined symbols of the archive's objects, minus those another runtime object defines.
defined=$(nm --defined-only "$lib" 2>/dev/null | awk 'NF == 3 {print $3}' | sort -u)
undef=$(nm -u "$lib" 2>/dev/null | grep -v ':$' | awk 'NF {print $NF}' | sort -u | comm -23 - "$(printf '%s\n' "$defined" > "${TMPDIR:-/tmp}/mk_defined.$$"; echo "${TMPDIR:-/tmp}/mk_defined.$$")")
rm -f "${TMPDIR:-/tmp}/mk_defined.$$"
if [ -z "$lib" ] || [ ! -f "$lib" ]; then echo "no library given"; echo "0 passed, 1 failed"; exit 1; fi
bad=$(printf '%s\n' "$undef" | grep -E '^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign|memalign|valloc|strdup|strndup|__libc_malloc)$')
if [ -n "$bad" ]; then echo "FAIL runtime references allocators: $bad"; failed=$((failed+1)); else echo "ok   no allocator symbols"; passed=$((passed+1)); fi
# Allowed: libc string/math functions and compiler intrinsics (the runtime uses no stdio).
other=$(printf '%s\n' "$undef" | grep -vE '^(mem(cpy|set|cmp|move)|str(len|cmp)|sqrtf|sqrt|sinf|atan2f|fmod|__[a-z0-9_]+|_GLOBAL_OFFSET_TABLE_|)$')
if [ -n "$other" ]; then echo "FAIL runtime references unexpected symbols: $other"; failed=$((failed+1)); else echo "ok   only libc/libm symbols: $(printf '%s ' $undef)"; passed=$((passed+1)); fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
