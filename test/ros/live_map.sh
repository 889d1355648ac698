#!/bin/bash
# The FormationPlanner's live map through ROS (docs/mapping.md "Through ROS"): onboard.launch
# mapping:=true (the leader in one manager; LCM on memq://). A depth camera 4 m in front of a wall —
# a 32FC1 image of 4.0 m everywhere, its CameraInfo and the optical frame on tf — is integrated
# into the planner's map (/diagnostics: frames integrated, voxels of the planner's map changed, none
# refused once its CameraInfo came); a depth image with the wrong encoding is refused and counted, the planner still plans;
# a mapping_config with an unknown key and an out-of-range value refuses the start, naming both.
set -o pipefail
source "$(dirname "$0")/common.bash"
make_key "$T/keys"
MAP=$SRC/config/scenarios/power_towers.yaml
# A config with two problems: the planner must name both and not start.
sed -e 's/prob_hit: 0.7/prob_hit: 1.5/' -e 's/^field:/field:\n  typo_m: 1.0/' "$SRC/config/mapping.yaml" > "$T/bad_mapping.yaml"
roslaunch -p "$PORT" gesture_formation onboard.launch uav_index:=0 key_file:="$T/keys" lcm_url:=memq:// perception:=false \
  scenario_file:="$MAP" odometry_topic:=odom mapping:=true mapping_config:="$T/bad_mapping.yaml" > "$T/bad.log" 2>&1 & bad=$!
for _ in $(seq 100); do grep -q "FormationPlanner refuses to start" "$T/bad.log" && break; sleep 0.3; done
sleep 1
grep -A12 "FormationPlanner refuses to start" "$T/bad.log" | matches "octomap.prob_hit" \
  && grep -A12 "FormationPlanner refuses to start" "$T/bad.log" | matches "unknown key field.typo_m" \
  && echo "PASS: a bad mapping_config refuses the start, naming the out-of-range value and the unknown key" \
  || fail "bad mapping_config: $(grep -A8 'refuses' "$T/bad.log" | head -10)"
kill -INT $bad; wait $bad 2>/dev/null
roslaunch -p "$PORT" gesture_formation onboard.launch uav_index:=0 key_file:="$T/keys" lcm_url:=memq:// perception:=false \
  scenario_file:="$MAP" odometry_topic:=odom mapping:=true > "$T/launch.log" 2>&1 & pids+=($!)
for _ in $(seq 100); do rostopic list 2>/dev/null | matches "^/plan$" && break; sleep 0.3; done
rostopic pub -s -r 20 /odom nav_msgs/Odometry \
  "{header: {stamp: now, frame_id: world}, child_frame_id: world, pose: {pose: {position: {x: 10, y: 10, z: 4}, orientation: {w: 1.0}}}}" \
  > /dev/null 2>&1 & pids+=($!)
rostopic pub -s -r 20 /worker_state gesture_formation/WorkerState \
  "{header: {stamp: now, frame_id: world}, position: {x: 20, y: 10, z: 2}, covariance: [0.01,0,0,0,0,0, 0,0.01,0,0,0,0, 0,0,0.01,0,0,0, 0,0,0,0.01,0,0, 0,0,0,0,0.01,0, 0,0,0,0,0,0.01], source: uwb, accepted: true, last_fused: now}" \
  > /dev/null 2>&1 & pids+=($!)
cat > "$T/depth.py" <<'PY'
import sys, struct, rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import Image, CameraInfo
from tf2_msgs.msg import TFMessage
encoding = sys.argv[1]
rospy.init_node("fake_depth", anonymous=True)
img = rospy.Publisher("/camera/aligned_depth_to_color/image_raw", Image, queue_size=2)
info = rospy.Publisher("/camera/color/camera_info", CameraInfo, queue_size=2)
tf = rospy.Publisher("/tf", TFMessage, queue_size=10)
# The leader at (10, 10, 4), its depth camera looking east (+x): optical z east, x south, y down.
T = TransformStamped()
T.header.frame_id, T.child_frame_id = "world", "livemap_cam"
T.transform.translation.x, T.transform.translation.y, T.transform.translation.z = 10.0, 10.0, 4.0
T.transform.rotation.x, T.transform.rotation.y, T.transform.rotation.z, T.transform.rotation.w = -0.5, 0.5, -0.5, 0.5
w, h = 160, 120
rate = rospy.Rate(10)
first = True
while not rospy.is_shutdown():
    now = rospy.Time.now()
    m = Image(width=w, height=h, encoding=encoding, is_bigendian=0)
    m.header.stamp, m.header.frame_id = now, "livemap_cam"
    if encoding == "32FC1":
        m.step, m.data = 4 * w, struct.pack("<f", 4.0) * (w * h)   # a wall 4 m ahead everywhere
    else:
        m.step, m.data = 3 * w, bytes(3 * w * h)                   # rgb8: not a depth image
    c = CameraInfo(width=w, height=h, K=[100, 0, 80, 0, 100, 60, 0, 0, 1])
    c.header = m.header
    T.header.stamp = now
    info.publish(c)  # the CameraInfo and the pose before the image: a depth image before them is refused (counted)
    tf.publish(TFMessage(transforms=[T]))
    if first:  # for 1 s before the first image: the planner's subscriptions connect one by one (a first
        for _ in range(10):  # image stamped before the tf listener's earliest pose is refused: extrapolation)
            rospy.sleep(0.1)
            T.header.stamp = rospy.Time.now()
            info.publish(c)
            tf.publish(TFMessage(transforms=[T]))
        m.header.stamp = c.header.stamp = T.header.stamp
        first = False
    img.publish(m)
    rate.sleep()
PY
cat > "$T/diag.py" <<'PY'
import sys, time, rospy
from diagnostic_msgs.msg import DiagnosticArray
rospy.init_node("diag", anonymous=True)
seen = []
rospy.Subscriber("/diagnostics", DiagnosticArray, lambda a: seen.extend(s for s in a.status if "FormationPlanner" in s.name))
t0 = time.time()
while time.time() - t0 < float(sys.argv[1]):
    time.sleep(0.1)
for s in seen:
    v = {k.key: k.value for k in s.values}
    if "live_map_frames_per_s" in v:
        print(v["live_map_frames_per_s"], v["live_map_changes"], v["live_map_refused"], v.get("mode", ""), s.message.replace("\n", " "))
PY
# From before the first frame (the wall's voxels change the map once: with the first frames).
timeout 40 python3 "$T/diag.py" 16 > "$T/diag_wall.txt" & diag=$!
sleep 4
python3 "$T/depth.py" 32FC1 & depth=$!; pids+=($depth)
wait $diag
# Refused: only a first image that came before its CameraInfo reached the planner (subscriptions connect
# one by one), never the wall's frames themselves.
awk '$1 > 0 { f++ } $2 > 0 { c++ } $3 > 0 && !/no CameraInfo on depth_info_in yet/ { r++ } END { exit !(f >= 2 && c >= 1 && r == 0) }' "$T/diag_wall.txt" \
  && echo "PASS: the wall's depth frames are integrated: $(awk '{ f += $1 > 0; c += $2 } END { print f " reports with frames, " c " voxels of the planner map changed" }' "$T/diag_wall.txt"), none refused but before the CameraInfo" \
  || fail "no live-map integration of the wall: $(tr "\n" "|" < "$T/diag_wall.txt")"
# rviz's view of it: the live map's voxels around the camera on live_map_markers (a latched cube
# list); the wall, 4 m east of the camera, is there in the colour of what the prior map lacks.
cat > "$T/markers.py" <<'PY'
import rospy
from visualization_msgs.msg import Marker
rospy.init_node("markers", anonymous=True)
m = rospy.wait_for_message("/live_map_markers", Marker, timeout=15)
wall = [i for i, p in enumerate(m.points) if abs(p.x - 14.0) < 0.5 and abs(p.y - 10.0) < 3.0 and abs(p.z - 4.0) < 3.0]
new = [i for i in wall if m.colors[i].r > 0.8 and m.colors[i].b < 0.3]
print(m.type, len(m.points), len(wall), len(new), m.header.frame_id)
PY
read -r mtype mpoints mwall mnew mframe < <(timeout 30 python3 "$T/markers.py" 2>/dev/null || echo "- 0 0 0 -")
[ "$mtype" = 6 ] && [ "$mwall" -gt 100 ] && [ "$mnew" -eq "$mwall" ] \
  && echo "PASS: live_map_markers: a cube list in $mframe of $mpoints voxels, $mwall of them the wall's, all in the colour of what the prior map lacks" \
  || fail "live_map_markers: type $mtype, $mpoints voxels, $mwall on the wall, $mnew of them new"
kill "$depth" 2>/dev/null; wait "$depth" 2>/dev/null
python3 "$T/depth.py" rgb8 & pids+=($!)
sleep 2
timeout 30 python3 "$T/diag.py" 8 > "$T/diag_bad.txt"
awk '$3 > 0 { r++ } END { exit !(r >= 1) }' "$T/diag_bad.txt" && matches "encoding" "$T/diag_bad.txt" \
  && echo "PASS: an rgb8 image on depth_in is refused and counted ($(grep -m1 -o "depth frame.*" "$T/diag_bad.txt" | head -c 120))" \
  || fail "rgb8 depth not refused: $(head -3 "$T/diag_bad.txt")"
rate=$(timeout 12 rostopic hz -w 10 /plan 2>/dev/null | grep -m2 "average rate" | tail -1 | awk '{print $3}')
awk -v r="$rate" 'BEGIN { exit !(r > 2.0 && r < 3.0) }' && echo "PASS: the planner plans at $rate Hz on the live map (2.5 expected)" || fail "/plan rate '$rate' on the live map (2.5 expected)"
grep -q "FormationPlanner refuses to start" "$T/launch.log" && fail "the planner refused to start: $(grep -A5 'refuses' "$T/launch.log" | head -6)"
[ $fails -eq 0 ] || { echo "--- launch.log"; tail -30 "$T/launch.log"; echo "--- diagnostics"; cat "$T"/diag_*.txt; }
exit $fails
