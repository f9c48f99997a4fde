#!/usr/bin/env bash
# pfaff beside its peers: installs SciPy, NumPy and CasADi into benchmarks/peers/.venv
# (pip, versions pinned in requirements.txt), unpacks SUNDIALS' headers and static
# libraries from Debian's libsundials-dev into build/sundials (apt-get download and
# dpkg -x: no root, nothing installed system-wide) for the compiled peer (sundials.c),
# builds the release `pfaff`, and runs peers.py with the arguments given (see
# README.md). Needs python3 (with venv), gcc, cargo, and apt-get/dpkg for the compiled
# peer (without them it is left out). Not part of CI: a full run takes several minutes.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [ ! -x "$here/.venv/bin/python" ]; then
  "${PYTHON:-python3}" -m venv "$here/.venv"
fi
"$here/.venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
sundials="$here/build/sundials"
if [ ! -f "$sundials/usr/include/cvodes/cvodes.h" ]; then
  mkdir -p "$sundials/debs"
  if (cd "$sundials/debs" && apt-get download libsundials-dev >/dev/null); then
    dpkg -x "$sundials"/debs/libsundials-dev_*.deb "$sundials"
  else
    echo "run.sh: could not fetch Debian's libsundials-dev: the compiled peer is left out" >&2
  fi
fi
extra=()
if [ -f "$sundials/usr/include/cvodes/cvodes.h" ]; then
  extra=(--sundials "$sundials/usr")
fi
(cd "$root" && cargo build --release -p pfaff-models --bin pfaff)
cd "$here"
exec "$here/.venv/bin/python" peers.py --pfaff "$root/target/release/pfaff" "${extra[@]}" "$@"
