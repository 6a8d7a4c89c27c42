#!/usr/bin/env bash
# Daldegan 1993 on the CLI: the four shipped scenes validate; small copies render (still and
# animated, with the strand cache making a re-run simulate nothing and draw the same frame); a
# bad styler region fails with its JSON path and leaves no output; the three workloads run.
source "$(dirname "$0")/lib/common.bash" "$@"

# small SCENE OUT KEY=VALUE...: a copy with absolute asset paths, low density, few guides, 96 px.
small() {
  python3 - "$ROOT/data/scenes/$1.json" "$2" <<'PY'
import json, os, sys
src, out = sys.argv[1], sys.argv[2]
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
for m in s["assets"]["meshes"]:
    m["path"] = os.path.normpath(os.path.join(base, m["path"]))
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = os.path.normpath(os.path.join(base, m["material"]["texture"]))
for sk in s.get("skin", []):
    sk["muscles"] = os.path.normpath(os.path.join(base, sk["muscles"]))
for h in s.get("hair", []):
    h["density_scale"] = 0.03
    h.setdefault("daldegan", {})["guides"] = 50
    if h["daldegan"].get("settle_time"):
        h["daldegan"]["settle_time"] = 0.1
s["render"].update(width=96, height=96, supersample=1)
if "animation" in s:
    s["animation"]["duration"] = 0.0
    s["animation"]["frames"] = 4
json.dump(s, open(out, "w"), indent=1)
PY
}

for s in daldegan_long daldegan_beard daldegan_fur daldegan_wind; do
  "$FOLLICLE" validate "$ROOT/data/scenes/$s.json" >/dev/null 2>"$TMP/err" || { fail "validate $s"; cat "$TMP/err"; }
  small "$s" "$TMP/$s.json"
  "$FOLLICLE" render "$TMP/$s.json" -o "$TMP/$s.png" -q 2>"$TMP/err" || { fail "render $s"; cat "$TMP/err"; }
  [ -s "$TMP/$s.png" ] || fail "no image for $s"
done

# Animated: frames 0-3 with a cache, then again from the cache: identical last frame.
"$FOLLICLE" animate "$TMP/daldegan_wind.json" -o "$TMP/f1" --cache "$TMP/cache" -q 2>"$TMP/err" ||
  { fail "animate wind"; cat "$TMP/err"; }
"$FOLLICLE" animate "$TMP/daldegan_wind.json" -o "$TMP/f2" --cache "$TMP/cache" -q 2>"$TMP/err" ||
  { fail "animate wind from the cache"; cat "$TMP/err"; }
ls "$TMP/cache"/hair0/strands_*.fsc >/dev/null 2>&1 || fail "no strand cache files"
last=$(ls "$TMP/f1" | sort | tail -1)
cmp -s "$TMP/f1/$last" "$TMP/f2/$last" || fail "cached re-run draws a different $last"

# Bad input: a region whose selector misses its argument; a mask that does not exist.
python3 - "$TMP/daldegan_fur.json" "$TMP/bad1.json" "$TMP/bad2.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["hair"][0]["styler"] = {"preset": "fur", "regions": [{"select": "sphere", "radius": 0.1}]}
json.dump(s, open(sys.argv[2], "w"))
s["hair"][0]["styler"] = {"preset": "fur", "regions": [{"select": "mask", "mask": "missing.png"}]}
json.dump(s, open(sys.argv[3], "w"))
PY
for b in bad1 bad2; do
  if "$FOLLICLE" render "$TMP/$b.json" -o "$TMP/$b.png" -q 2>"$TMP/err"; then fail "$b accepted"; fi
  grep -q "hair\[0\].styler.regions\[0\]" "$TMP/err" || { fail "$b: no JSON path"; cat "$TMP/err"; }
  [ "$(wc -l <"$TMP/err")" -eq 1 ] || { fail "$b: not one line"; cat "$TMP/err"; }
  [ ! -e "$TMP/$b.png" ] || fail "$b left an output"
done

# The workloads at smoke sizes.
"$FOLLICLE" bench daldegan-style --size density_scale=0.05 --min-seconds 0 >/dev/null 2>"$TMP/err" || { fail "bench style"; cat "$TMP/err"; }
"$FOLLICLE" bench daldegan-dynamics --size strands=500 --size segments=10 --min-seconds 0 >/dev/null 2>"$TMP/err" || { fail "bench dynamics"; cat "$TMP/err"; }
"$FOLLICLE" bench daldegan-render --size strands=2000 --size width=128 --size height=128 --size settle_time=0 --min-seconds 0 >/dev/null 2>"$TMP/err" || { fail "bench render"; cat "$TMP/err"; }

[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "daldegan cli ok"
