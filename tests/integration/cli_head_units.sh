#!/usr/bin/env bash
# A hair mesh whose size is implausible for its declared units is named before any hair grows
# (issue 24 item 5, issue 21 item 6): the Lee Perry-Smith bust is in mm; declared cm (6 m
# across) it warns with the unit that fits, declared m (595 m across) it is refused at once
# instead of growing millions of strands.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
make_scene() {  # make_scene UNITS OUT
  python3 - "$ROOT" "$1" "$2" <<'PY'
import json, sys
root, units, out = sys.argv[1:]
d = json.load(open(f"{root}/data/scenes/anjyo_bob.json"))
for m in d["assets"]["meshes"]:
    m["path"] = f"{root}/data/scenes/{m['path']}"
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = f"{root}/data/scenes/{m['material']['texture']}"
    m["units"] = units
d["hair"][0]["density_scale"] = 0.01
json.dump(d, open(out, "w"))
PY
}
make_scene cm "$work/cm.json"
"$FOLLICLE" render "$work/cm.json" -o "$work/cm.png" --width 32 --height 32 2> "$work/err" \
  || fail "cm scene failed: $(cat "$work/err")"
grep -q 'mesh "head" is 5.95 m across (assets.meshes\[0\].units is "cm").*with "units": "mm" it would be 0.59 m' "$work/err" \
  || fail "no size warning: $(cat "$work/err")"
make_scene m "$work/m.json"
set +e
timeout 60 "$FOLLICLE" render "$work/m.json" -o "$work/m.png" --width 32 --height 32 2> "$work/err"
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "metres scene exited $rc, expected 1: $(cat "$work/err")"
grep -q 'mesh "head" is 595 m across.*"units": "mm" it would be 0.59 m' "$work/err" \
  || fail "no size error: $(cat "$work/err")"
[ ! -e "$work/m.png" ] || fail "an image was written"
"$FOLLICLE" render "$ROOT/data/scenes/anjyo_bob.json" -o "$work/ok.png" --width 32 --height 32 2> "$work/err"
if grep -q "across" "$work/err"; then fail "false size warning: $(cat "$work/err")"; fi
echo "ok: implausible head sizes are named with the fitting unit"
