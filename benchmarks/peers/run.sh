#!/usr/bin/env bash
# pfaff beside its peers: installs SciPy, NumPy and CasADi into benchmarks/peers/.venv
# (pip, versions pinned in requirements.txt), builds the release `pfaff`, and runs
# peers.py with the arguments given (see README.md). Needs python3 (with venv), gcc and
# cargo. Not part of CI: a full run takes several minutes.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [ ! -x "$here/.venv/bin/python" ]; then
  "${PYTHON:-python3}" -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
(cd "$root" && cargo build --release -p pfaff-models --bin pfaff)
cd "$here"
exec "$here/.venv/bin/python" peers.py --pfaff "$root/target/release/pfaff" "$@"
