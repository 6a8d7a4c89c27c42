#!/usr/bin/env bash
# A hair group that grows no strands (here a hull of 1 mm on a real head) renders a bald head; the
# user is told so, with what to check, instead of a silent exit 0 (issue 24 item 7).
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$ROOT" "$work/bald.json" <<'PY'
import json, sys
root, out = sys.argv[1], sys.argv[2]
d = json.load(open(f"{root}/data/scenes/anjyo_bob.json"))
for m in d["assets"]["meshes"]:  # asset paths relative to the shipped scene, made absolute
    m["path"] = f"{root}/data/scenes/{m['path']}"
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = f"{root}/data/scenes/{m['material']['texture']}"
d["hair"][0]["hull"] = {"centre": [0, 0.1, 0], "radii": [0.001, 0.001, 0.001]}
d["outputs"] = []
json.dump(d, open(out, "w"))
PY
"$FOLLICLE" render "$work/bald.json" -o "$work/bald.png" --width 32 --height 32 2> "$work/stderr" \
  || { echo "FAIL: render failed: $(cat "$work/stderr")" >&2; exit 1; }
grep -q 'hair\[0\] ("bob"): no strands grew: the head is bald' "$work/stderr" \
  || { echo "FAIL: no bald-head warning: $(cat "$work/stderr")" >&2; exit 1; }
# The bundled scene grows hair and stays quiet about it.
"$FOLLICLE" render "$ROOT/data/scenes/anjyo_bob.json" -o "$work/bob.png" --width 32 --height 32 2> "$work/stderr2"
if grep -q "bald" "$work/stderr2"; then echo "FAIL: a false bald-head warning" >&2; exit 1; fi
echo "ok: bald head warned"
