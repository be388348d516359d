#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Rewrites the generated tables of docs/conformance.md (coverage, ncfiles, corpus) from cases.tsv,
# items.tsv and the programs' `items:` lines. Called by regen-golden.sh.
#
# Usage: tests/conformance/update-docs.sh [CASES_TSV [OUTPUT]]   (defaults: cases.tsv, docs/conformance.md in place)
set -euo pipefail
export LC_ALL=C
here=$(cd "$(dirname "$0")" && pwd)
doc=$here/../../docs/conformance.md
cases=${1:-$here/cases.tsv}
out=${2:-$doc}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# item <TAB> program (own programs, with `accept` or `reject`)
grep -v '^#' "$cases" | awk -F'\t' '$2 == "own" { print $3 "\t" $8 }' | while IFS=$'\t' read -r program expect; do
  sed -n -E '1,12{s/^[;(][[:space:]]*items:[[:space:]]*([^)]*)\)?\r?$/\1/p}' "$here/programs/$program" | tr -d '\r' |
    tr ' ' '\n' | sed '/^$/d' | sed "s#\$#\t${program%.*}\t$expect#"
done >"$tmp/uses"

{
  printf '| item | what | programs | rejected programs |\n|---|---|---|---|\n'
  grep -v '^#' "$here/items.tsv" | while IFS=$'\t' read -r item errors what; do
    ok=$(awk -F'\t' -v i="$item" '$1 == i && $3 == "accept" { printf "%s`%s`", sep, $2; sep = ", " }' "$tmp/uses")
    bad=$(awk -F'\t' -v i="$item" '$1 == i && $3 == "reject" { printf "%s`%s`", sep, $2; sep = ", " }' "$tmp/uses")
    [[ -z $bad && $errors == no ]] && bad="(no error case)"
    printf '| `%s` | %s | %s | %s |\n' "$item" "$what" "$ok" "$bad"
  done
} >"$tmp/coverage"

code_for() { MSG="$1" awk -F'\t' '!/^#/ && NF >= 2 && ENVIRON["MSG"] ~ $1 { print $2; exit }' "$here/error-codes.tsv"; }

status() { # expect code note -> status text
  case $1 in
    accept) printf 'accepted by rs274: must match' ;;
    reject) printf 'rejected by rs274 (%s): must reject with `%s`' "${3#rejected by rs274: }" \
      "$(code_for "${3#rejected by rs274: }")" ;;
    excluded) printf 'excluded: %s' "$3" ;;
    run) printf 'Fanuc dialect: must run (%s)' "${3#Fanuc-style: }" ;;
    unsupported) printf 'unsupported: must fail with `%s` (%s)' "$2" "${3#unsupported: }" ;;
  esac
}
{
  printf '| program | status |\n|---|---|\n'
  grep -v '^#' "$cases" | awk -F'\t' '$2 == "ncfiles"' | sort -t $'\t' -k3,3 |
    while IFS=$'\t' read -r _ _ program _ _ _ _ expect code _ _ note; do
      printf '| `%s` | %s |\n' "$program" "$(status "$expect" "$code" "$note")"
    done
} >"$tmp/ncfiles"
{
  printf '| program | rs274 | opencnc must |\n|---|---|---|\n'
  grep -v '^#' "$cases" | awk -F'\t' '$2 == "corpus"' | sort -t $'\t' -k3,3 |
    while IFS=$'\t' read -r _ _ program _ table _ _ expect code construct _ note; do
      tools=; [[ $table != - ]] && tools=' (with tools.tbl)'
      case $expect in
        accept) printf '| `%s` | accepted%s | match rs274 |\n' "$program" "$tools" ;;
        reject) printf '| `%s` | rejected | reject it with the same problem (%s) |\n' "$program" "${note#error: }" ;;
        run) printf '| `%s` | rejected | run it with `--dialect fanuc` (%s) |\n' "$program" "${note#Fanuc-style: }" ;;
        unsupported) printf '| `%s` | rejected | fail with `%s` naming `%s` (%s) |\n' "$program" "$code" "$construct" \
          "${note#unsupported: }" ;;
      esac
    done
} >"$tmp/corpus"

# Replaces the lines between <!-- NAME:begin --> and <!-- NAME:end --> with the file $tmp/NAME.
awk -v dir="$tmp" '
  /^<!-- [a-z]+:begin -->$/ { print; name = $2; sub(/:begin$/, "", name); while ((getline l < (dir "/" name)) > 0) print l; skip = 1; next }
  /^<!-- [a-z]+:end -->$/ { skip = 0 }
  !skip { print }
' "$doc" >"$tmp/doc"
cp "$tmp/doc" "$out"
