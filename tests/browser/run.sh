#!/usr/bin/env bash
# The HTML view in a real browser (not part of `cargo test`): builds `pfaff`, writes the
# animation of slider_crank_bodies, bicycle and bouncing_ball (those in the registry;
# the others are skipped with a note), opens each in headless Chromium at two times,
# takes screenshots, checks that the drawing changes and that no script error is
# logged, and that a run of 1e5 output steps gives a file under 20 MB that opens in
# under 2 s. `--docs` also copies the first screenshot of slider_crank_bodies and
# bicycle to docs/screenshot-MODEL.png (the README's pictures).
# Needs Debian's chromium: apt-get install -y chromium
set -euo pipefail
cd "$(dirname "$0")/../.."
chromium="${CHROMIUM:-$(command -v chromium || command -v chromium-browser || true)}"
if [ -z "$chromium" ]; then
  echo "browser test: no chromium found; install Debian's: apt-get install -y chromium" >&2
  exit 1
fi
docs=()
if [ "${1:-}" = "--docs" ]; then docs=(--docs docs); fi
cargo build --release -p pfaff-models --bin pfaff
python3 tests/browser/check.py --pfaff target/release/pfaff --chromium "$chromium" \
  --out target/browser "${docs[@]}"
