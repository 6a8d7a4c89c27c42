#!/usr/bin/env bash
# Hair on the CLI: `follicle export` round trips (.hair and .tfx re-read by `follicle info` with
# the same counts; re-export is bit-identical), `follicle animate` writes numbered PNGs and an MP4
# (when ffmpeg is present), a re-run with the strand cache renders identical frames without
# simulating, and bad hair keys fail with a JSON path. Uses small copies of the shipped scenes.
source "$(dirname "$0")/lib/common.bash" "$@"

# small SCENE OUT [DENSITY] [KEY=JSON ...]: a copy of data/scenes/SCENE.json with absolute asset
# paths, a low hair density and a small image.
small() {
  python3 - "$ROOT/data/scenes/$1.json" "$2" "${3:-0.05}" <<'PY'
import json, os, sys
src, out, dens = sys.argv[1], sys.argv[2], float(sys.argv[3])
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
for m in s["assets"]["meshes"]:
    m["path"] = os.path.normpath(os.path.join(base, m["path"]))
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = os.path.normpath(os.path.join(base, m["material"]["texture"]))
for h in s.get("hair", []):
    h["density_scale"] = dens
s["render"].update(width=96, height=96, supersample=1)
json.dump(s, open(out, "w"), indent=1)
PY
}

small anjyo_bob "$TMP/bob.json"
for ext in hair tfx; do
  "$FOLLICLE" export "$TMP/bob.json" --hair "$TMP/bob.$ext" -q 2>"$TMP/err" || { fail "export .$ext"; cat "$TMP/err"; }
  "$FOLLICLE" info "$TMP/bob.$ext" >"$TMP/info.$ext" 2>"$TMP/err" || { fail "info .$ext"; cat "$TMP/err"; }
  grep -q '^strands: [1-9]' "$TMP/info.$ext" || fail "info .$ext shows no strands: $(cat "$TMP/info.$ext")"
  # Re-export is bit-identical (deterministic styling).
  "$FOLLICLE" export "$TMP/bob.json" --hair "$TMP/bob2.$ext" -q --threads 1 || fail "re-export .$ext"
  cmp -s "$TMP/bob.$ext" "$TMP/bob2.$ext" || fail "re-export of .$ext differs"
done
# Same strand count in both formats; .hair keeps every point, .tfx resamples to 32 per strand.
[ "$(grep '^strands:' "$TMP/info.hair")" = "$(grep '^strands:' "$TMP/info.tfx")" ] \
  || fail "strand counts differ: $(grep '^strands:' "$TMP/info.hair") vs $(grep '^strands:' "$TMP/info.tfx")"
n=$(sed -n 's/^strands: //p' "$TMP/info.tfx")
[ "$(sed -n 's/^points: //p' "$TMP/info.tfx")" = "$((n * 32))" ] || fail "tfx points are not 32 per strand"
"$FOLLICLE" export "$TMP/bob.json" --hair "$TMP/bob.usda" -q || fail "export .usda"
grep -q 'BasisCurves' "$TMP/bob.usda" || fail "usda has no BasisCurves"
"$FOLLICLE" export "$TMP/bob.json" --hair "$TMP/bob.obj" -q || fail "export .obj"
grep -q '^l ' "$TMP/bob.obj" || fail "obj has no polylines"
"$FOLLICLE" export "$TMP/bob.json" --hair "$TMP/bob.xyz" 2>"$TMP/err"
[ $? = 2 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "bad extension"; cat "$TMP/err"; }

# animate: 3 frames, then again from the strand cache (identical PNGs, no simulation).
small anjyo_wind "$TMP/wind.json" 0.03
"$FOLLICLE" animate "$TMP/wind.json" --frames 0-2 -o "$TMP/anim" --cache "$TMP/cache" 2>"$TMP/err" >"$TMP/out1" \
  || { fail "animate"; cat "$TMP/err"; }
for f in 0 1 2; do [ -s "$TMP/anim/frame_000$f.png" ] || fail "frame $f missing"; done
if command -v ffmpeg >/dev/null; then
  [ -s "$TMP/anim/wind.mp4" ] || fail "mp4 missing"
  head -c 12 "$TMP/anim/wind.mp4" | grep -q ftyp || fail "not an MP4"
fi
grep -q "0 frames read" "$TMP/out1" || fail "first run read a cache: $(cat "$TMP/out1")"
mkdir -p "$TMP/first" && cp "$TMP"/anim/frame_*.png "$TMP/first/"
"$FOLLICLE" animate "$TMP/wind.json" --frames 0-2 -o "$TMP/anim" --cache "$TMP/cache" --no-video >"$TMP/out2" 2>"$TMP/err" \
  || { fail "animate from cache"; cat "$TMP/err"; }
grep -q "3 frames read, 0 written, 0 dynamics steps" "$TMP/out2" || fail "re-run simulated: $(cat "$TMP/out2")"
for f in 0 1 2; do cmp -s "$TMP/first/frame_000$f.png" "$TMP/anim/frame_000$f.png" || fail "cached frame $f differs"; done
"$FOLLICLE" animate "$TMP/wind.json" --frames 2-1 -o "$TMP/anim" 2>"$TMP/err"
[ $? = 2 ] || fail "reversed frame range accepted"
"$FOLLICLE" animate "$TMP/wind.json" --frames 0-9999 -o "$TMP/anim" 2>"$TMP/err"
[ $? = 2 ] || fail "frame range past the clip accepted"
# Without ffmpeg on PATH: a clear one-line error (exit 1).
PATH=/nonexistent "$FOLLICLE" animate "$TMP/wind.json" --frames 0-0 -o "$TMP/anim" 2>"$TMP/err"
[ $? = 1 ] && grep -q "ffmpeg not found" "$TMP/err" || { fail "missing ffmpeg"; cat "$TMP/err"; }

# Bad hair keys: exit 1, one line naming the JSON path.
python3 - "$TMP/bob.json" "$TMP/bad.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["hair"][0]["dynamics"] = {"stifness_deg": 10}
json.dump(s, open(sys.argv[2], "w"))
PY
"$FOLLICLE" validate "$TMP/bad.json" 2>"$TMP/err"
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] && grep -q 'hair\[0\]\.dynamics' "$TMP/err" \
  || { fail "bad hair key"; cat "$TMP/err"; }
"$FOLLICLE" export "$TMP/bad.json" --hair "$TMP/bad.hair" 2>/dev/null
[ ! -e "$TMP/bad.hair" ] || fail "failed export left a file"
find "$TMP" -name '*.tmp-*' | grep -q . && fail "temporary file left behind"
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "hair cli ok"
