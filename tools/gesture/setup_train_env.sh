#!/usr/bin/env bash
# Creates the training venv for the gesture LSTM (never needed by CI or the build):
# /opt/gesture_formation/venv-train with PyTorch from PyPI (the CUDA build — PyPI has no
# CPU-only wheel; it runs on the CPU, ~5 GB), onnx, numpy and pyyaml (the error-model file). Idempotent.
set -eo pipefail
VENV=${GF_TRAIN_VENV:-/opt/gesture_formation/venv-train}
REQS="torch==2.5.1 onnx==1.16.2 numpy==1.26.4 matplotlib==3.8.4 pyyaml==6.0.2"
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
if [ -f "$VENV/.gf_requirements" ] && [ "$(cat "$VENV/.gf_requirements")" = "$REQS" ]; then
  echo "train env up to date ($VENV)"; exit 0
fi
$SUDO mkdir -p "$(dirname "$VENV")"
$SUDO /usr/bin/python3 -m venv "$VENV"
$SUDO "$VENV/bin/pip" install -q --disable-pip-version-check $REQS
echo "$REQS" | $SUDO tee "$VENV/.gf_requirements" > /dev/null
echo "train env ready ($VENV)"
