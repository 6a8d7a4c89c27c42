#!/usr/bin/env bash
# Usage errors: exit 2 and exactly one line "follicle: error: ..." on stderr; --help exits 0.
source "$(dirname "$0")/lib/common.bash" "$@"
check() {  # check NAME EXPECTED_CODE CMD...
  local name=$1 want=$2
  shift 2
  "$@" >"$TMP/out" 2>"$TMP/err"
  local got=$?
  if [ "$got" != "$want" ]; then
    echo "FAIL $name: exit $got, want $want"; cat "$TMP/err"; fails=$((fails + 1)); return
  fi
  if [ "$want" != 0 ]; then
    local n; n=$(wc -l <"$TMP/err")
    if [ "$n" != 1 ] || ! grep -q '^follicle: error: ' "$TMP/err"; then
      echo "FAIL $name: stderr is not one 'follicle: error:' line:"; cat "$TMP/err"; fails=$((fails + 1)); return
    fi
  fi
  echo "ok   $name"
}
check help 0 "$FOLLICLE" --help
grep -q render "$TMP/out" || { echo "FAIL help does not list render"; fails=$((fails + 1)); }
grep -q ' docs' "$TMP/out" && { echo "FAIL hidden docs command shows in --help"; fails=$((fails + 1)); }
check version 0 "$FOLLICLE" --version
check no-command 2 "$FOLLICLE"
check unknown-command 2 "$FOLLICLE" frobnicate
check unknown-flag 2 "$FOLLICLE" validate --frobnicate "$ROOT/data/scenes/default.json"
check missing-arg 2 "$FOLLICLE" validate
check bad-width 2 "$FOLLICLE" render "$ROOT/data/scenes/default.json" -o "$TMP/x.png" --width -3
check not-png 2 "$FOLLICLE" render "$ROOT/data/scenes/default.json" -o "$TMP/x.jpg"
check empty-output 2 "$FOLLICLE" render "$ROOT/data/scenes/default.json" -o ''
check empty-export-hair 2 "$FOLLICLE" export "$ROOT/data/scenes/anjyo_bob.json" --hair ''
check bad-size 2 "$FOLLICLE" bench foo --size nonsense
check bad-units 1 "$FOLLICLE" info "$ROOT/data/meshes/lee_perry_smith/head.obj" --units inch
check unknown-file-type 1 "$FOLLICLE" info "$ROOT/data/CREDITS.md"
check global-flag-after-subcommand 0 "$FOLLICLE" validate "$ROOT/data/scenes/default.json" --threads 1 --quiet
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
