#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Checks that the real-time core (the archives given) needs nothing from outside that allocates,
# locks, throws, formats or does I/O: the symbols its objects use and do not define themselves
# must not include operator new, malloc and friends, pthread, exceptions, std::string, fmt or stdio.
# (operator delete is allowed: a virtual destructor's deleting variant names it without calling it.)
#   tests/repo/rt_core_symbols.sh ARCHIVE...
set -eu
case ${1:-} in
  -h | --help) echo "usage: $0 ARCHIVE..."; exit 0 ;;
  "" | -*) echo "usage: $0 ARCHIVE..." >&2; exit 2 ;;
esac
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
nm --defined-only "$@" 2>/dev/null | awk 'NF == 3 { print $3 }' | sort -u >"$tmp/defined"
nm -u "$@" 2>/dev/null | awk 'NF == 2 && $1 == "U" { print $2 }' | sort -u >"$tmp/used"
comm -23 "$tmp/used" "$tmp/defined" >"$tmp/external"
forbidden='^_Znw|^_Zna|^(malloc|calloc|realloc|free|posix_memalign|aligned_alloc|memalign)$'
forbidden="$forbidden|^pthread_|^__cxa_throw|^__cxa_allocate_exception|^_ZSt[0-9]*__throw"
forbidden="$forbidden|_ZN3fmt|basic_string|^(printf|fprintf|puts|fputs|fopen|fwrite|write|open|syslog)$"
forbidden="$forbidden|^_ZSt4(cout|cerr|clog)"
bad=$(grep -E "$forbidden" "$tmp/external" || true)
if [ -n "$bad" ]; then
  echo "the real-time core uses symbols it must not (mangled; c++filt to read):"
  echo "$bad"
  exit 1
fi
echo "real-time core: $(wc -l <"$tmp/external") external symbols, none that allocates, locks, throws or does I/O:"
sed 's/^/  /' "$tmp/external"
