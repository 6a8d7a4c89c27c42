#!/usr/bin/env bash
# follicle validate: shipped scenes pass; broken scenes exit 1 with one line naming the file and
# the JSON path (and a did-you-mean for unknown keys).
source "$(dirname "$0")/lib/common.bash" "$@"
MESH="$ROOT/data/meshes/lee_perry_smith/head.obj"

"$FOLLICLE" validate "$ROOT"/data/scenes/*.json >"$TMP/out" 2>"$TMP/err" \
  || { echo "FAIL shipped scenes do not validate:"; cat "$TMP/err"; fails=$((fails + 1)); }
grep -q '^ok: ' "$TMP/out" || { echo "FAIL no ok line"; fails=$((fails + 1)); }

bad() {  # bad NAME 'JSON' PATTERN...: the scene must fail with one line matching every pattern
  local name=$1 json=$2
  shift 2
  printf '%s\n' "$json" >"$TMP/$name.json"
  "$FOLLICLE" validate "$TMP/$name.json" >"$TMP/out" 2>"$TMP/err"
  local code=$?
  if [ "$code" != 1 ]; then echo "FAIL $name: exit $code, want 1"; cat "$TMP/err"; fails=$((fails + 1)); return; fi
  if [ "$(wc -l <"$TMP/err")" != 1 ]; then echo "FAIL $name: not one line:"; cat "$TMP/err"; fails=$((fails + 1)); return; fi
  grep -qF "follicle: error: $TMP/$name.json" "$TMP/err" || { echo "FAIL $name: file not named:"; cat "$TMP/err"; fails=$((fails + 1)); return; }
  for p in "$@"; do
    grep -qF -- "$p" "$TMP/err" || { echo "FAIL $name: missing '$p' in:"; cat "$TMP/err"; fails=$((fails + 1)); return; }
  done
  echo "ok   $name: $(cat "$TMP/err")"
}
bad unknown-key '{"follicle_scene": 1, "camera": {"fov": 30}}' 'camera.fov' 'did you mean "fov_deg"?'
bad nested-unknown-key "{\"follicle_scene\": 1, \"assets\": {\"meshes\": [{\"path\": \"$MESH\", \"units\": \"mm\", \"material\": {\"textur\": \"a.png\"}}]}}" \
  'assets.meshes[0].material.textur' 'did you mean "texture"?'
bad wrong-type '{"follicle_scene": 1, "render": {"width": "big"}}' 'render.width' 'expected an integer, got a string "big"'
bad wrong-type-vec '{"follicle_scene": 1, "camera": {"eye": [0, 1]}}' 'camera.eye' 'expected an array of 3 numbers'
bad out-of-range '{"follicle_scene": 1, "render": {"supersample": 99}}' 'render.supersample' 'out of range' '[1, 8]'
bad bad-version '{"follicle_scene": 7}' 'follicle_scene' 'unsupported scene format version 7'
bad no-version '{"camera": {}}' 'missing required key "follicle_scene"'
bad missing-required '{"follicle_scene": 1, "assets": {"meshes": [{"path": "x.obj"}]}}' 'assets.meshes[0]' 'missing required key "units"'
bad bad-enum '{"follicle_scene": 1, "outputs": [{"type": "imag", "path": "a.png"}]}' 'outputs[0].type' 'did you mean "image"?'
bad missing-mesh '{"follicle_scene": 1, "assets": {"meshes": [{"path": "nowhere.obj", "units": "m"}]}}' 'assets.meshes[0].path' 'mesh file not found'
bad not-json '{"follicle_scene": 1,
  "camera": {eye: [0, 0, 1]}}' ':2:' 'invalid JSON'
bad duplicate-key '{"follicle_scene": 1, "render": {"width": 10, "width": 20}}' 'duplicate key "width"'
printf '\x00\x01\xff random bytes' >"$TMP/bytes.json"
"$FOLLICLE" validate "$TMP/bytes.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { echo "FAIL random bytes:"; cat "$TMP/err"; fails=$((fails + 1)); }
: >"$TMP/empty.json"
"$FOLLICLE" validate "$TMP/empty.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { echo "FAIL empty file:"; cat "$TMP/err"; fails=$((fails + 1)); }
"$FOLLICLE" validate "$TMP/does-not-exist.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && grep -q 'does-not-exist.json: file not found' "$TMP/err" || { echo "FAIL missing file:"; cat "$TMP/err"; fails=$((fails + 1)); }
# A mesh that exists but is malformed fails at validate (assets are loaded).
printf 'v 0 0 0\nv 1 0 0\nf 1 2 9\n' >"$TMP/broken.obj"
printf '{"follicle_scene": 1, "assets": {"meshes": [{"path": "broken.obj", "units": "m"}]}}\n' >"$TMP/brokenmesh.json"
"$FOLLICLE" validate "$TMP/brokenmesh.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] && grep -q 'broken.obj' "$TMP/err" || { echo "FAIL malformed mesh:"; cat "$TMP/err"; fails=$((fails + 1)); }
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
