#!/bin/bash
# The WorkerEstimator nodelet end to end under a private ROS master: it refuses to start
# (listing every missing parameter) without parameters, and with the shipped config turns
# WorkerDetections (three confirm the track) + a static camera tf into a WorkerState at the
# expected position.
set -o pipefail  # not -u: devel/setup.bash reads unset variables
GFCTL=$1
SRC=$2
BUILD=$(cd "$(dirname "$GFCTL")/../../.." && pwd)
T=$(mktemp -d)
PORT=$((11400 + RANDOM % 500))
export ROS_MASTER_URI=http://127.0.0.1:$PORT ROS_IP=127.0.0.1 ROS_HOME=$T/ros ROS_LOG_DIR=$T/log
export PATH=/usr/bin:/bin:$PATH
# shellcheck disable=SC1091
source "$BUILD/devel/setup.bash"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; rm -rf "$T"; }
trap cleanup EXIT
roscore -p "$PORT" > "$T/roscore.log" 2>&1 & pids+=($!)
for _ in $(seq 50); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done

# 1. No parameters: refuses to start, every missing one listed, no output topic advertised.
#    An unknown intrinsics_source is named beside them.
timeout 6 rosrun nodelet nodelet standalone gesture_formation/WorkerEstimator __name:=est_bad _intrinsics_source:=yaml > "$T/bad.log" 2>&1
fails=0
for p in config_file world_frame uwb_max_age_s tf_timeout_s publish_rate_hz; do
  grep -q "est_bad/$p: missing" "$T/bad.log" || { echo "FAIL: missing parameter $p not reported"; fails=$((fails+1)); }
done
grep -q "intrinsics_source: 'yaml': expected camera_info or config" "$T/bad.log" || { echo "FAIL: bad intrinsics_source not named"; fails=$((fails+1)); }
grep -q "refuses to start" "$T/bad.log" || { echo "FAIL: no refusal message"; cat "$T/bad.log"; fails=$((fails+1)); }

# 2. With the shipped config's camera (intrinsics_source config, the explicit override): camera at
#    (0,0,2) looking along +x (optical z → world x), a box centred on the principal point with a
#    stereo range of 10 m → worker at (10, 0, 2).
# (Debian ships no static_transform_publisher binary; python3-tf2-ros has the broadcaster.)
python3 - > "$T/tf.log" 2>&1 <<'PY' & pids+=($!)
import rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
rospy.init_node("static_cam_tf")
t = TransformStamped()
t.header.stamp = rospy.Time.now()
t.header.frame_id, t.child_frame_id = "world", "cam_optical"
t.transform.translation.z = 2.0
t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = -0.5, 0.5, -0.5, 0.5
tf2_ros.StaticTransformBroadcaster().sendTransform(t)
rospy.spin()
PY
rosrun nodelet nodelet standalone gesture_formation/WorkerEstimator __name:=est \
  _config_file:="$SRC/config/estimator.yaml" _world_frame:=world _uwb_max_age_s:=0.2 _tf_timeout_s:=0.5 \
  _publish_rate_hz:=5.0 _intrinsics_source:=config detection_in:=det worker_state_out:=state > "$T/est.log" 2>&1 & pids+=($!)
sleep 2
timeout 25 rostopic echo -n 1 /state > "$T/state.txt" 2>&1 & echo_pid=$!
sleep 1
# The estimator publishes a track once confirm_measurements (3) detections were accepted
# (docs/estimation.md); five, in case one is lost while a publisher connects.
for i in 1 2 3 4 5; do
  rostopic pub -1 /det gesture_formation/WorkerDetection \
    "{header: {stamp: now, frame_id: cam_optical}, detected: true, u: 300, v: 190, w: 40, h: 100, confidence: 0.9, stereo_distance_m: 10.0}" > /dev/null 2>&1
done
wait $echo_pid
python3 - "$T/state.txt" <<'PY' || fails=$((fails+1))
import sys, yaml
docs = [d for d in yaml.safe_load_all(open(sys.argv[1]).read().replace("---", "\n---\n")) if d]
if not docs:
    print("FAIL: no WorkerState received"); sys.exit(1)
s = docs[0]
p = s["position"]
err = ((p["x"] - 10) ** 2 + p["y"] ** 2 + (p["z"] - 2) ** 2) ** 0.5
print(f"WorkerState: position ({p['x']:.3f}, {p['y']:.3f}, {p['z']:.3f}) source {s['source']} frame {s['header']['frame_id']}")
ok = err < 1e-6 and s["header"]["frame_id"] == "world" and s["source"] == "stereo"
if not ok:
    print("FAIL: unexpected state"); sys.exit(1)
PY

# 3. The default: the camera model from CameraInfo. Without one every detection is refused (no
#    state); then a CameraInfo whose principal point is 100 px left of the box centre (cx 220):
#    the worker lies on that pixel's ray, 10 m along it — not where the YAML's camera would put it.
rosrun nodelet nodelet standalone gesture_formation/WorkerEstimator __name:=est_info \
  _config_file:="$SRC/config/estimator.yaml" _world_frame:=world _uwb_max_age_s:=0.2 _tf_timeout_s:=0.5 \
  _publish_rate_hz:=5.0 detection_in:=det_info camera_info_in:=info worker_state_out:=state_info > "$T/est_info.log" 2>&1 & pids+=($!)
sleep 2
det_info() {
  for i in 1 2 3 4 5; do
    rostopic pub -1 /det_info gesture_formation/WorkerDetection \
      "{header: {stamp: now, frame_id: cam_optical}, detected: true, u: 300, v: 190, w: 40, h: 100, confidence: 0.9, stereo_distance_m: 10.0}" > /dev/null 2>&1
  done
}
timeout 8 rostopic echo -n 1 /state_info > "$T/state_none.txt" 2>&1 & echo_pid=$!
sleep 1
det_info
wait $echo_pid
if grep -q "position" "$T/state_none.txt"; then echo "FAIL: a state without any CameraInfo"; fails=$((fails+1)); fi
grep -q "detection refused: no camera intrinsics received yet" "$T/est_info.log" || { echo "FAIL: refusal without CameraInfo not logged"; fails=$((fails+1)); }
rostopic pub -l /info sensor_msgs/CameraInfo \
  "{header: {frame_id: cam_optical}, width: 640, height: 480, distortion_model: plumb_bob, D: [0, 0, 0, 0, 0], K: [615, 0, 220, 0, 615, 240, 0, 0, 1]}" > /dev/null 2>&1 & pids+=($!)
sleep 2
timeout 25 rostopic echo -n 1 /state_info > "$T/state_info.txt" 2>&1 & echo_pid=$!
sleep 1
det_info
wait $echo_pid
python3 - "$T/state_info.txt" <<'PY' || fails=$((fails+1))
import math, sys, yaml
docs = [d for d in yaml.safe_load_all(open(sys.argv[1]).read().replace("---", "\n---\n")) if d]
if not docs:
    print("FAIL: no WorkerState received after the CameraInfo"); sys.exit(1)
p = docs[0]["position"]
# Box centre (320, 240), principal point (220, 240): optical ray (100/615, 0, 1); optical x → world −y.
x_n = 100.0 / 615.0
expected = (10.0 / math.hypot(1.0, x_n), -10.0 * x_n / math.hypot(1.0, x_n), 2.0)
err = math.dist((p["x"], p["y"], p["z"]), expected)
print(f"WorkerState with CameraInfo: ({p['x']:.4f}, {p['y']:.4f}, {p['z']:.4f}), expected ({expected[0]:.4f}, {expected[1]:.4f}, 2)")
if err > 1e-6:
    print("FAIL: the estimate does not use the CameraInfo's intrinsics"); sys.exit(1)
PY
[ $fails -eq 0 ] || { echo "--- est.log"; cat "$T/est.log"; echo "--- est_info.log"; cat "$T/est_info.log"; }
exit $fails
