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
[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "bench ok"
