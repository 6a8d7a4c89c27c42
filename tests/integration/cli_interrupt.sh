#!/usr/bin/env bash
# SIGTERM while `follicle animate` runs ffmpeg (issue 24): ffmpeg is stopped, the temporary MP4 is
# removed, no final MP4 appears, the message says what happened and the exit status is 128 + 15.
# ffmpeg is replaced by a stand-in on PATH that writes part of its output and then waits, so the
# signal lands while the video is being written, every time.
set -euo pipefail
FOLLICLE="$1"
ROOT="$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir -p "$work/bin"
tag="follicle-interrupt-test-$$"
cat > "$work/bin/ffmpeg" <<SH
#!/usr/bin/env bash
out="\${@: -1}"
printf 'partial video' > "\$out"
exec -a $tag sleep 120
SH
chmod +x "$work/bin/ffmpeg"

PATH="$work/bin:$PATH" "$FOLLICLE" -q animate "$ROOT/data/scenes/anjyo_shake.json" -o "$work/out" \
  --frames 0-1 --width 48 --height 48 2> "$work/stderr" &
pid=$!
for _ in $(seq 1 600); do
  compgen -G "$work/out/*.mp4.tmp-*" > /dev/null && break
  kill -0 "$pid" 2> /dev/null || break
  sleep 0.1
done
compgen -G "$work/out/*.mp4.tmp-*" > /dev/null || fail "the stand-in ffmpeg never started: $(cat "$work/stderr")"
kill -TERM "$pid"
set +e
wait "$pid"
status=$?
set -e
[ "$status" -eq 143 ] || fail "exit status $status, expected 143 (128 + SIGTERM)"
grep -q "terminated (SIGTERM); removed the unfinished output" "$work/stderr" \
  || fail "no message: $(cat "$work/stderr")"
if compgen -G "$work/out/*.tmp-*" > /dev/null; then fail "temporary files left: $(ls "$work/out")"; fi
[ ! -e "$work/out/anjyo_shake.mp4" ] || fail "a final MP4 exists"
[ -s "$work/out/frame_0000.png" ] && [ -s "$work/out/frame_0001.png" ] || fail "finished frames are missing"
sleep 0.2
if pgrep -f "$tag" > /dev/null; then pkill -f "$tag"; fail "the stand-in ffmpeg still runs"; fi
echo "ok: SIGTERM during the MP4 left no partial file and stopped ffmpeg"
