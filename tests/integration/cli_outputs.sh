#!/usr/bin/env bash
# Outputs that cannot be written fail before any work with the path and the system's reason
# (issue 24 item 4): a folder where a file is asked for, a file where a folder is needed, a place
# the system refuses (/proc). Nothing is left behind.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
# expect_error STATUS NEEDLE CMD...: CMD exits with STATUS and stderr contains NEEDLE.
expect_error() {
  local want=$1 needle=$2
  shift 2
  set +e
  "$FOLLICLE" -q "$@" > "$work/stdout" 2> "$work/stderr"
  local got=$?
  set -e
  [ "$got" -eq "$want" ] || fail "$* exited $got, expected $want: $(cat "$work/stderr")"
  grep -qF -- "$needle" "$work/stderr" || fail "$*: no '$needle' in: $(cat "$work/stderr")"
}
cd "$ROOT"
mkdir -p "$work/a_folder.png" "$work/hair.hair"
touch "$work/a_file"
expect_error 1 "$work/a_folder.png: is a folder, expected a file name" \
  render data/scenes/default.json -o "$work/a_folder.png"
expect_error 1 "/proc/follicle-test.png: cannot write here:" \
  render data/scenes/default.json -o /proc/follicle-test.png
expect_error 1 "cannot create directory $work/a_file: Not a directory" \
  render data/scenes/default.json -o "$work/a_file/x.png"
expect_error 1 "$work/a_file/frames: cannot create the output folder" \
  animate data/scenes/anjyo_shake.json -o "$work/a_file/frames" --no-video
expect_error 1 "$work/hair.hair: is a folder" \
  export data/scenes/anjyo_shake.json --hair "$work/hair.hair" --frame 71
expect_error 1 "/proc/h.json: cannot write here" \
  harness data/scenes/anjyo_shake.json --json /proc/h.json --sheet "$work/s.png"
[ "$(find "$work" -name '*.tmp-*' | wc -l)" -eq 0 ] || fail "temporary files left"
[ ! -e "$work/s.png" ] || fail "harness wrote its sheet although the report cannot be written"
echo "ok: unwritable outputs fail first"
