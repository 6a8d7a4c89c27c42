#!/usr/bin/env bash
# Issue 25 items 3-4: an edit made in follicle-viewer (here through --set, which goes the same
# way as the panel: the scene's JSON, then the scene reader) changes the view; the viewer's Save
# (--save) writes a scene that `follicle validate` accepts and that `follicle render` draws as the
# viewer showed it (within viewer_scenes.tolerance); a bad value is reported with its JSON path
# while the last good scene stays on screen. Skips (exit 0) without xvfb-run or the viewer.
source "$(dirname "$0")/lib/common.bash" "$@"
source "$(dirname "$0")/lib/viewer.bash"
SIZE=256
view() {  # view SCENE OUT.png [viewer options...]
  local scene=$1 out=$2
  shift 2
  xvfb-run -a -s "-screen 0 1280x900x24" "$VIEWER" "$scene" --screenshot "$out" --frames 2 \
    --width $((400 + SIZE)) --height $SIZE "$@"
}
within() { python3 -c "import sys; sys.exit(0 if $1 <= $2 and $3 <= $4 else 1)"; }

for case in "anjyo_bob hair[0].density_scale=0.3 hair[0].shading.hair_color=[0.5,0.3,0.1]" \
            "lcp_back_hair lcp.dynamics.integrator=\"implicit\" lcp.scenario.hair_length=0.18"; do
  read -r name set1 set2 <<< "$case"
  scene="$ROOT/data/scenes/$name.json"
  view "$scene" "$TMP/$name.orig.png" > "$TMP/$name.o.out" 2>&1 ||
    { fail "$name: the viewer failed: $(tail -2 "$TMP/$name.o.out")"; continue; }
  if ! view "$scene" "$TMP/$name.edit.png" --set "$set1" --set "$set2" \
      --save "$TMP/saved/$name.json" > "$TMP/$name.e.out" 2>&1; then
    fail "$name: the viewer failed with the edits: $(tail -2 "$TMP/$name.e.out")"; continue
  fi
  read -r mean _ <<< "$($PNG diff "$TMP/$name.orig.png" "$TMP/$name.edit.png")"
  within "$mean" 1.0 0 0 && fail "$name: the edit did not change the view (mean |diff| $mean)"
  "$FOLLICLE" -q validate "$TMP/saved/$name.json" > "$TMP/$name.v.out" 2>&1 ||
    fail "$name: follicle validate refused the saved scene: $(cat "$TMP/$name.v.out")"
  grep -q "$(echo "$set1" | sed 's/.*\.\([a-z_]*\)=.*/\1/')" "$TMP/saved/$name.json" ||
    fail "$name: the saved scene lacks the edited key"
  if ! "$FOLLICLE" -q render "$TMP/saved/$name.json" -o "$TMP/$name.cli.png" --width $SIZE \
      --height $SIZE 2> "$TMP/$name.r.err"; then
    fail "$name: follicle render of the saved scene failed: $(cat "$TMP/$name.r.err")"; continue
  fi
  read -r mean frac <<< "$($PNG diff "$TMP/$name.edit.png" "$TMP/$name.cli.png")"
  if within "$mean" "$mean_max" "$frac" "$frac_max"; then
    echo "ok $name: edited view = render of the saved scene (mean |diff| $mean, > 32: $frac)"
  else
    fail "$name: edited view and render of the saved scene differ: mean $mean, fraction $frac"
  fi
done

# A bad value: reported with its JSON path, exit 1, the last good scene still drawn.
scene="$ROOT/data/scenes/anjyo_bob.json"
if view "$scene" "$TMP/bad.png" --set 'hair[0].density_scale="abc"' > "$TMP/bad.out" 2>&1; then
  fail "a bad --set value was accepted"
fi
grep -q 'hair\[0\].density_scale: expected a number' "$TMP/bad.out" ||
  fail "the bad value's message lacks the JSON path: $(cat "$TMP/bad.out")"
[ -s "$TMP/bad.png" ] || fail "no view was drawn after the bad edit"
read -r mean _ <<< "$($PNG diff "$TMP/bad.png" "$TMP/anjyo_bob.orig.png")"
within "$mean" 0.5 0 0 || fail "after the bad edit the view is not the last good scene (mean $mean)"
view "$scene" "$TMP/bad2.png" --set 'hair[7].density_scale=1' > "$TMP/bad2.out" 2>&1 &&
  fail "an edit of a missing hair group was accepted"
grep -q "hair\[7\]" "$TMP/bad2.out" || fail "missing group: $(cat "$TMP/bad2.out")"
[ "$fails" = 0 ] || exit 1
echo "viewer edits: applied, saved, validated and rendered alike; bad values reported"
