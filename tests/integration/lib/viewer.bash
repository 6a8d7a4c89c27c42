# Shared preamble of the viewer integration tests, sourced after lib/common.bash as
#   source "$(dirname "$0")/lib/viewer.bash"
# Sets VIEWER (follicle-viewer next to the CLI's build folder), PNG (the PNG tool), the default
# tolerance line of viewer_scenes.tolerance in mean_max / frac_max; skips the test (exit 0)
# without xvfb-run or when the viewer is not built.
VIEWER="$(dirname "$FOLLICLE")/../viewer/follicle-viewer"
if ! command -v xvfb-run > /dev/null 2>&1; then
  echo "SKIP: xvfb-run not installed"; exit 0
fi
if [ ! -x "$VIEWER" ]; then
  echo "SKIP: follicle-viewer not built"; exit 0
fi
PNG="python3 $(dirname "$0")/lib/png_tools.py"
TOL="$(dirname "$0")/viewer_scenes.tolerance"
read -r _ mean_max frac_max <<< "$(grep '^\* ' "$TOL")"
