#!/usr/bin/env bash
# The hand on the CLI: `follicle render` of a hand scene, `follicle animate` of a short
# finger-flexion clip (PNGs, MP4 when ffmpeg is present), `follicle export --maps` writing
# height/normal/displacement maps as EXR + PNG for the rest state and each frame of --frames
# (sizes checked with `follicle info`-free Python PNG header reads), and clean errors for bad
# hand keys and for --maps on a scene without a hand. Uses small copies of the shipped scenes.
source "$(dirname "$0")/lib/common.bash" "$@"

# small SCENE OUT [FRAMES]: data/scenes/SCENE.json with absolute paths, 128^2 fine maps, a
# small image and (for animations) FRAMES frames.
small() {
  python3 - "$ROOT/data/scenes/$1.json" "$2" "${3:-0}" <<'PY'
import json, os, sys
src, out, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
h = s["hand"]
h["makehuman"] = os.path.normpath(os.path.join(base, h.get("makehuman", "../makehuman")))
h.setdefault("rig", {}).setdefault("fine", {})["resolution"] = 128
h["rig"].setdefault("refine", {})["max_levels"] = 1
s["render"].update(width=96, height=96, supersample=1)
if frames and "animation" in s:
    s["animation"]["frames"] = frames
json.dump(s, open(out, "w"), indent=1)
PY
}
png_size() { python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print(*struct.unpack('>II', d[16:24]))" "$1"; }

small hand_flex "$TMP/flex.json"
"$FOLLICLE" render "$TMP/flex.json" -o "$TMP/flex.png" -q 2>"$TMP/err" || { fail "render"; cat "$TMP/err"; }
[ "$(png_size "$TMP/flex.png" 2>/dev/null)" = "96 96" ] || fail "render size: $(png_size "$TMP/flex.png" 2>&1)"

small hand_flexion_anim "$TMP/anim.json" 3
"$FOLLICLE" animate "$TMP/anim.json" --frames 0-2 -o "$TMP/anim" -q 2>"$TMP/err" \
  || { fail "animate"; cat "$TMP/err"; }
for f in 0 1 2; do [ -s "$TMP/anim/frame_000$f.png" ] || fail "frame $f missing"; done
if command -v ffmpeg >/dev/null; then [ -s "$TMP/anim/anim.mp4" ] || fail "mp4 missing"; fi

# export --maps: rest + frames 1-2, every map as EXR and PNG of the map size.
"$FOLLICLE" export "$TMP/anim.json" --maps "$TMP/maps" --frames 1-2 -q 2>"$TMP/err" \
  || { fail "export --maps"; cat "$TMP/err"; }
for stem in hand_rest hand_frame_0001 hand_frame_0002; do
  for kind in height normal displacement; do
    [ -s "$TMP/maps/${stem}_$kind.exr" ] || fail "${stem}_$kind.exr missing"
    head -c 4 "$TMP/maps/${stem}_$kind.exr" 2>/dev/null | od -An -tx1 | grep -q '76 2f 31 01' \
      || fail "${stem}_$kind.exr is not OpenEXR"
    [ "$(png_size "$TMP/maps/${stem}_$kind.png" 2>/dev/null)" = "128 128" ] \
      || fail "${stem}_$kind.png size"
  done
done
[ -e "$TMP/maps/hand_frame_0000_height.png" ] && fail "frame 0 written outside --frames 1-2"
ls "$TMP/maps" | grep -q '\.tmp' && fail "temporary files left behind"
"$FOLLICLE" export "$TMP/anim.json" --maps "$TMP/maps2" --frames 2-9 2>"$TMP/err"
[ $? = 2 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "--frames past the end"; cat "$TMP/err"; }

# --maps on a scene without a hand: one-line error.
"$FOLLICLE" export "$ROOT/data/scenes/default.json" --maps "$TMP/none" 2>"$TMP/err"
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] && grep -q 'hand' "$TMP/err" \
  || { fail "maps without a hand"; cat "$TMP/err"; }

# Bad hand key: one-line error naming the JSON path.
python3 - "$TMP/flex.json" "$TMP/bad.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["hand"]["rig"]["joint_depht"] = 0.001
json.dump(s, open(sys.argv[2], "w"))
PY
"$FOLLICLE" validate "$TMP/bad.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && grep -q 'hand.rig.joint_depht' "$TMP/err" || { fail "bad key"; cat "$TMP/err"; }

[ $fails = 0 ] && echo "cli_hand: all passed"
exit $fails
