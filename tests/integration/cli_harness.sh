#!/usr/bin/env bash
# `follicle harness`: every hair model on a small copy of anjyo_shake writes a JSON report with
# every field for every model and a PNG sheet; --models, --group, --sheet-frames select; bad
# inputs exit non-zero with one line and leave no output behind.
source "$(dirname "$0")/lib/common.bash" "$@"

# A copy of data/scenes/anjyo_shake.json with absolute asset paths, low hair density, 4 frames
# and a tiny image (runs in seconds).
python3 - "$ROOT/data/scenes/anjyo_shake.json" "$TMP/shake.json" "$TMP/still.json" <<'PY'
import json, os, sys
src, out, still = sys.argv[1], sys.argv[2], sys.argv[3]
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
for m in s["assets"]["meshes"]:
    m["path"] = os.path.normpath(os.path.join(base, m["path"]))
    if m.get("material", {}).get("texture"):
        m["material"]["texture"] = os.path.normpath(os.path.join(base, m["material"]["texture"]))
for h in s["hair"]:
    h["density_scale"] = 0.03
s["render"].update(width=64, height=64, supersample=1)
s["animation"]["frames"] = 4
json.dump(s, open(out, "w"), indent=1)
del s["animation"]
json.dump(s, open(still, "w"), indent=1)
PY

H() { "$FOLLICLE" harness "$@"; }

# Every model, every frame.
H "$TMP/shake.json" --json "$TMP/r.json" --sheet "$TMP/s.png" --thumb-size 48 >"$TMP/out" 2>"$TMP/err" \
  || { fail "harness"; cat "$TMP/err"; }
grep -q "^wrote $TMP/r.json" "$TMP/out" || fail "no 'wrote' line for the report: $(cat "$TMP/out")"
grep -q "^wrote $TMP/s.png" "$TMP/out" || fail "no 'wrote' line for the sheet: $(cat "$TMP/out")"
head -c 8 "$TMP/s.png" | grep -q PNG || fail "sheet is not a PNG"
python3 - "$TMP/r.json" all 0 3 <<'PY' || fail "report fields"
import json, math, sys
r = json.load(open(sys.argv[1]))
first, last = int(sys.argv[3]), int(sys.argv[4])
assert r["first_frame"] == first and r["last_frame"] == last, (r["first_frame"], r["last_frame"])
assert len(r["models"]) >= 1
assert r["models"][0]["model"] == "anjyo1992"
for m in r["models"]:
    for k in ["model", "max_stretch_percent", "max_penetration_mm", "root_drift_mm", "time_s",
              "kinetic_j", "potential_j", "total_j", "stretch_percent",
              "ms_per_simulated_second", "strands", "points", "frames"]:
        assert k in m, (m["model"], k)
    assert m["ok"], (m["model"], m["error"])
    assert m["frames"] == last - first + 1, m["frames"]
    for k in ["time_s", "kinetic_j", "potential_j", "total_j", "stretch_percent"]:
        assert len(m[k]) == m["frames"], (m["model"], k)
    assert m["strands"] > 0 and m["points"] > m["strands"]
    for k, e, p in zip(m["total_j"], m["kinetic_j"], m["potential_j"]):
        assert math.isclose(k, e + p, rel_tol=1e-12, abs_tol=1e-300)
    assert abs(m["time_s"][1] - m["time_s"][0] - 1.0 / r["fps"]) < 1e-12
PY

# One model by name, a group by name, chosen sheet frames and range.
H "$TMP/shake.json" --models anjyo1992 --group bob --frames 1-3 --sheet-frames 1,3 \
  --json "$TMP/r1.json" --sheet "$TMP/s1.png" --thumb-size 32 -q 2>"$TMP/err" \
  || { fail "harness --models"; cat "$TMP/err"; }
python3 - "$TMP/r1.json" <<'PY' || fail "report of --models anjyo1992 --frames 1-3"
import json, sys
r = json.load(open(sys.argv[1]))
assert [m["model"] for m in r["models"]] == ["anjyo1992"]
assert r["sheet_frames"] == [1, 3] and r["first_frame"] == 1 and r["last_frame"] == 3
assert r["models"][0]["frames"] == 3
PY
[ -s "$TMP/s1.png" ] || fail "sheet of --models missing"

# Bad inputs: exit 2 (usage) or 1 (scene), one line, no output written.
bad() {  # bad CODE WHAT ARGS...
  local code=$1 what=$2
  shift 2
  rm -f "$TMP/b.json" "$TMP/b.png"
  H "$@" >/dev/null 2>"$TMP/err"
  local rc=$?
  [ $rc = "$code" ] || fail "$what: exit $rc, expected $code: $(cat "$TMP/err")"
  [ "$(wc -l <"$TMP/err")" = 1 ] || { fail "$what: not one line"; cat "$TMP/err"; }
  [ ! -e "$TMP/b.json" ] && [ ! -e "$TMP/b.png" ] || fail "$what: left an output"
}
bad 2 "missing --json" "$TMP/shake.json" --sheet "$TMP/b.png"
grep -q -- "--json" "$TMP/err" || fail "missing --json: message does not name it: $(cat "$TMP/err")"
bad 2 "missing --sheet" "$TMP/shake.json" --json "$TMP/b.json"
bad 2 "bad --frames" "$TMP/shake.json" --frames 1-x --json "$TMP/b.json" --sheet "$TMP/b.png"
grep -q -- "--frames" "$TMP/err" || fail "bad --frames: message does not name it: $(cat "$TMP/err")"
bad 2 "reversed --frames" "$TMP/shake.json" --frames 3-1 --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "--frames past the clip" "$TMP/shake.json" --frames 0-99 --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "one frame" "$TMP/shake.json" --frames 2-2 --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "unknown model" "$TMP/shake.json" --models anjyo1992,hairy --json "$TMP/b.json" --sheet "$TMP/b.png"
grep -q "anjyo1992" "$TMP/err" || fail "unknown model: known models not listed: $(cat "$TMP/err")"
bad 2 "unknown group" "$TMP/shake.json" --group 7 --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "bad --sheet-frames" "$TMP/shake.json" --sheet-frames 1,b --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "--sheet-frames outside" "$TMP/shake.json" --sheet-frames 9 --json "$TMP/b.json" --sheet "$TMP/b.png"
bad 2 "--sheet not .png" "$TMP/shake.json" --json "$TMP/b.json" --sheet "$TMP/b.jpg"
bad 1 "still scene" "$TMP/still.json" --json "$TMP/b.json" --sheet "$TMP/b.png"
grep -q "still scene" "$TMP/err" || fail "still scene: unclear message: $(cat "$TMP/err")"
bad 1 "missing scene" "$TMP/nope.json" --json "$TMP/b.json" --sheet "$TMP/b.png"

find "$TMP" -name '*.tmp-*' | grep -q . && fail "temporary file left behind"
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "harness cli ok"
