#!/usr/bin/env bash
# Resource guards and progress (issue 24 items 5 and 7): scenes whose sizes explode inside
# documented ranges are stopped at once with the reason and the fix instead of running for
# minutes with growing memory; long settling shows a progress bar on a terminal.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
edit() {  # edit SCENE OUT PYTHON-STATEMENTS (on d, the scene dict; paths made absolute)
  python3 - "$ROOT" "$1" "$2" "$3" <<'PY'
import json, os, sys
root, name, out, code = sys.argv[1:]
d = json.load(open(f"{root}/data/scenes/{name}.json"))
base = f"{root}/data/scenes"
for m in d.get("assets", {}).get("meshes", []):
    m["path"] = os.path.join(base, m["path"])
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = os.path.join(base, m["material"]["texture"])
if "hand" in d:
    d["hand"]["makehuman"] = os.path.join(base, d["hand"]["makehuman"])
exec(code)
json.dump(d, open(out, "w"))
PY
}
expect_refused() {  # expect_refused SCENE-FILE PATTERN SECONDS
  local t0 rc
  t0=$(date +%s)
  set +e
  timeout 120 "$FOLLICLE" render "$1" -o "$work/out.png" --width 32 --height 32 2> "$work/err"
  rc=$?
  set -e
  [ "$rc" -eq 1 ] || fail "$1 exited $rc, expected 1: $(cat "$work/err")"
  grep -q "$2" "$work/err" || fail "$1: no '$2' in: $(cat "$work/err")"
  [ ! -e "$work/out.png" ] || fail "$1: an image was written"
  [ $(($(date +%s) - t0)) -le "$3" ] || fail "$1 took more than $3 s to refuse"
  echo "ok: $(basename "$1") refused: $(head -c 300 "$work/err")"
}
# Hand refinement 8 levels at edge_factor 0.05 (before: minutes, growing memory).
edit hand_flex "$work/hand8.json" 'd["hand"]["rig"]["refine"] = {"max_levels": 8, "edge_factor": 0.05}'
expect_refused "$work/hand8.json" "refine.max_triangles.*raise edge_factor (now 0.05)" 60
# A 10 m sphere head for the lcp hair (before: 178 M body samples, minutes): outside the range.
edit lcp_shake "$work/lcp10.json" 'd["lcp"]["mesh"] = ""; d["lcp"]["scenario"].pop("mesh_head"); d["lcp"]["scenario"]["head_radius"] = 10'
expect_refused "$work/lcp10.json" "head_radius.*\[0.03, 1\]" 10
# A style far denser than the strand budget (100 x the bob: about 1 M strands, over a budget of
# 200 k).
edit anjyo_bob "$work/dense.json" 'd["hair"][0]["density_scale"] = 100; d["hair"][0]["max_strands"] = 2e5'
expect_refused "$work/dense.json" "max_strands: the style would grow about .* M strands .*more than the budget of 200 k" 30
# Settling shows progress on a terminal (script(1) gives the program a pseudo-terminal; $CI
# switches bars off, so it is unset here).
edit lcp_shake "$work/settle.json" 'd["lcp"]["scenario"]["settle_time"] = 4; d["animation"]["duration"] = 0.05'
if command -v script > /dev/null; then
  env -u CI script -qec "'$FOLLICLE' render '$work/settle.json' -o '$work/s.png' --width 32 --height 32 --frame 0" \
    "$work/typescript" > /dev/null || fail "settle scene failed: $(cat "$work/typescript")"
  grep -q "settling hair \[" "$work/typescript" || fail "no progress bar: $(cat "$work/typescript")"
  echo "ok: settling shows a progress bar"
  # Without a terminal (a log file, CI) no bar is drawn.
  "$FOLLICLE" render "$work/settle.json" -o "$work/s2.png" --width 32 --height 32 --frame 0 2> "$work/err"
  if grep -q "settling hair \[" "$work/err"; then fail "a bar was drawn without a terminal"; fi
else
  echo "skipped the progress check: no script(1)"
fi
# A framebuffer beyond the GL's limits, and one beyond the memory the process may use.
set +e
"$FOLLICLE" render "$ROOT/data/scenes/anjyo_bob.json" -o "$work/big.png" --width 16384 --height 16384 2> "$work/err"
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "16384x16384 at supersample 3 exited $rc: $(cat "$work/err")"
grep -q "at supersample 3 needs a 49152x49152 framebuffer; this GL allows" "$work/err" || fail "no GL limit: $(cat "$work/err")"
edit anjyo_bob "$work/ss1.json" 'd["render"]["supersample"] = 1; d["hair"][0]["density_scale"] = 0.01'
set +e
(ulimit -v 4000000; "$FOLLICLE" render "$work/ss1.json" -o "$work/big.png" --width 16000 --height 16000 2> "$work/err")
rc=$?
set -e
[ "$rc" -eq 1 ] || fail "16000x16000 under a 4 GB limit exited $rc: $(cat "$work/err")"
grep -q "render: a 16000x16000 framebuffer at supersample 1 needs about .* GB but this machine has .* available" "$work/err" \
  || fail "no memory estimate: $(cat "$work/err")"
echo "ok: framebuffers beyond the GL limits or the memory are refused before they are made"
