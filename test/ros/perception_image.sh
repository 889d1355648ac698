#!/bin/bash
# The Perception nodelet on a real image: test/data/perception/astronaut.png published by a tiny
# camera (test/ros/perception_check.py: bgr8 image + aligned 32FC1 depth + CameraInfo, 10 Hz)
# gives WorkerDetection messages with the worker found and the stereo range along the box-centre
# ray, and a Gesture once the skeleton FIFO is full; then the same with the image as a PNG in a
# sensor_msgs/CompressedImage (image_transport:=compressed); bad parameters refuse to start, each named.
set -o pipefail
source "$(dirname "$0")/common.bash"
start_master
MODELS=$SRC/third_party_models
timeout 60 rosrun nodelet nodelet standalone gesture_formation/Perception __name:=perception \
  _models_root:="$MODELS" _gesture_model:="$MODELS/gesture_lstm/gesture_lstm.onnx" \
  _detector:=movenet_multipose _skeleton:=movenet_lightning _detect_every_k:=5 _appearance:=true \
  _min_depth_m:=0.2 _max_depth_m:=20.0 _depth_scale_m:=0.001 _max_depth_dt_s:=0.05 \
  image_in:=/cam/image depth_in:=/cam/depth camera_info_in:=/cam/camera_info \
  detection_out:=/perception/worker_detection gesture_out:=/perception/gesture candidates_out:=/perception/candidates > "$T/perception.log" 2>&1 & pids+=($!)
timeout 8 rosrun nodelet nodelet standalone gesture_formation/Perception __name:=perception_bad \
  _models_root:="$T/no_models" _gesture_model:="$MODELS/gesture_lstm/gesture_lstm.onnx" _detector:=yolo \
  _skeleton:=movenet_lightning _detect_every_k:=0 _min_depth_m:=0.2 _max_depth_m:=20.0 _depth_scale_m:=0.001 _image_transport:=theora \
  detection_out:=/perception_bad/worker_detection > "$T/perception_bad.log" 2>&1 & bad=$!
for _ in $(seq 100); do rostopic list 2>/dev/null | matches "^/perception/worker_detection$" && break; sleep 0.3; done
timeout 70 python3 "$SRC/test/ros/perception_check.py" "$SRC/test/data/perception/astronaut.png" || fails=$((fails + $?))
# The same camera compressed: image_transport's `compressed` topic (decoded by the nodelet when the
# compressed_image_transport plugin is not installed, as on Debian).
kill -INT "${pids[-1]}" 2>/dev/null; wait "${pids[-1]}" 2>/dev/null
timeout 60 rosrun nodelet nodelet standalone gesture_formation/Perception __name:=perception \
  _models_root:="$MODELS" _gesture_model:="$MODELS/gesture_lstm/gesture_lstm.onnx" \
  _detector:=movenet_multipose _skeleton:=movenet_lightning _detect_every_k:=5 _appearance:=true \
  _min_depth_m:=0.2 _max_depth_m:=20.0 _depth_scale_m:=0.001 _max_depth_dt_s:=0.05 _image_transport:=compressed \
  image_in:=/cam/image depth_in:=/cam/depth camera_info_in:=/cam/camera_info \
  detection_out:=/perception/worker_detection gesture_out:=/perception/gesture candidates_out:=/perception/candidates > "$T/perception_compressed.log" 2>&1 & pids+=($!)
for _ in $(seq 100); do rostopic info /cam/image/compressed 2>/dev/null | matches "/perception" && break; sleep 0.3; done
timeout 70 python3 "$SRC/test/ros/perception_check.py" "$SRC/test/data/perception/astronaut.png" --compressed || fails=$((fails + $?))
grep -q "refuses to start" "$T/perception_compressed.log" && fail "Perception (compressed) refused to start: $(grep -A5 refuses "$T/perception_compressed.log")"
rostopic list 2>/dev/null | matches "^/perception_bad/" && fail "Perception advertised its output although it refused to start"
wait $bad
for pattern in "refuses to start" "detector: " "detect_every_k: value 0 out of range" "max_depth_dt_s: missing" "appearance: missing" \
  "image_transport 'theora': no such image_transport plugin installed"; do
  grep -q -- "$pattern" "$T/perception_bad.log" || fail "perception_bad: '$pattern' not reported"
done
grep -q "refuses to start" "$T/perception.log" && fail "Perception refused to start: $(grep -A5 refuses "$T/perception.log")"
[ $fails -eq 0 ] && echo "PASS: the Perception nodelet turns an image into a detection, a stereo range and a gesture" \
  || { echo "--- perception.log"; tail -20 "$T/perception.log"; echo "--- perception_bad.log"; tail -10 "$T/perception_bad.log"; }
exit $fails
