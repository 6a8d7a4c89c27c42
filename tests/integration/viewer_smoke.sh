#!/usr/bin/env bash
# follicle-viewer in batch mode under Xvfb: renders the default scene, writes a PNG of the view
# and one of the whole window (with the panel), both non-uniform; a broken scene exits 1 with a
# message and writes nothing. Skips (exit 0) without xvfb-run or when the viewer is not built.
# Usage: bash viewer_smoke.sh <follicle-binary> <repo-root>
set -u
FOLLICLE=$(realpath "$1")
ROOT=$2
VIEWER="$(dirname "$FOLLICLE")/../viewer/follicle-viewer"
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "SKIP: xvfb-run not installed"; exit 0
fi
if [ ! -x "$VIEWER" ]; then
  echo "SKIP: follicle-viewer not built (configure with -DFOLLICLE_BUILD_VIEWER=ON)"; exit 0
fi
VIEWER=$(realpath "$VIEWER")
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
SCENE="$ROOT/data/scenes/default.json"
XVFB=(xvfb-run -a -s "-screen 0 1280x1024x24")

# Prints "W H distinct_colours" of a PNG.
png_stats() { python3 "$(dirname "$0")/lib/png_tools.py" stats "$1"; }

# 1. The 3D view.
"${XVFB[@]}" "$VIEWER" "$SCENE" --screenshot "$TMP/view.png" --frames 3 --width 1000 --height 700 \
  >"$TMP/out" 2>&1 || { fail "viewer batch screenshot"; cat "$TMP/out"; }
if [ -f "$TMP/view.png" ]; then
  read -r w h n <<<"$(png_stats "$TMP/view.png")"
  # The panel (400 px) is not part of the view.
  [ "$w $h" = "600 700" ] || fail "view size is ${w}x${h}, expected 600x700"
  [ "${n:-0}" -gt 50 ] || fail "view looks uniform ($n colours)"
else
  fail "no view screenshot written"
fi

# 2. The whole window with the panel.
"${XVFB[@]}" "$VIEWER" "$SCENE" --screenshot "$TMP/window.png" --with-ui --frames 3 \
  --width 1000 --height 700 >"$TMP/out" 2>&1 || { fail "viewer window screenshot"; cat "$TMP/out"; }
if [ -f "$TMP/window.png" ]; then
  read -r w h n <<<"$(png_stats "$TMP/window.png")"
  [ "$w $h" = "1000 700" ] || fail "window size is ${w}x${h}, expected 1000x700"
  [ "${n:-0}" -gt 50 ] || fail "window looks uniform ($n colours)"
else
  fail "no window screenshot written"
fi

# 3. A broken scene: exit 1, an error naming the problem, no output file.
printf '{"follicle_scene": 1, "camera": {"fov_deg": 500}}\n' >"$TMP/broken.json"
"${XVFB[@]}" "$VIEWER" "$TMP/broken.json" --screenshot "$TMP/broken.png" --frames 2 \
  >"$TMP/out" 2>&1
rc=$?
[ "$rc" = 1 ] || { fail "broken scene exit code $rc"; cat "$TMP/out"; }
grep -q "fov_deg" "$TMP/out" || { fail "broken scene error does not name camera.fov_deg"; cat "$TMP/out"; }
[ ! -e "$TMP/broken.png" ] || fail "broken scene left a screenshot"
find "$TMP" -name '*.tmp*' | grep -q . && fail "temporary file left behind"

[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "viewer ok"
