#!/usr/bin/env bash
# LCP particle hair on the CLI: `follicle render` and `follicle animate` (PNGs, MP4 when ffmpeg
# is present) of short clips of the shipped lcp scenes with few particles; the same frame
# rendered twice is byte-identical; bad lcp keys fail with a JSON path.
source "$(dirname "$0")/lib/common.bash" "$@"

# small SCENE OUT FRAMES: few particles, a small image, FRAMES frames.
small() {
  python3 - "$ROOT/data/scenes/$1.json" "$2" "$3" <<'PY'
import json, os, sys
src, out, frames = sys.argv[1], sys.argv[2], int(sys.argv[3])
s = json.load(open(src))
# The copy lives elsewhere: asset paths (relative to the scene file) become absolute.
base = os.path.dirname(os.path.abspath(src))
for m in s.get("assets", {}).get("meshes", []):
    m["path"] = os.path.normpath(os.path.join(base, m["path"]))
    mat = m.get("material", {})
    if "texture" in mat:
        mat["texture"] = os.path.normpath(os.path.join(base, mat["texture"]))
sc = s["lcp"]["scenario"]
sc["spacing"] = 0.02
sc["settle_time"] = 0.1
if sc.get("wind"):
    sc["air_spacing"] = 0.04
s["render"].update(width=96, height=96, supersample=1)
s["animation"]["frames"] = frames
json.dump(s, open(out, "w"), indent=1)
PY
}

for sc in lcp_back_hair lcp_wind; do
  small $sc "$TMP/$sc.json" 3
  "$FOLLICLE" animate "$TMP/$sc.json" --frames 0-2 -o "$TMP/$sc" -q 2>"$TMP/err" \
    || { fail "animate $sc"; cat "$TMP/err"; }
  for f in 0 1 2; do [ -s "$TMP/$sc/frame_000$f.png" ] || fail "$sc frame $f missing"; done
  if command -v ffmpeg >/dev/null; then [ -s "$TMP/$sc/$sc.mp4" ] || fail "$sc mp4 missing"; fi
  # Frame 2 rendered on its own (simulated from frame 0) equals the animated one.
  "$FOLLICLE" render "$TMP/$sc.json" --frame 2 -o "$TMP/$sc-2.png" -q 2>"$TMP/err" \
    || { fail "render $sc"; cat "$TMP/err"; }
  cmp -s "$TMP/$sc-2.png" "$TMP/$sc/frame_0002.png" || fail "$sc frame 2 differs from animate"
done

python3 - "$TMP/lcp_back_hair.json" "$TMP/bad.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["lcp"]["dynamics"]["hair_hiar"] = False
json.dump(s, open(sys.argv[2], "w"))
PY
"$FOLLICLE" validate "$TMP/bad.json" 2>"$TMP/err" >/dev/null
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] && grep -q 'lcp.dynamics.hair_hiar' "$TMP/err" \
  || { fail "bad key"; cat "$TMP/err"; }

# lcp-wind at small sizes: the multi-rate (default) and the tight coupling both run; a
# fractional air_every fails with a clear message and exit code 1.
for every in 0 1; do
  "$FOLLICLE" bench lcp-wind --size hair=2000 --size air=1500 --size air_every=$every \
    --min-seconds 0 -q >"$TMP/wind" 2>"$TMP/err" || { fail "bench lcp-wind air_every=$every"; cat "$TMP/err"; }
  grep -q '"workload":"lcp-wind"' "$TMP/wind" || fail "bench lcp-wind output"
done
"$FOLLICLE" bench lcp-wind --size hair=2000 --size air=1500 --size air_every=2.5 \
  --min-seconds 0 >/dev/null 2>"$TMP/err"
[ $? = 1 ] && grep -q 'air_every must be a whole number' "$TMP/err" \
  || { fail "bad air_every"; cat "$TMP/err"; }

[ $fails = 0 ] && echo "cli_lcp: all passed"
exit $fails
