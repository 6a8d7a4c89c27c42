# Shared preamble of the CLI integration tests, sourced as
#   source "$(dirname "$0")/lib/common.bash" "$@"
# by tests/integration/*.sh, which CTest runs as `bash SCRIPT <follicle binary> <repo root>`.
# Sets FOLLICLE (absolute path of the binary), ROOT (the repository), TMP (a scratch folder
# removed on exit), the failure count `fails` and `fail MESSAGE...` (prints and counts).
set -u
FOLLICLE=$(realpath "$1")
ROOT=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
