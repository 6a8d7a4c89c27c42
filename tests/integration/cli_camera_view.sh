#!/usr/bin/env bash
# A mesh the camera does not look at is named, with numbers and the likely fix, instead of a
# silent empty image (issue 21 item 6): the bob with the camera turned away from the head warns
# once; the shipped scene does not.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
python3 - "$ROOT" "$work/away.json" <<'PY'
import json, sys
root, out = sys.argv[1:]
d = json.load(open(f"{root}/data/scenes/anjyo_bob.json"))
for m in d["assets"]["meshes"]:
    m["path"] = f"{root}/data/scenes/{m['path']}"
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = f"{root}/data/scenes/{m['material']['texture']}"
d["hair"][0]["density_scale"] = 0.01
d["camera"]["target"] = [5.0, 0.06, 0.0]  # looking away to the side
json.dump(d, open(out, "w"))
PY
"$FOLLICLE" render "$work/away.json" -o "$work/away.png" --width 32 --height 32 2> "$work/err" \
  || fail "render failed: $(cat "$work/err")"
grep -q "mesh \"head\" (assets.meshes\[0\]) is outside the camera's view.*set camera.target" "$work/err" \
  || fail "no view warning: $(cat "$work/err")"
[ "$(grep -c "outside the camera's view" "$work/err")" -eq 1 ] || fail "warned more than once"
"$FOLLICLE" render "$ROOT/data/scenes/anjyo_bob.json" -o "$work/ok.png" --width 32 --height 32 \
  2> "$work/err"
if grep -q "outside the camera" "$work/err"; then fail "false view warning: $(cat "$work/err")"; fi
echo "ok: a mesh outside the camera's view is named"
