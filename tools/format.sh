#!/usr/bin/env bash
# Formats (or with --check, verifies) every C++ file of ours with the repository's .clang-format.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=(-i)
if [ "${1:-}" = "--check" ]; then mode=(--dry-run -Werror); fi
git ls-files '*.cpp' '*.hpp' | xargs -r clang-format "${mode[@]}"
