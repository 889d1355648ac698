#!/bin/bash
# Map changes shared between two UAVs through ROS and LCM (docs/mapping.md §8 "Through ROS"): two
# onboard.launch (UAV 0 and 1, namespaces uav0 / uav1, mapping:=true with share.enabled, LCM udpm in a
# private network namespace). Only UAV 0 has a depth camera, 4 m in front of a wall; its planner
# publishes its changes, the bridges carry them, UAV 1's planner merges them: UAV 1's map changes
# without a camera, and every voxel UAV 0 had sent 3 s before the end (its wall, resent every update) is
# merged by UAV 1 by the end, nothing it did not send (/diagnostics live_map_*). A map
# update that claims UAV 0's index but comes from UAV 1's bridge is refused by UAV 0's bridge.
set -o pipefail
source "$(dirname "$0")/common.bash"
need_netns
make_key "$T/keys"
sed -e 's/^\(share:.*\)$/share:/' -e '/^share:/,/^[a-z]/ s/enabled: false/enabled: true/' "$SRC/config/mapping.yaml" > "$T/mapping_share.yaml"
matches -A1 "^share:" "$T/mapping_share.yaml" && grep -A1 "^share:" "$T/mapping_share.yaml" | matches "enabled: true" \
  || { echo "FAIL: could not enable share in a copy of config/mapping.yaml"; exit 1; }
cat > "$T/two.launch" <<LAUNCH
<launch>
  <group ns="uav0"><include file="$SRC/launch/onboard.launch"><arg name="uav_index" value="0"/>
    <arg name="key_file" value="$T/keys"/> <arg name="lcm_url" value="udpm://239.255.76.67:7667?ttl=0"/> <arg name="perception" value="false"/>
    <arg name="scenario_file" value="$SRC/config/scenarios/power_towers.yaml"/> <arg name="odometry_topic" value="odom"/>
    <arg name="mapping" value="true"/> <arg name="mapping_config" value="$T/mapping_share.yaml"/></include></group>
  <group ns="uav1"><include file="$SRC/launch/onboard.launch"><arg name="uav_index" value="1"/>
    <arg name="key_file" value="$T/keys"/> <arg name="lcm_url" value="udpm://239.255.76.67:7667?ttl=0"/> <arg name="perception" value="false"/>
    <arg name="scenario_file" value="$SRC/config/scenarios/power_towers.yaml"/> <arg name="odometry_topic" value="odom"/>
    <arg name="mapping" value="true"/> <arg name="mapping_config" value="$T/mapping_share.yaml"/></include></group>
</launch>
LAUNCH
cat > "$T/depth.py" <<'PY'
import struct, rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import Image, CameraInfo
from tf2_msgs.msg import TFMessage
rospy.init_node("fake_depth", anonymous=True)
img = rospy.Publisher("/uav0/camera/aligned_depth_to_color/image_raw", Image, queue_size=2)
info = rospy.Publisher("/uav0/camera/color/camera_info", CameraInfo, queue_size=2)
tf = rospy.Publisher("/tf", TFMessage, queue_size=10)
# UAV 0 at (10, 10, 4), its depth camera looking east (+x): optical z east, x south, y down.
T = TransformStamped()
T.header.frame_id, T.child_frame_id = "world", "uav0_cam"
T.transform.translation.x, T.transform.translation.y, T.transform.translation.z = 10.0, 10.0, 4.0
T.transform.rotation.x, T.transform.rotation.y, T.transform.rotation.z, T.transform.rotation.w = -0.5, 0.5, -0.5, 0.5
w, h = 160, 120
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    now = rospy.Time.now()
    m = Image(width=w, height=h, encoding="32FC1", is_bigendian=0, step=4 * w, data=struct.pack("<f", 4.0) * (w * h))
    m.header.stamp, m.header.frame_id = now, "uav0_cam"
    c = CameraInfo(width=w, height=h, K=[100, 0, 80, 0, 100, 60, 0, 0, 1])
    c.header = m.header
    T.header.stamp = now
    info.publish(c)
    tf.publish(TFMessage(transforms=[T]))
    rospy.sleep(0.02)
    img.publish(m)
    rate.sleep()
PY
cat > "$T/diag.py" <<'PY'
import sys, time, rospy
from diagnostic_msgs.msg import DiagnosticArray
rospy.init_node("diag", anonymous=True)
keys = ["live_map_frames_per_s", "live_map_changes", "live_map_updates_sent", "live_map_voxels_sent",
        "live_map_updates_merged", "live_map_voxels_merged", "live_map_updates_refused"]
total = {u: {k: 0.0 for k in keys} for u in ("uav0", "uav1")}
history = {"uav0": [], "uav1": []}  # (wall time, voxels UAV 0 sent / UAV 1 merged so far)
def on(a):
    for s in a.status:
        for u in total:
            if s.name == "FormationPlanner " + u:
                v = {k.key: k.value for k in s.values}
                for k in keys:
                    total[u][k] += float(v.get(k, 0))
                history[u].append((time.time(), total[u]["live_map_voxels_sent" if u == "uav0" else "live_map_voxels_merged"]))
rospy.Subscriber("/diagnostics", DiagnosticArray, on)
t0 = time.time()
while time.time() - t0 < float(sys.argv[1]):
    time.sleep(0.1)
for u in total:
    print(u, " ".join("%s=%g" % (k, total[u][k]) for k in keys))
# The counts 3 s before the end (a report every second, two updates a second, the link's latency:
# 3 s covers what is in flight and what a report has not told yet).
for u, k in (("uav0", "live_map_voxels_sent"), ("uav1", "live_map_voxels_merged")):
    early = [s for t, s in history[u] if t <= time.time() - 3.0]
    print(u + "_early", "%s=%g" % (k, early[-1] if early else 0))
PY
cat > "$T/inner.sh" <<INNER
ip link set lo up && ip route add 224.0.0.0/4 dev lo || exit 1
roscore -p $PORT > "$T/roscore.log" 2>&1 &
for _ in \$(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
roslaunch -p $PORT "$T/two.launch" > "$T/launch.log" 2>&1 &
for _ in \$(seq 150); do rostopic list 2>/dev/null | grep -q "^/uav1/plan$" && rostopic list 2>/dev/null | grep -q "^/uav0/plan$" && break; sleep 0.3; done
for u in 0 1; do
  rostopic pub -s -r 20 /uav\$u/odom nav_msgs/Odometry \
    "{header: {stamp: now, frame_id: world}, child_frame_id: world, pose: {pose: {position: {x: 10, y: \$((10 + 4 * u)), z: 4}, orientation: {w: 1.0}}}}" > /dev/null 2>&1 &
done
rostopic pub -s -r 20 /uav0/worker_state gesture_formation/WorkerState \
  "{header: {stamp: now, frame_id: world}, position: {x: 20, y: 10, z: 2}, covariance: [0.01,0,0,0,0,0, 0,0.01,0,0,0,0, 0,0,0.01,0,0,0, 0,0,0,0.01,0,0, 0,0,0,0,0.01,0, 0,0,0,0,0,0.01], source: uwb, accepted: true, last_fused: now}" \
  > /dev/null 2>&1 &
timeout 60 python3 "$T/diag.py" 20 > "$T/diag.txt" &
diag=\$!
sleep 3
python3 "$T/depth.py" & depth=\$!
sleep 10
kill \$depth
# A map update claiming UAV 0 sent through UAV 1's bridge: UAV 0's bridge must refuse it.
rostopic pub -1 /uav1/map_update gesture_formation/MapUpdate \
  "{header: {stamp: now}, uav_index: 0, sequence: 99, resolution_m: 0.2, occupied: [32800, 32800, 32770], free: []}" > /dev/null 2>&1
wait \$diag
sleep 1
cat "$T/log"/latest/rosout.log > "$T/rosout.txt" 2>/dev/null
kill \$(jobs -p) 2>/dev/null; wait
INNER
timeout 150 unshare -n bash "$T/inner.sh"
cat "$T/diag.txt"
val() { grep "^$1 " "$T/diag.txt" | tr ' ' '\n' | awk -F= -v k="$2" '$1 == k { print $2 }'; }
sent=$(val uav0 live_map_voxels_sent); merged=$(val uav1 live_map_voxels_merged); changed=$(val uav1 live_map_changes)
awk -v s="$sent" -v u="$(val uav0 live_map_updates_sent)" 'BEGIN { exit !(s >= 100 && u >= 1) }' \
  && echo "PASS: UAV 0's planner sent its wall: $sent voxels in $(val uav0 live_map_updates_sent) updates" \
  || fail "UAV 0 sent no map changes (voxels '$sent')"
# UAV 0 resends its wall every update (share.refresh_share), so updates are always in flight (and not yet
# reported) when the counting stops: by the end UAV 1 must have merged every voxel UAV 0 had sent 3 s
# before, and what UAV 1 had merged 3 s before the end UAV 0 must have sent by the end (nothing merged
# that was not sent).
early=$(val uav0_early live_map_voxels_sent); merged_early=$(val uav1_early live_map_voxels_merged)
awk -v s="$sent" -v e="$early" -v m="$merged" -v me="$merged_early" -v c="$changed" \
  'BEGIN { exit !(e >= 100 && m >= e && me <= s && c >= 100) }' \
  && echo "PASS: UAV 1's planner, without a camera, merged every voxel UAV 0 sent, nothing else ($merged merged by the end >= $early sent 3 s before; $merged_early merged 3 s before <= $sent sent by the end; $changed voxels of its map changed)" \
  || fail "UAV 1 merged '$merged' by the end, '$merged_early' 3 s before; UAV 0 had sent '$early' 3 s before the end, '$sent' by the end ($changed of its map changed)"
awk -v f="$(val uav1 live_map_frames_per_s)" -v r="$(val uav1 live_map_updates_refused)" 'BEGIN { exit !(f == 0 && r == 0) }' \
  && echo "PASS: UAV 1 integrated no frame of its own and refused no update" || fail "UAV 1: frames or refusals: $(grep ^uav1 "$T/diag.txt")"
matches "LcmBridge: from sender 1: map update refused ([0-9]* so far): sender 1, uav_index 0" "$T/rosout.txt" \
  && echo "PASS: a map update claiming UAV 0 from UAV 1's bridge is refused by UAV 0's bridge" \
  || fail "no refusal of the map update claiming another UAV (rosout: $(grep -c . "$T/rosout.txt" 2>/dev/null) lines)"
matches "refuses to start" "$T/launch.log" && fail "a nodelet refused to start: $(grep -A5 'refuses' "$T/launch.log" | head -6)"
[ $fails -eq 0 ] || { echo "--- launch.log"; grep -i "error\|warn" "$T/launch.log" | grep -v "group key" | tail -20; }
exit $fails
