#!/usr/bin/env bash
# The skin on the CLI: `follicle export --mesh` of a face rig (OBJ round trip readable by
# `follicle info`, PLY too, atomically written), `follicle compare` (a mesh with itself: zeros;
# with and without wrinkles: a positive maximum and an error render of the requested size),
# `follicle animate` of the contraction track, and clean one-line errors for bad inputs. Uses
# small copies of the shipped scenes (one refinement level, tiny images).
source "$(dirname "$0")/lib/common.bash" "$@"

# small SCENE OUT [FRAMES FPS]: data/scenes/SCENE.json with absolute paths, one refinement level,
# a small image and (for animations) FRAMES frames at FPS.
small() {
  python3 - "$ROOT/data/scenes/$1.json" "$2" "${3:-0}" "${4:-0}" <<'PY'
import json, os, sys
src, out, frames, fps = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
for m in s["assets"]["meshes"]:
    m["path"] = os.path.normpath(os.path.join(base, m["path"]))
    mat = m.get("material", {})
    if "texture" in mat:
        mat["texture"] = os.path.normpath(os.path.join(base, mat["texture"]))
for k in s.get("skin", []):
    k["muscles"] = os.path.normpath(os.path.join(base, k["muscles"]))
    k.setdefault("refine", {})["max_levels"] = 1
s["render"].update(width=96, height=96, supersample=1)
if frames and "animation" in s:
    s["animation"].update(frames=frames, fps=fps)
json.dump(s, open(out, "w"), indent=1)
PY
}
png_size() { python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print(*struct.unpack('>II', d[16:24]))" "$1"; }
# field LABEL COLUMN FILE: a number of the `follicle compare` table (columns: mean rms p95 max)
field() { awk -v l="$1" -v c="$2" '$1 == l { print $(c + 1) }' "$3"; }

small skin_angry "$TMP/angry.json"
small skin_angry_nowrinkles "$TMP/flat.json"

# export --mesh: OBJ in mm, readable back; PLY too; no temporary files left.
"$FOLLICLE" export "$TMP/angry.json" --mesh "$TMP/angry.obj" --units mm -q 2>"$TMP/err" \
  || { fail "export --mesh obj"; cat "$TMP/err"; }
"$FOLLICLE" info "$TMP/angry.obj" --units mm >"$TMP/info" 2>&1 || { fail "info of the export"; cat "$TMP/info"; }
grep -qi 'vert' "$TMP/info" || { fail "info output"; cat "$TMP/info"; }
"$FOLLICLE" export "$TMP/flat.json" --mesh "$TMP/flat.ply" --units mm -q 2>"$TMP/err" \
  || { fail "export --mesh ply"; cat "$TMP/err"; }
ls "$TMP" | grep -q '\.tmp' && fail "temporary files left behind"

# compare: a mesh with itself prints zeros; with the no-wrinkle face a positive maximum.
"$FOLLICLE" compare "$TMP/angry.obj" "$TMP/angry.obj" --units mm --samples 20000 >"$TMP/self" 2>"$TMP/err" \
  || { fail "compare self"; cat "$TMP/err"; }
for c in 1 2 3 4; do
  v=$(field two-sided $c "$TMP/self")
  python3 -c "import sys; sys.exit(0 if abs(float('$v')) < 1e-3 else 1)" 2>/dev/null \
    || { fail "compare self column $c: '$v'"; cat "$TMP/self"; }
done
"$FOLLICLE" compare "$TMP/angry.obj" "$TMP/flat.ply" --units mm --samples 20000 -o "$TMP/err.png" \
  --width 128 --height 96 >"$TMP/diff" 2>"$TMP/err" || { fail "compare wrinkled/flat"; cat "$TMP/err"; }
mx=$(field two-sided 4 "$TMP/diff")
mean=$(field two-sided 1 "$TMP/diff")
python3 -c "import sys; sys.exit(0 if float('$mx') > 0.1 and float('$mx') > float('$mean') else 1)" 2>/dev/null \
  || { fail "compare wrinkled/flat max '$mx' mean '$mean'"; cat "$TMP/diff"; }
[ "$(png_size "$TMP/err.png" 2>/dev/null)" = "128 96" ] || fail "error render size: $(png_size "$TMP/err.png" 2>&1)"

# animate the contraction track: 3 frames at 1 fps (neutral, surprise, angry side).
small skin_track "$TMP/track.json" 3 1
"$FOLLICLE" animate "$TMP/track.json" -o "$TMP/anim" --no-video -q 2>"$TMP/err" \
  || { fail "animate"; cat "$TMP/err"; }
for f in 0 1 2; do [ -s "$TMP/anim/frame_000$f.png" ] || fail "frame $f missing"; done
cmp -s "$TMP/anim/frame_0000.png" "$TMP/anim/frame_0001.png" && fail "the track does not move the face"

# Bad inputs: exit non-zero with one line naming the problem.
expect_error() {  # CODE PATTERN command...
  local code=$1 pat=$2; shift 2
  "$@" >/dev/null 2>"$TMP/err"
  local rc=$?
  [ $rc = "$code" ] && [ "$(wc -l <"$TMP/err")" = 1 ] && grep -q -- "$pat" "$TMP/err" \
    || { fail "expected exit $code matching '$pat' from: $*  (got $rc)"; cat "$TMP/err"; }
}
expect_error 2 '.obj, .ply' "$FOLLICLE" export "$TMP/angry.json" --mesh "$TMP/x.stl"
expect_error 1 'skin' "$FOLLICLE" export "$ROOT/data/scenes/anjyo_bob.json" --mesh "$TMP/x.obj"
expect_error 2 'no face rig' "$FOLLICLE" export "$TMP/angry.json" --mesh "$TMP/x.obj" --rig face
expect_error 2 'rig applies' "$FOLLICLE" export "$TMP/angry.json" --hair "$TMP/x.hair" --rig head
expect_error 2 'nothing to export' "$FOLLICLE" export "$TMP/angry.json"
expect_error 1 'nope.obj' "$FOLLICLE" compare "$TMP/nope.obj" "$TMP/angry.obj"
expect_error 2 '.png' "$FOLLICLE" compare "$TMP/angry.obj" "$TMP/angry.obj" -o "$TMP/e.jpg"
[ -e "$TMP/x.obj" ] && fail "a failed export left a file"
python3 - "$TMP/angry.json" "$TMP/bad.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); s["skin"][0]["expression"] = "angery"
json.dump(s, open(sys.argv[2], "w"))
PY
expect_error 1 'skin\[0\].expression' "$FOLLICLE" validate "$TMP/bad.json"
# The head declared in cm instead of mm: the face setup's muscles lie far from its surface, and
# the export is refused naming the numbers and the fix (before: a face without wrinkles, exit 0).
python3 - "$TMP/angry.json" "$TMP/wrong_units.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for m in s["assets"]["meshes"]:
    if m.get("units") == "mm":
        m["units"] = "cm"
json.dump(s, open(sys.argv[2], "w"))
PY
expect_error 1 'the face setup does not fit this mesh: 17 of 17 muscles lie more than 2 cm from its surface.*check the mesh.s units' \
  "$FOLLICLE" export "$TMP/wrong_units.json" --mesh "$TMP/wu.obj" --units mm
[ -e "$TMP/wu.obj" ] && fail "a refused export left a file"

[ $fails = 0 ] && echo "cli_skin: all passed"
exit $fails
