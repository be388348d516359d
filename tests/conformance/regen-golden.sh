#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Regenerates the conformance golden files with LinuxCNC's rs274, rewrites cases.tsv and the generated
# tables of docs/conformance.md (update-docs.sh). About 45 s.
#
# Usage: tests/conformance/regen-golden.sh [--check]
#   --check   regenerate into a scratch folder and report what differs from the committed files
#             (exit 1 if anything is stale); nothing in the tree changes.
# Environment:
#   OPENCNC_NCFILES  LinuxCNC sample programs (default /usr/share/linuxcnc/ncfiles)
#   OPENCNC_CORPUS   real-world corpus (default <repo>/../shared/gcode-corpus)
#   RS274            the rs274 binary (default: rs274 on PATH)
#
# How each set runs (the harness runs rs274 and opencnc the same way, from cases.tsv):
#   own      programs/<area>/*.ngc. Working directory = the program's folder; tool table
#            tools/standard.tbl; an INI file sets SUBROUTINE_PATH = <area>/lib (if present) : programs/lib,
#            or the folders of a `; subroutine-path:` line (programs/ngcgui drives LinuxCNC's ngcgui
#            subroutines in OPENCNC_NCFILES, the way LinuxCNC's sample configurations set it up).
#            errors/ programs must be rejected, every other area accepted (else the script says so and
#            exits 1), and every rejection must match a row of error-codes.tsv.
#            programs/fanuc and programs/transforms are Fanuc-dialect programs: rs274 cannot run them,
#            their expected output is rs274's output of a hand-written LinuxCNC twin (twins/<area>/),
#            or, for err-*.nc, the problem code named in their `(expect-error: CODE)` line.
#   ncfiles  every *.ngc below OPENCNC_NCFILES except those listed in ncfiles-excluded.tsv (remap bodies).
#            Working directory = the program's folder, which is where rs274 looks for called subprogram
#            files when no SUBROUTINE_PATH is set (LinuxCNC's own sample configs point SUBROUTINE_PATH
#            at these folders); tool table tools/ncfiles.tbl (rs274's built-in default table is not
#            something opencnc can know). Accepted or rejected as rs274 says.
#   corpus   every row of MANIFEST.tsv. `ok` runs without a tool table, everything else with the corpus'
#            tools.tbl (as the MANIFEST's rs274 column was made). Rejected files are classified in
#            corpus-dialects.tsv.
#
# Golden file: header lines starting with "# " (command, exit status, rs274's stderr without its
# "executing" line), a line "# ---", then rs274's standard output unchanged. Absolute paths of the
# programs and ncfiles folders in rs274's messages are written as @programs and @ncfiles. Goldens over
# 64 KiB are xz-compressed. rs274 runs with a private HOME: it keeps the tool table in $HOME/.tool.mmap,
# which parallel rs274 runs (other scripts, ctest -j2) would otherwise overwrite under each other.
set -euo pipefail
export LC_ALL=C

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
programs=$here/programs
twins=$here/twins
ncfiles=${OPENCNC_NCFILES:-/usr/share/linuxcnc/ncfiles}
corpus=${OPENCNC_CORPUS:-$repo/../shared/gcode-corpus}
rs274=${RS274:-rs274}
check=0
[[ ${1:-} == --check ]] && check=1

command -v "$rs274" >/dev/null || { echo "regen-golden: rs274 not found (install LinuxCNC 2.9)" >&2; exit 2; }
command -v xz >/dev/null || { echo "regen-golden: xz not found" >&2; exit 2; }
[[ -d $ncfiles ]] || { echo "regen-golden: $ncfiles not found (set OPENCNC_NCFILES)" >&2; exit 2; }
[[ -f $corpus/MANIFEST.tsv ]] || { echo "regen-golden: $corpus/MANIFEST.tsv not found (set OPENCNC_CORPUS)" >&2; exit 2; }
corpus=$(cd "$corpus" && pwd)

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out_root=$here
if ((check)); then out_root=$tmp/tree; mkdir -p "$out_root"; fi
golden=$out_root/golden
rm -rf "$golden"
mkdir -p "$golden"
cases=$tmp/cases.body
: >"$cases"
failures=0

fail() { echo "regen-golden: $*" >&2; failures=$((failures + 1)); }

# Test-case name: set and path with every other character turned into '_'.
case_name() { printf '%s_%s' "$1" "$2" | sed -E 's/\.(ngc|nc|NC|gcode|tap)$//; s/[^A-Za-z0-9]+/_/g; s/_+$//'; }

# A directive `KEY: value` from the first lines of a program, written as `; KEY: value` or `(KEY: value)`.
directive() {
  sed -n -E "1,12{s/^[;(][[:space:]]*$2:[[:space:]]*([^)]*)\)?[[:space:]]*\$/\\1/p}" "$1" | head -n 1 | sed -E 's/[[:space:]]+$//'
}

# run_rs274 DIR FILE TOOLTABLE SUBPATH — runs rs274 as the harness does; leaves out/err/rc in $tmp.
run_rs274() {
  local dir=$1 file=$2 table=$3 subpath=$4 args=()
  [[ $table != - ]] && args+=(-t "$table")
  if [[ $subpath != - ]]; then
    subpath=${subpath//@ncfiles/$ncfiles}
    printf '[RS274NGC]\nSUBROUTINE_PATH = %s\n' "$subpath" >"$tmp/run.ini"
    args+=(-i "$tmp/run.ini")
  fi
  set +e
  # rs274 keeps the tool table in $HOME/.tool.mmap: a private HOME keeps parallel runs apart.
  (cd "$dir" && HOME=$tmp "$rs274" "${args[@]}" -g "$file" </dev/null >"$tmp/out" 2>"$tmp/err.raw")
  echo $? >"$tmp/rc"
  set -e
  grep -v -x 'executing' "$tmp/err.raw" | sed "s#$programs#@programs#g; s#$ncfiles#@ncfiles#g" >"$tmp/err" || true
}

# First line of rs274's error message (the line before the offending block).
error_message() { head -n 1 "$tmp/err"; }

# The problem code error-codes.tsv gives for message $1 (empty if none).
code_for() {
  MSG="$1" awk -F'\t' '!/^#/ && NF >= 2 && ENVIRON["MSG"] ~ $1 { print $2; exit }' "$here/error-codes.tsv"
}

# write_golden DEST COMMAND [NOTE] — stores the last run as a golden file (xz if large).
write_golden() {
  local dest=$1 cmd=$2 note=${3:-}
  mkdir -p "$(dirname "$dest")"
  {
    [[ -n $note ]] && printf '# %s\n' "$note"
    printf '# command: %s\n' "$cmd"
    printf '# exit: %s\n' "$(cat "$tmp/rc")"
    sed 's/^/# stderr: /' "$tmp/err"
    printf '# ---\n'
    cat "$tmp/out"
  } >"$dest"
  if (($(stat -c %s "$dest") > 65536)); then xz -9 -f "$dest"; echo "$dest.xz"; else echo "$dest"; fi
}

# add_case NAME SET PROGRAM DIALECT TABLE SUBPATH ARGS EXPECT CODE CONSTRUCT GOLDEN NOTE
add_case() { local IFS=$'\t'; printf '%s\n' "$*" >>"$cases"; }

rel_golden() { local p=$1; printf '%s' "${p#"$golden"/}"; }

# ---------------------------------------------------------------------------------------------
echo "own programs..." >&2
while IFS= read -r path; do
  rel=${path#"$programs"/}
  area=${rel%%/*}
  dir=$(dirname "$path")
  base=$(basename "$path")
  stem=${base%.*}
  name=$(case_name own "$rel")
  subpath=../lib
  [[ -d $dir/lib ]] && subpath=lib:../lib
  # `; subroutine-path: @ncfiles/a @ncfiles/b` replaces the default (drivers of LinuxCNC's sample subroutines).
  sp=$(directive "$path" subroutine-path)
  [[ -n $sp ]] && subpath=$(tr ' ' ':' <<<"$sp")
  args=$(directive "$path" opencnc-args)
  [[ -z $args ]] && args=-
  table=@conf/tools/standard.tbl
  note=$(sed -n -E '/^[;(]/{s/^[;(][[:space:]]*//; s/\)?[[:space:]]*\r?$//; p; q}' "$path")
  if [[ $area == fanuc || $area == transforms ]]; then
    code=$(directive "$path" expect-error)
    if [[ -n $code ]]; then
      add_case "$name" own "$rel" fanuc "$table" "$subpath" "$args" reject "$code" - - "$note"
      continue
    fi
    twin=$twins/$area/$stem.ngc
    [[ -f $twin ]] || { fail "$rel: no twin $twin and no expect-error line"; continue; }
    run_rs274 "$(dirname "$twin")" "$(basename "$twin")" "$here/tools/standard.tbl" -
    [[ $(cat "$tmp/rc") == 0 ]] || fail "twin of $rel rejected by rs274: $(error_message)"
    g=$(write_golden "$golden/own/$area/$stem.golden" "rs274 -t tools/standard.tbl -g twins/$area/$stem.ngc" \
      "expected output of the Fanuc-dialect program programs/$rel: rs274's output of its hand-written twin")
    add_case "$name" own "$rel" fanuc "$table" "$subpath" "$args" accept - - "$(rel_golden "$g")" "$note"
    continue
  fi
  run_rs274 "$dir" "$base" "$here/tools/standard.tbl" "$subpath"
  rc=$(cat "$tmp/rc")
  g=$(write_golden "$golden/own/$area/$stem.golden" \
    "rs274 -t tools/standard.tbl -i (SUBROUTINE_PATH=$subpath) -g $base  [in programs/$area]")
  code=$(directive "$path" expect-code)
  if [[ $area == errors ]]; then
    [[ $rc != 0 ]] || fail "$rel: rs274 accepts a program of errors/"
    [[ -n $code || -n $(code_for "$(error_message)") ]] || fail "$rel: no error-codes.tsv row for: $(error_message)"
    add_case "$name" own "$rel" linuxcnc "$table" "$subpath" "$args" reject "${code:--}" - "$(rel_golden "$g")" "$note"
  else
    [[ $rc == 0 ]] || fail "$rel: rs274 rejects it: $(error_message)"
    add_case "$name" own "$rel" linuxcnc "$table" "$subpath" "$args" accept - - "$(rel_golden "$g")" "$note"
  fi
done < <(find "$programs" -mindepth 2 -maxdepth 2 -type f \( -name '*.ngc' -o -name '*.nc' \) ! -path "$programs/lib/*" | sort)

# ---------------------------------------------------------------------------------------------
echo "LinuxCNC sample programs..." >&2
declare -A excluded=()
while IFS=$'\t' read -r p why; do
  [[ -z $p || $p == \#* ]] && continue
  excluded[$p]=$why
done <"$here/ncfiles-excluded.tsv"
while IFS= read -r path; do
  rel=${path#"$ncfiles"/}
  name=$(case_name ncfiles "$rel")
  if [[ -n ${excluded[$rel]:-} ]]; then
    add_case "$name" ncfiles "$rel" linuxcnc - - - excluded - - - "${excluded[$rel]}"
    continue
  fi
  run_rs274 "$(dirname "$path")" "$(basename "$path")" "$here/tools/ncfiles.tbl" -
  g=$(write_golden "$golden/ncfiles/${rel%.*}.golden" "rs274 -t tools/ncfiles.tbl -g $(basename "$path")  [in ncfiles/$(dirname "$rel")]")
  if [[ $(cat "$tmp/rc") == 0 ]]; then
    add_case "$name" ncfiles "$rel" linuxcnc @conf/tools/ncfiles.tbl - - accept - - "$(rel_golden "$g")" "accepted by rs274"
  else
    msg=$(error_message)
    [[ -n $(code_for "$msg") ]] || fail "ncfiles/$rel: no error-codes.tsv row for: $msg"
    add_case "$name" ncfiles "$rel" linuxcnc @conf/tools/ncfiles.tbl - - reject - - "$(rel_golden "$g")" "rejected by rs274: $msg"
  fi
done < <(find "$ncfiles" -type f -name '*.ngc' | sort)

# ---------------------------------------------------------------------------------------------
echo "corpus..." >&2
declare -A klass=() construct=() kcode=() why=()
while IFS=$'\t' read -r f c k code w; do
  [[ -z $f || $f == \#* ]] && continue
  klass[$f]=$c; construct[$f]=$k; kcode[$f]=$code; why[$f]=$w
done <"$here/corpus-dialects.tsv"
while IFS=$'\t' read -r file _ _ _ _ _ _ _ result; do
  [[ $file == file ]] && continue
  name=$(case_name corpus "$file")
  table=@corpus/tools.tbl
  [[ $result == ok ]] && table=-
  tpath=-
  [[ $table != - ]] && tpath=$corpus/tools.tbl
  run_rs274 "$corpus" "$file" "$tpath" -
  rc=$(cat "$tmp/rc")
  tflag=
  [[ $table != - ]] && tflag="-t tools.tbl "
  g=$(write_golden "$golden/corpus/$file.golden" "rs274 ${tflag}-g $file  [in gcode-corpus]")
  if [[ $result == ok* ]]; then
    [[ $rc == 0 ]] || fail "corpus/$file: MANIFEST says $result but rs274 rejects it: $(error_message)"
    add_case "$name" corpus "$file" linuxcnc "$table" - - accept - - "$(rel_golden "$g")" "$result"
    continue
  fi
  [[ $rc != 0 ]] || fail "corpus/$file: MANIFEST says rejected but rs274 accepts it"
  c=${klass[$file]:-}
  case $c in
    fanuc) add_case "$name" corpus "$file" fanuc "$table" - - run - - "$(rel_golden "$g")" "Fanuc-style: ${why[$file]}" ;;
    unsupported) add_case "$name" corpus "$file" linuxcnc "$table" - - unsupported "${kcode[$file]}" "${construct[$file]}" \
      "$(rel_golden "$g")" "unsupported: ${why[$file]}" ;;
    error)
      [[ -n $(code_for "$(error_message)") ]] || fail "corpus/$file: no error-codes.tsv row for: $(error_message)"
      add_case "$name" corpus "$file" linuxcnc "$table" - - reject - - "$(rel_golden "$g")" "error: ${why[$file]}" ;;
    *) fail "corpus/$file: rejected by rs274 but not classified in corpus-dialects.tsv" ;;
  esac
done <"$corpus/MANIFEST.tsv"

# ---------------------------------------------------------------------------------------------
{
  printf '# Conformance cases, written by regen-golden.sh: do not edit by hand.\n'
  printf '# Roots: @conf = tests/conformance, own = @conf/programs, ncfiles = OPENCNC_NCFILES, corpus = OPENCNC_CORPUS.\n'
  printf '# subpath: SUBROUTINE_PATH entries relative to the program folder (also searched itself). args: extra opencnc arguments.\n'
  printf '# expect: accept (match rs274) | reject (fail with code) | run (Fanuc dialect, no oracle) | unsupported | excluded\n'
  printf 'name\tset\tprogram\tdialect\ttool_table\tsubpath\targs\texpect\tcode\tconstruct\tgolden\tnote\n'
  sort -t $'\t' -k1,1 "$cases"
} >"$out_root/cases.tsv"

if ((check)); then
  stale=0
  diff -q "$here/cases.tsv" "$out_root/cases.tsv" >/dev/null || { echo "stale: cases.tsv" >&2; stale=1; }
  "$here/update-docs.sh" "$out_root/cases.tsv" "$tmp/conformance.md"
  diff -q "$repo/docs/conformance.md" "$tmp/conformance.md" >/dev/null || { echo "stale: docs/conformance.md tables" >&2; stale=1; }
  while IFS= read -r f; do
    r=${f#"$golden"/}
    if [[ $f == *.xz ]]; then
      cmp -s <(xz -dc "$f") <(xz -dc "$here/golden/$r" 2>/dev/null) || { echo "stale: golden/$r" >&2; stale=1; }
    else
      cmp -s "$f" "$here/golden/$r" || { echo "stale: golden/$r" >&2; stale=1; }
    fi
  done < <(find "$golden" -type f | sort)
  extra=$(cd "$here/golden" && find . -type f | sed 's#^\./##' | sort | comm -23 - <(cd "$golden" && find . -type f | sed 's#^\./##' | sort))
  [[ -z $extra ]] || { echo "stale (no longer produced): $extra" >&2; stale=1; }
  ((failures == 0)) || exit 1
  ((stale == 0)) && echo "golden files are up to date" >&2
  exit $stale
fi
"$here/update-docs.sh"
((failures == 0)) || { echo "regen-golden: $failures problem(s); golden files written anyway" >&2; exit 1; }
echo "regen-golden: $(grep -vc '^#' "$out_root/cases.tsv") rows in cases.tsv, $(find "$golden" -type f | wc -l) golden files" >&2
