#!/usr/bin/env bash
# follicle bench: --list, one short run printing one JSON object with the required keys, and
# clean errors for unknown workloads and sizes.
source "$(dirname "$0")/lib/common.bash" "$@"

"$FOLLICLE" bench --list >"$TMP/list" 2>"$TMP/err" || { fail "bench --list"; cat "$TMP/err"; }
cat "$TMP/list"
"$FOLLICLE" bench no-such-workload 2>"$TMP/err" >/dev/null
[ $? = 1 ] && grep -q "unknown workload 'no-such-workload'" "$TMP/err" || { fail "unknown workload"; cat "$TMP/err"; }

# A short run of the cheapest workload we know (mesh-load), else the first listed one.
W=$(awk '{print $1}' "$TMP/list" | grep -x mesh-load || true)
[ -n "$W" ] || W=$(awk 'NR==1 {print $1}' "$TMP/list")
if [ -z "$W" ]; then
  echo "no workloads registered yet: skipping the run"
else
  "$FOLLICLE" bench "$W" --threads 1 --min-seconds 0 -q >"$TMP/run" 2>"$TMP/err" || { fail "bench $W"; cat "$TMP/err"; }
  cat "$TMP/run"
  python3 - "$TMP/run" "$W" <<'PY' || fail "bench output"
import json, sys
lines = [l for l in open(sys.argv[1]).read().splitlines() if l.strip()]
assert len(lines) == 1, f"expected one line, got {len(lines)}"
o = json.loads(lines[0])
keys = {"workload", "params", "threads", "iterations", "seconds_per_iter", "throughput", "throughput_unit"}
assert set(o) == keys, f"keys {sorted(o)}"
assert o["workload"] == sys.argv[2]
assert o["threads"] == 1 and o["iterations"] >= 1 and o["seconds_per_iter"] > 0 and o["throughput"] > 0
assert isinstance(o["params"], dict)
PY
  "$FOLLICLE" bench "$W" --size no_such_key=3 2>"$TMP/err" >/dev/null
  [ $? = 1 ] && grep -q "has no size 'no_such_key'" "$TMP/err" || { fail "unknown size key"; cat "$TMP/err"; }
fi
# large-mesh-load writes its mesh in each format, reads it back and checks the triangle count;
# a small size keeps this quick. Its temporary folder is removed afterwards.
for F in 0 1 2 3; do
  "$FOLLICLE" bench large-mesh-load --size triangles=2000 --size format=$F --min-seconds 0 -q \
    >"$TMP/run" 2>"$TMP/err" || { fail "large-mesh-load format $F"; cat "$TMP/err"; }
done
ls -d "${TMPDIR:-/tmp}"/follicle-mesh-load-* 2>/dev/null && fail "large-mesh-load left its folder"
"$FOLLICLE" bench large-mesh-load --size format=4 --min-seconds 0 2>"$TMP/err" >/dev/null
[ $? = 1 ] && grep -q "size 'format' = 4 is not one of" "$TMP/err" || { fail "bad format"; cat "$TMP/err"; }
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "bench ok"
