#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang + AddressSanitizer + UBSan) in build/fuzz and runs
# them on their seed corpora and dictionaries.
#
#   bash tools/fuzz.sh                       # every target, 60 s each
#   bash tools/fuzz.sh --seconds 5           # smoke pass
#   bash tools/fuzz.sh --runs 1000000 ply    # one target, 1M executions
#   bash tools/fuzz.sh --build-only
#   bash tools/fuzz.sh --no-build --runs 1000000 hair tfx   # reuse build/fuzz as it is
#   bash tools/fuzz.sh --keep-going --runs 1000000 png       # fork mode: go on after findings
#
# Prints per target: executions, exec/s, coverage (libFuzzer's final cov:), corpus size (inputs
# / bytes) and findings (crash, sanitizer report, uncaught exception, timeout, out of memory).
# Exits 1 when any target found something; the reproducer is in build/fuzz/crashes/<target>/
# (run it with build/fuzz/fuzz/fuzz_<target> <file>). New corpus entries accumulate in
# build/fuzz/corpus/<target>/; the committed seeds in fuzz/corpus/<target>/ are only read.
# Logs: build/fuzz/logs/<target>.log. Needs clang, libclang-rt-14-dev (libFuzzer + sanitizer
# runtimes) and the project's packages (tools/setup.sh).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build/fuzz"
ALL_TARGETS=(obj ply gltf scene face_setup hair tfx usda obj_strands png exr)

seconds=""
runs=""
build_only=0
no_build=0
keep_going=0
jobs=2
timeout_s=10
rss_mb=2048
targets=()
usage() { sed -n '2,18p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --build-only) build_only=1; shift ;;
    --no-build) no_build=1; shift ;;
    --keep-going) keep_going=1; shift ;;
    -j) jobs="$2"; shift 2 ;;
    --timeout) timeout_s="$2"; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[[ -z "$seconds" && -z "$runs" ]] && seconds=60
[[ ${#targets[@]} -eq 0 ]] && targets=("${ALL_TARGETS[@]}")
for t in "${targets[@]}"; do
  if [[ ! " ${ALL_TARGETS[*]} " == *" $t "* ]]; then
    echo "fuzz.sh: unknown target '$t' (known: ${ALL_TARGETS[*]})" >&2
    exit 2
  fi
done

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
t0=$(date +%s)
if [[ $no_build -eq 1 ]]; then
  :
elif [[ ! -f "$BUILD/build.ninja" ]]; then
  # -O1 -g with assertions on; -Werror off: clang warns where the g++ builds are clean.
  CC=clang CXX=clang++ cmake -S "$ROOT" -B "$BUILD" -G Ninja \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DFOLLICLE_BUILD_FUZZ=ON -DFOLLICLE_WERROR=OFF -DFOLLICLE_SANITIZE=OFF \
    -DFOLLICLE_BUILD_TESTS=OFF -DFOLLICLE_BUILD_BENCH=OFF -DFOLLICLE_BUILD_VIEWER=OFF \
    -DFOLLICLE_BUILD_PYTHON=OFF "${launcher[@]}" >/dev/null
fi
if [[ $no_build -eq 0 ]]; then
  cmake --build "$BUILD" -j "$jobs" --target "${targets[@]/#/fuzz_}"
  echo "fuzz.sh: configure + build took $(($(date +%s) - t0)) s"
fi
[[ $build_only -eq 1 ]] && exit 0

export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=0:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
mkdir -p "$BUILD/logs"
status=0
printf '%-12s %12s %9s %7s %16s %8s\n' target executions exec/s cov corpus findings
for t in "${targets[@]}"; do
  work="$BUILD/corpus/$t"
  crashes="$BUILD/crashes/$t"
  log="$BUILD/logs/$t.log"
  mkdir -p "$work" "$crashes"
  args=(-artifact_prefix="$crashes/" -print_final_stats=1 -timeout="$timeout_s"
        -rss_limit_mb="$rss_mb")
  [[ -n "$seconds" ]] && args+=(-max_total_time="$seconds")
  [[ -n "$runs" ]] && args+=(-runs="$runs")
  # Fork mode runs the target in a child process and goes on after a crash, timeout or OOM
  # (each is saved); the numbers are then libFuzzer's fork-mode totals.
  [[ $keep_going -eq 1 ]] && args+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  [[ -f "$ROOT/fuzz/dict/$t.dict" ]] && args+=(-dict="$ROOT/fuzz/dict/$t.dict")
  seeds=()
  [[ -d "$ROOT/fuzz/corpus/$t" ]] && seeds+=("$ROOT/fuzz/corpus/$t")
  before=$(find "$crashes" -type f \( -name "crash-*" -o -name "timeout-*" -o -name "oom-*" -o -name "leak-*" \) | wc -l)
  s0=$(date +%s)
  rc=0
  (cd "$BUILD" && "$BUILD/fuzz/fuzz_$t" "${args[@]}" "$work" "${seeds[@]}") >"$log" 2>&1 || rc=$?
  s1=$(date +%s)
  after=$(find "$crashes" -type f \( -name "crash-*" -o -name "timeout-*" -o -name "oom-*" -o -name "leak-*" \) | wc -l)
  found=$((after - before))
  [[ $rc -ne 0 && $found -eq 0 ]] && found="rc=$rc"
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)
  [[ -z "$execs" ]] && execs=$(sed -n 's/^#\([0-9]*\).*/\1/p' <<<"$last")
  [[ -z "$rate" ]] && rate=$(sed -n 's/.* exec\/s:\{0,1\} \([0-9]*\).*/\1/p' <<<"$last")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\(\/[0-9a-zA-Z]*\)\{0,1\}\).*/\1/p' <<<"$last")
  printf '%-12s %12s %9s %7s %16s %8s  (%ss)\n' "$t" "${execs:-?}" "${rate:-?}" "${cov:-?}" \
    "${corp:-?}" "$found" "$((s1 - s0))"
  if [[ "$found" != 0 ]]; then
    status=1
    grep -E '^==[0-9]+==ERROR|runtime error|SUMMARY|uncaught exception|ALARM|out-of-memory|deadly signal' \
      "$log" | head -5 | sed 's/^/    /'
    ls -t "$crashes" | grep -v "^slow-unit-" | head -"$((after - before > 0 ? after - before : 1))" | sed "s|^|    reproducer: $crashes/|"
  fi
done
exit $status
