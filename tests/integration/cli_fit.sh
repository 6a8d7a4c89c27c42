#!/usr/bin/env bash
# follicle fit (issue 21 item 2) on a head the template was not made for (the shipped Sintel bust,
# cm): it prints the orientation and the registration residual in mm, writes setup.json,
# scene.json and fit.png; the scene validates and renders; the same head turned about a skew
# axis and stored in mm gives the turned orientation; bad input fails with the reason and
# writes nothing.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$FOLLICLE" -q fit "$ROOT/data/meshes/sintel/sintel.obj" --units cm -o "$work/fit" \
  --image-size 200 > "$work/out" 2> "$work/err" || fail "fit failed: $(cat "$work/err")"
grep -q "registration residual: RMS [0-9.]* mm" "$work/out" || fail "no residual: $(cat "$work/out")"
grep -q "orientation: up \[.*\] (found)" "$work/out" || fail "no orientation: $(cat "$work/out")"
for f in setup.json scene.json fit.png; do [ -s "$work/fit/$f" ] || fail "no $f"; done
python3 - "$work/fit" <<'PY' || fail "setup/scene content"
import json, math, sys
d = sys.argv[1]
s = json.load(open(f"{d}/setup.json"))
up, front = s["up"], s["front"]
assert up[1] > 0.97 and front[2] > 0.97, (up, front)  # Sintel is y up, facing +z
assert len(s["muscles"]["linear"]) == 14 and len(s["surface_wrinkles"]) == 10
sc = json.load(open(f"{d}/scene.json"))
assert sc["skin"][0]["muscles"] == "setup.json" and sc["hair"][0]["style"] == "bob"
assert sc["assets"]["meshes"][0]["units"] == "cm"
PY
"$FOLLICLE" -q validate "$work/fit/scene.json" 2> "$work/err" || fail "scene invalid: $(cat "$work/err")"
"$FOLLICLE" -q render "$work/fit/scene.json" -o "$work/r.png" --width 96 --height 96 \
  2> "$work/err" || fail "render failed: $(cat "$work/err")"

# Turned 90 degrees about x (face looking down -y... up along +z) and stored in mm.
python3 - "$ROOT/data/meshes/sintel/sintel.obj" "$work/turned.obj" <<'PY'
import sys
src, out = sys.argv[1:]
with open(out, "w") as o:
    for l in open(src):
        if l.startswith("v "):
            x, y, z = map(float, l.split()[1:4])
            o.write(f"v {10*x:.5f} {-10*z:.5f} {10*y:.5f}\n")  # (x, y, z) -> (x, -z, y), cm -> mm
        elif l.startswith("f "):  # positions only: no UVs, no normals
            o.write("f " + " ".join(t.split("/")[0] for t in l.split()[1:]) + "\n")
PY
"$FOLLICLE" -q fit "$work/turned.obj" --units mm -o "$work/turned" --image-size 96 \
  > "$work/out2" 2> "$work/err" || fail "turned fit failed: $(cat "$work/err")"
python3 - "$work/turned/setup.json" <<'PY' || fail "turned orientation: $(cat "$work/out2")"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["up"][2] > 0.97 and s["front"][1] < -0.97, (s["up"], s["front"])
PY

# Bad input: a missing file, --up without --front; nothing written.
if "$FOLLICLE" -q fit "$work/none.obj" --units cm -o "$work/bad" 2> "$work/err"; then
  fail "missing head accepted"
fi
grep -q "none.obj" "$work/err" || fail "missing file not named: $(cat "$work/err")"
[ ! -e "$work/bad" ] || fail "output written for a failed fit"
set +e
"$FOLLICLE" -q fit "$ROOT/data/meshes/sintel/sintel.obj" --units cm -o "$work/bad" --up 0 1 0 \
  2> "$work/err"
rc=$?
set -e
[ "$rc" -eq 2 ] || fail "--up alone: exit $rc, want 2"
grep -q "both --up and --front" "$work/err" || fail "no reason: $(cat "$work/err")"
echo "cli_fit: ok"
