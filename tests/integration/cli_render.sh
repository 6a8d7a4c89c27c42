#!/usr/bin/env bash
# follicle render: the default scene renders to a PNG of the requested size; the scene's own
# outputs are used without -o; failures (broken scene, unwritable output) leave no file behind.
source "$(dirname "$0")/lib/common.bash" "$@"
SCENE="$ROOT/data/scenes/default.json"

png_size() {  # prints "W H" from the IHDR chunk, fails unless the file is a PNG
  python3 - "$1" <<'PY'
import struct, sys
d = open(sys.argv[1], "rb").read(32)
assert d[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
print(*struct.unpack(">II", d[16:24]))
PY
}

"$FOLLICLE" render "$SCENE" -o "$TMP/small.png" --width 160 --height 120 -q 2>"$TMP/err" \
  || { fail "render"; cat "$TMP/err"; }
[ "$(png_size "$TMP/small.png")" = "160 120" ] || fail "size is $(png_size "$TMP/small.png")"

# Without -o the scene's outputs (relative to the working directory) are written.
(cd "$TMP" && "$FOLLICLE" render "$SCENE" --width 64 --height 64 -q) 2>"$TMP/err" || { fail "render to scene outputs"; cat "$TMP/err"; }
[ -f "$TMP/out/default.png" ] || fail "scene output out/default.png not written"

# A broken scene: exit 1, one line, no output file.
printf '{"follicle_scene": 1, "camera": {"fov_deg": 500}}\n' >"$TMP/broken.json"
"$FOLLICLE" render "$TMP/broken.json" -o "$TMP/broken.png" 2>"$TMP/err"
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "broken scene"; cat "$TMP/err"; }
[ ! -e "$TMP/broken.png" ] || fail "broken scene left an output"

# An output that cannot be written (its folder would be inside a regular file): exit 1, nothing left.
: >"$TMP/afile"
"$FOLLICLE" render "$SCENE" -o "$TMP/afile/x.png" --width 32 --height 32 2>"$TMP/err"
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "unwritable output"; cat "$TMP/err"; }
# An existing output survives a failed render untouched.
cp "$TMP/small.png" "$TMP/keep.png"
"$FOLLICLE" render "$TMP/broken.json" -o "$TMP/keep.png" 2>/dev/null
cmp -s "$TMP/small.png" "$TMP/keep.png" || fail "failed render modified an existing output"
find "$TMP" -name '*.tmp-*' | grep -q . && fail "temporary file left behind"
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "render ok"
