#!/usr/bin/env bash
# follicle info on a mesh and a scene; follicle convert round trips OBJ -> PLY -> glTF -> OBJ
# with unit changes and keeps counts and bounds.
source "$(dirname "$0")/lib/common.bash" "$@"
MESH="$ROOT/data/meshes/lee_perry_smith/head.obj"

"$FOLLICLE" info "$MESH" --units mm >"$TMP/info0" 2>"$TMP/err" || { fail "info mesh"; cat "$TMP/err"; }
cat "$TMP/info0"
nv=$(grep -c '^v ' "$MESH")
grep -qx "vertices: $nv" "$TMP/info0" || fail "vertex count is not $nv"
grep -q '^faces: [1-9]' "$TMP/info0" || fail "no face count"
grep -q '^uvs: yes' "$TMP/info0" || fail "head has UVs"
grep -q '^units: mm' "$TMP/info0" || fail "units not reported"
grep -q '^bounds max: \[' "$TMP/info0" || fail "no bounds"
grep -q '^units: mm (as declared with --units)' "$TMP/info0" || fail "declared unit not said"
grep -q '^note:' "$TMP/info0" && fail "a head in mm declared mm got a size note"
# Without --units: metres are assumed, and said; the head (in mm) is 250 m across in metres,
# which the note names with the unit that fits.
"$FOLLICLE" info "$MESH" >"$TMP/info_nounits" 2>"$TMP/err" || { fail "info without units"; cat "$TMP/err"; }
grep -q '^units: m (assumed: no --units given' "$TMP/info_nounits" || fail "assumed unit not said: $(grep units "$TMP/info_nounits")"
grep -q "^note: .* m across in m (assumed) is not the size of a head, bust, hand or body; with --units mm it is 0\.[0-9][0-9] m across" "$TMP/info_nounits" \
  || fail "size note: $(grep note "$TMP/info_nounits")"

"$FOLLICLE" info "$ROOT/data/scenes/default.json" >"$TMP/sinfo" 2>"$TMP/err" || { fail "info scene"; cat "$TMP/err"; }
grep -q '^meshes: 1' "$TMP/sinfo" || fail "scene info: meshes"
grep -q '^lights: 3' "$TMP/sinfo" || fail "scene info: lights"

# mm OBJ -> m PLY (binary) -> glTF (metres by specification) -> mm OBJ; and an ASCII PLY.
"$FOLLICLE" convert "$MESH" "$TMP/a.ply" --in-units mm --out-units m -q || fail "convert obj->ply"
if "$FOLLICLE" convert "$TMP/a.ply" "$TMP/bad.gltf" --in-units m --out-units cm -q 2>"$TMP/err"; then
  fail "a glTF in cm was written"
fi
grep -q "glTF stores metres by specification" "$TMP/err" || fail "glTF unit message: $(cat "$TMP/err")"
[ ! -e "$TMP/bad.gltf" ] || fail "a refused glTF was left behind"
"$FOLLICLE" convert "$TMP/a.ply" "$TMP/b.gltf" --in-units m --out-units m -q || fail "convert ply->gltf"
"$FOLLICLE" convert "$TMP/b.gltf" "$TMP/c.obj" --in-units m --out-units mm -q || fail "convert gltf->obj"
"$FOLLICLE" convert "$MESH" "$TMP/d.ply" --in-units mm --out-units mm --ascii -q || fail "convert ascii ply"
head -c 3 "$TMP/d.ply" | grep -q ply || fail "ascii ply header"
grep -q 'format ascii' "$TMP/d.ply" || fail "ply is not ascii"
"$FOLLICLE" info "$TMP/c.obj" --units mm >"$TMP/info1" 2>"$TMP/err" || { fail "info round trip"; cat "$TMP/err"; }
"$FOLLICLE" info "$TMP/a.ply" --units m >"$TMP/info2" 2>"$TMP/err" || { fail "info ply"; cat "$TMP/err"; }
# PLY and glTF store one UV per vertex, so vertices on UV seams are split there: compare faces,
# bounds and area through the chain, and vertex counts on a direct OBJ -> OBJ unit round trip.
for k in faces 'bounds min' 'bounds max' 'surface area'; do
  a=$(grep "^$k:" "$TMP/info0"); b=$(grep "^$k:" "$TMP/info1")
  [ "$a" = "$b" ] || fail "round trip changed '$k': '$a' vs '$b'"
done
"$FOLLICLE" convert "$MESH" "$TMP/e.obj" --in-units mm --out-units m -q || fail "convert obj->obj"
"$FOLLICLE" convert "$TMP/e.obj" "$TMP/f.obj" --in-units m --out-units mm -q || fail "convert obj->obj back"
"$FOLLICLE" info "$TMP/f.obj" --units mm >"$TMP/info3" 2>"$TMP/err" || { fail "info obj round trip"; cat "$TMP/err"; }
for k in vertices faces uvs 'bounds min' 'bounds max'; do
  a=$(grep "^$k:" "$TMP/info0"); b=$(grep "^$k:" "$TMP/info3")
  [ "$a" = "$b" ] || fail "obj round trip changed '$k': '$a' vs '$b'"
done
grep -q "^faces: $(grep '^faces:' "$TMP/info0" | cut -d' ' -f2)" "$TMP/info2" || fail "ply face count"
# Same surface area whatever the units (reported in m^2).
a=$(grep '^surface area' "$TMP/info0"); b=$(grep '^surface area' "$TMP/info2")
[ "$a" = "$b" ] || fail "area differs: '$a' vs '$b'"
# Converting a broken file fails cleanly and writes nothing.
printf 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n' >"$TMP/nan.obj"
"$FOLLICLE" convert "$TMP/nan.obj" "$TMP/nan.ply" 2>"$TMP/err"
[ $? = 1 ] && [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "nan mesh not rejected cleanly"; cat "$TMP/err"; }
[ ! -e "$TMP/nan.ply" ] || fail "output left behind"
ls "$TMP" | grep -q 'tmp-' && fail "temporary file left behind"
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "info/convert ok"
