#!/usr/bin/env bash
# Creates the model-conversion venv (default /opt/gesture_formation/venv-models) with
# Debian's /usr/bin/python3 and installs the pinned packages of requirements.txt.
# Idempotent: a second run only checks. Touches no other venv.
#
#   tools/models/setup_env.sh            # create / check the venv
#   GF_MODELS_VENV=/path tools/models/setup_env.sh
#
# Also installs (apt) what the checks need: python3-venv, python3-opencv (OpenCV 4.6 DNN,
# the runtime the product uses), opencv-doc (test images), npm (to fetch npm packages).
set -eo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="${GF_MODELS_VENV:-/opt/gesture_formation/venv-models}"
PY=/usr/bin/python3

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

wait_apt_lock() {
  # apt may be busy (another engineer's install); wait up to 15 min for the locks.
  local i=0
  while fuser /var/lib/dpkg/lock-frontend /var/lib/dpkg/lock /var/lib/apt/lists/lock >/dev/null 2>&1; do
    [ $i -eq 0 ] && echo "setup_env: waiting for the apt/dpkg lock..." >&2
    i=$((i + 1)); [ $i -gt 180 ] && { echo "setup_env: apt lock still held after 15 min" >&2; exit 1; }
    sleep 5
  done
}

need_pkgs=()
for p in python3-venv python3-opencv opencv-doc psmisc; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need_pkgs+=("$p")
done
# npm: any working npm will do (Debian's package conflicts with a nodejs from elsewhere)
command -v npm >/dev/null || need_pkgs+=(npm)
if [ ${#need_pkgs[@]} -gt 0 ]; then
  echo "setup_env: apt-get install ${need_pkgs[*]}" >&2
  command -v fuser >/dev/null && wait_apt_lock
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${need_pkgs[@]}" \
    || { command -v fuser >/dev/null && wait_apt_lock; $SUDO apt-get update && \
         $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${need_pkgs[@]}"; }
fi

if [ ! -x "$VENV/bin/python" ]; then
  $SUDO mkdir -p "$(dirname "$VENV")"
  $SUDO "$PY" -m venv "$VENV"
fi
# the venv must be made from Debian's python (not pyenv's)
grep -q "^home = /usr/bin" "$VENV/pyvenv.cfg" || { echo "setup_env: $VENV was not created from /usr/bin/python3" >&2; exit 1; }

if ! "$VENV/bin/python" - "$HERE/requirements.txt" <<'PYEOF' 2>/dev/null
import sys
from importlib.metadata import version
for line in open(sys.argv[1]):
    line = line.split("#")[0].strip()
    if not line:
        continue
    name, want = line.split("==")
    if version(name) != want:
        sys.exit(1)
PYEOF
then
  $SUDO "$VENV/bin/python" -m pip install --disable-pip-version-check -q -r "$HERE/requirements.txt"
fi
"$VENV/bin/python" -c "import tensorflow, tf2onnx, onnx, tflite, numpy; print('setup_env: ok', '$VENV', 'tf', tensorflow.__version__, 'tf2onnx', tf2onnx.__version__, 'onnx', onnx.__version__, 'numpy', numpy.__version__)"
