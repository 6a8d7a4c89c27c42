#!/usr/bin/env bash
# The viewer's timeline (issue 25 item 3): opened at frame F of an animated scene (`--frame F`,
# the panel's frame slider), it shows what `follicle render --frame F` draws, within the default
# line of viewer_scenes.tolerance, and a different picture from frame 0; a frame beyond the
# animation is an error naming the range. Skips (exit 0) without xvfb-run or the viewer.
source "$(dirname "$0")/lib/common.bash" "$@"
source "$(dirname "$0")/lib/viewer.bash"
SIZE=256
view() {  # scene frame out
  xvfb-run -a -s "-screen 0 1280x900x24" "$VIEWER" "$1" --frame "$2" --screenshot "$3" \
    --frames 2 --width $((400 + SIZE)) --height $SIZE
}
# A skeleton-driven hand (skin) and Anjyo hair following a head shake (dynamics).
for pair in hand_flexion_anim:36 anjyo_shake:20; do
  name=${pair%%:*} f=${pair##*:}
  scene="$ROOT/data/scenes/$name.json"
  view "$scene" "$f" "$TMP/$name.$f.png" > "$TMP/$name.out" 2>&1 ||
    { fail "$name: the viewer failed at frame $f: $(tail -3 "$TMP/$name.out")"; continue; }
  view "$scene" 0 "$TMP/$name.0.png" > "$TMP/$name.out0" 2>&1 ||
    { fail "$name: the viewer failed at frame 0: $(tail -3 "$TMP/$name.out0")"; continue; }
  "$FOLLICLE" -q render "$scene" --frame "$f" -o "$TMP/$name.cli.png" --width $SIZE \
    --height $SIZE 2> "$TMP/$name.err" || { fail "$name: follicle render failed: $(cat "$TMP/$name.err")"; continue; }
  read -r mean frac <<< "$($PNG diff "$TMP/$name.$f.png" "$TMP/$name.cli.png")"
  python3 -c "import sys; sys.exit(0 if $mean <= $mean_max and $frac <= $frac_max else 1)" ||
    fail "$name frame $f: viewer and follicle render differ: mean |diff| $mean (max $mean_max), fraction > 32: $frac (max $frac_max)"
  read -r moved _ <<< "$($PNG diff "$TMP/$name.$f.png" "$TMP/$name.0.png")"
  python3 -c "import sys; sys.exit(0 if $moved >= 0.5 else 1)" ||
    fail "$name: frame $f looks like frame 0 (mean |diff| $moved): the timeline did not move"
  echo "ok $name frame $f: vs render $mean / $frac, vs frame 0 $moved"
done
# Beyond the animation: an error with the range and a non-zero exit code.
if view "$ROOT/data/scenes/hand_flexion_anim.json" 100000 "$TMP/beyond.png" > "$TMP/beyond.out" 2>&1; then
  fail "--frame 100000 was accepted"
fi
grep -q -- "--frame 100000: the scene has" "$TMP/beyond.out" ||
  fail "--frame 100000: no clear error: $(cat "$TMP/beyond.out")"
[ "$fails" = 0 ] || exit 1
echo "viewer timeline: frames match follicle render"
