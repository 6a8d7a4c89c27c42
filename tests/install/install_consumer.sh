#!/usr/bin/env bash
# Installs a Follicle build into a temporary prefix, builds examples/ against it with
# find_package(Follicle CONFIG REQUIRED) (Ninja, CMAKE_PREFIX_PATH = the prefix only), runs the
# example on a mesh and a scene, and checks what it prints. Registered by cmake/install.cmake.
#
#   install_consumer.sh --build-dir=B --source-dir=S --mesh=MESH.obj
#                       [--cmake=CMAKE] [--config=C] [--cxx=CXX] [--launcher=L] [--ninja=NINJA]
#
# The temporary folder (B/install-test.XXXXXX) is removed on exit; --keep keeps it.
set -euo pipefail

cmake=cmake build_dir="" source_dir="" config="" cxx="" launcher="" ninja="" mesh="" keep=0
for arg in "$@"; do
  case "$arg" in
    --cmake=*) cmake=${arg#*=} ;;
    --build-dir=*) build_dir=${arg#*=} ;;
    --source-dir=*) source_dir=${arg#*=} ;;
    --config=*) config=${arg#*=} ;;
    --cxx=*) cxx=${arg#*=} ;;
    --launcher=*) launcher=${arg#*=} ;;
    --ninja=*) ninja=${arg#*=} ;;
    --mesh=*) mesh=${arg#*=} ;;
    --keep) keep=1 ;;
    *) echo "install_consumer: unknown argument '$arg'" >&2; exit 2 ;;
  esac
done

fail() {
  echo "install_consumer: FAIL: $*" >&2
  exit 1
}
if [ -z "$build_dir" ] || [ -z "$source_dir" ] || [ -z "$mesh" ]; then
  echo "usage: $0 --build-dir=B --source-dir=S --mesh=MESH.obj [options]" >&2
  exit 2
fi
[ -f "$build_dir/CMakeCache.txt" ] || fail "$build_dir is not a configured CMake build"
[ -f "$source_dir/examples/CMakeLists.txt" ] || fail "no examples/CMakeLists.txt in $source_dir"
[ -f "$mesh" ] || fail "mesh $mesh does not exist"

tmp=$(mktemp -d "$build_dir/install-test.XXXXXX")
cleanup() {
  if [ "$keep" = 1 ]; then echo "install_consumer: kept $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT
prefix=$tmp/prefix
log=$tmp/log.txt

# Runs a step quietly; on failure prints its output and what failed.
step() {
  local what=$1
  shift
  echo "install_consumer: $what"
  if ! "$@" >"$log" 2>&1; then
    cat "$log" >&2
    fail "$what failed: $*"
  fi
}

# 1. Install. Missing files mean the build is not complete (build everything first).
install_args=(--install "$build_dir" --prefix "$prefix")
[ -n "$config" ] && install_args+=(--config "$config")
echo "install_consumer: cmake --install into $prefix"
if ! "$cmake" "${install_args[@]}" >"$log" 2>&1; then
  cat "$log" >&2
  fail "cmake ${install_args[*]} failed (is every target built? cmake --build $build_dir)"
fi

[ -f "$prefix/include/follicle/core/context.hpp" ] ||
  fail "headers not installed as include/follicle/<module>/*.hpp"
config_file=$(find "$prefix" -path '*/cmake/Follicle/FollicleConfig.cmake' | head -n 1)
[ -n "$config_file" ] || fail "no lib*/cmake/Follicle/FollicleConfig.cmake under $prefix"
[ -x "$prefix/bin/follicle" ] || fail "the follicle CLI was not installed into bin/"
if find "$prefix" -type f \( -name 'test_*' -o -name 'follicle_bench' \) ! -name '*.hpp' | grep -q .; then
  fail "test or bench programs were installed"
fi
# Every #include "follicle/..." of an installed header is installed too.
missing=$(cd "$prefix/include" &&
  grep -rhoE '#include [<"]follicle/[^">]+[">]' follicle | sed -E 's/#include [<"]//; s/[">]$//' |
  sort -u | while read -r h; do [ -f "$h" ] || echo "$h"; done)
[ -z "$missing" ] || fail "installed headers include files that were not installed: $missing"
# No path into the source or build tree may leak into the package.
if grep -rqF -e "$source_dir/src" -e "$build_dir" "$(dirname "$config_file")"; then
  fail "the installed CMake package refers to the source or build tree"
fi

# 2. Configure and build examples/ against the prefix only.
cfg=(-S "$source_dir/examples" -B "$tmp/build" -G Ninja
  -DCMAKE_PREFIX_PATH="$prefix"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
[ -n "$config" ] && cfg+=(-DCMAKE_BUILD_TYPE="$config")
[ -n "$cxx" ] && cfg+=(-DCMAKE_CXX_COMPILER="$cxx")
[ -n "$launcher" ] && cfg+=(-DCMAKE_CXX_COMPILER_LAUNCHER="$launcher")
[ -n "$ninja" ] && cfg+=(-DCMAKE_MAKE_PROGRAM="$ninja")
step "configure examples/ with -DCMAKE_PREFIX_PATH=$prefix" "$cmake" "${cfg[@]}"
if ! grep -E '^-- Follicle [0-9.]+: ' "$log" | grep -qF ": $prefix/"; then
  cat "$log" >&2
  fail "find_package(Follicle) did not pick the package from $prefix"
fi
step "build examples/" "$cmake" --build "$tmp/build"
exe=$tmp/build/load_and_describe
[ -x "$exe" ] || fail "examples/ built no load_and_describe"

# 3. Run it on the mesh; expected values come from the OBJ itself (v lines, fan-triangulated f).
echo "install_consumer: load_and_describe $mesh"
out=$("$exe" "$mesh" --units m 2>&1) || { echo "$out" >&2; fail "load_and_describe $mesh failed"; }
echo "$out"
expect=$(awk '
  /^v / { n++; for (i = 0; i < 3; i++) { x = $(i + 2) + 0
            if (n == 1 || x < lo[i]) lo[i] = x; if (n == 1 || x > hi[i]) hi[i] = x } }
  /^f / { t += NF - 3 }
  END { printf "%d %d %.9g %.9g %.9g %.9g %.9g %.9g\n", n, t, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2] }
' "$mesh")
got=$(echo "$out" | awk '
  /^vertices:/ { v = $2 } /^triangles:/ { t = $2 }
  /^bounds min:/ { a = $3 " " $4 " " $5 } /^bounds max:/ { b = $3 " " $4 " " $5 }
  END { print v, t, a, b }')
awk -v e="$expect" -v g="$got" 'BEGIN {
  ne = split(e, E, " "); ng = split(g, G, " ")
  if (ng != ne) exit 1
  if (E[1] != G[1] || E[2] != G[2]) exit 1
  for (i = 3; i <= ne; i++) { d = E[i] - G[i]; if (d < 0) d = -d; if (d > 1e-5 * (1 + (E[i] < 0 ? -E[i] : E[i]))) exit 1 }
}' || fail "load_and_describe printed 'vertices triangles min max' = '$got', the OBJ has '$expect'"

# 4. A scene: Session::load links and runs the whole library (scene, hair, render, ...).
scene=$source_dir/data/scenes/daldegan_fur.json
if [ -f "$scene" ]; then
  echo "install_consumer: load_and_describe $scene"
  out=$("$exe" "$scene" 2>&1) || { echo "$out" >&2; fail "load_and_describe $scene failed"; }
  echo "$out"
  echo "$out" | grep -q '^scene: ' || fail "load_and_describe $scene printed no scene summary"
fi
echo "install_consumer: PASS"
