#!/bin/bash
# Broken configs make the nodelets refuse to start, each problem named (parameter or YAML key),
# and nothing is advertised: FormationPlanner (a formation.yaml missing a key and holding an
# unknown one + an out-of-range
# ROS parameter + a missing one), GestureCommander (a gestures.yaml with an out-of-range ratio; one
# with an out-of-range view_fusion.min_agreeing_views and a missing view_fusion key), ViewObserver
# (no parameters),
# LcmBridge (a key file readable by others, a sender list that is not a list, a mistyped rate),
# SimWorld/SimUav (no mission), Leadership (an out-of-range leadership.clock_drift and a missing
# estimate_tolerance_s), OdometryAdapter (a camera mount angle in degrees).
set -o pipefail
source "$(dirname "$0")/common.bash"
start_master
CFG=$SRC/config
sed -e '/distance_max_m/d' -e 's/^limits:$/limits:\n  distance_maximum_m: 30.0/' "$CFG/formation.yaml" > "$T/formation_broken.yaml"
echo "safety_distance_m: 4.0  # misplaced: belongs under limits" >> "$T/formation_broken.yaml"
grep -q "distance_maximum_m" "$T/formation_broken.yaml" || fail "could not add an unknown key to a copy of formation.yaml"
sed 's/^ratio_threshold: .*/ratio_threshold: 1.7/' "$CFG/gestures.yaml" > "$T/gestures_broken.yaml"
sed -e 's/^\( *min_agreeing_views:\) .*/\1 0/' -e '/^ *elevation_max_deg:/d' "$CFG/gestures.yaml" > "$T/gestures_vf_broken.yaml"
grep -q "min_agreeing_views: 0" "$T/gestures_vf_broken.yaml" && ! grep -q "elevation_max_deg" "$T/gestures_vf_broken.yaml" \
  || fail "could not break view_fusion in a copy of gestures.yaml"
runs=()
run() {  # name, nodelet type, then ROS args (in the background; its pid in runs)
  local name=$1 type=$2; shift 2
  timeout 90 rosrun nodelet nodelet standalone "gesture_formation/$type" __name:="$name" "$@" > "$T/$name.log" 2>&1 &
  runs+=($!)
}
run fp_bad FormationPlanner _uav_index:=0 _uav_count:=3 _world_frame:=world \
  _scenario_file:="$CFG/scenarios/power_towers.yaml" _formation_config:="$T/formation_broken.yaml" \
  _planner_config:="$CFG/planner.yaml" _replanning_period_s:=99.0 _horizon_dt_s:=0.2 _horizon_steps:=40 \
  _params_rate_hz:=2.0 _max_odometry_age_s:=0.5 plan_out:=fp_bad_plan
run gc_bad GestureCommander _uav_count:=3 _sender_name:=gesture _frame_wait_s:=0.1 _frame_merge_s:=0.05 _gesture_config:="$T/gestures_broken.yaml"
run gc_vf GestureCommander _uav_count:=3 _sender_name:=gesture _frame_wait_s:=0.1 _frame_merge_s:=0.05 _gesture_config:="$T/gestures_vf_broken.yaml" \
  gesture_status_out:=gc_vf_status
run vo_bad ViewObserver observation_out:=vo_bad_observation
make_key "$T/keys"; chmod 644 "$T/keys"
run lb_bad LcmBridge _sender_id:=1 _known_senders:="[0,1,2]" _lcm_url:="memq://" _channel_prefix:=GF_ \
  _key_file:="$T/keys" _max_age_s:=1.0 _heartbeat_rate_hz:=5.0 _world_frame:=world _command_senders:=100 _max_rate_hz:=fast
rosparam set /od_bad/camera_mount_rpy_rad "[0.0, 20.0, 0.0]"  # a list: roscpp's _name:= arguments take scalars only
run od_bad OdometryAdapter _world_frame:=map _body_frame:=base_link _camera_mount:=fixed _camera_optical_axis:=x \
  odometry_out:=od_bad_odometry
run sw_bad SimWorld
run ld_bad Leadership _uav_index:=0 _uav_count:=3 _heartbeat_period_s:=0.2 _lease_s:=1.0 _silence_limit_s:=2.0 \
  _candidacy_stagger_s:=0.5 _election_timeout_s:=1.0 _clock_drift:=0.5 leadership_state:=ld_bad_state
# Wait until every nodelet has printed its refusal (a loaded machine takes several seconds to load
# six nodelet processes), at most 80 s, then give the rest of their messages a second.
for _ in $(seq 160); do
  n=0
  for f in fp_bad gc_bad gc_vf vo_bad lb_bad sw_bad ld_bad od_bad; do grep -q "refuses to start" "$T/$f.log" 2>/dev/null && n=$((n + 1)); done
  [ $n -eq 8 ] && break
  sleep 0.5
done
sleep 1
rostopic list 2>/dev/null | matches fp_bad_plan && fail "FormationPlanner advertised its output although it refused to start"
rostopic list 2>/dev/null | matches gc_vf_status && fail "GestureCommander advertised its output although it refused to start"
rostopic list 2>/dev/null | matches vo_bad_observation && fail "ViewObserver advertised its output although it refused to start"
rostopic list 2>/dev/null | matches ld_bad_state && fail "Leadership advertised its state although it refused to start"
rostopic list 2>/dev/null | matches od_bad_odometry && fail "OdometryAdapter advertised its output although it refused to start"
kill "${runs[@]}" 2>/dev/null
wait "${runs[@]}"
check() {  # log, pattern, what
  grep -q -- "$2" "$T/$1.log" || { fail "$1: $3 not reported"; sed 's/^/    /' "$T/$1.log" | head -20; }
}
for f in fp_bad gc_bad gc_vf vo_bad lb_bad sw_bad ld_bad od_bad; do check $f "refuses to start" "refusal"; done
check ld_bad "ld_bad/clock_drift: value 0.5 out of range" "out-of-range clock_drift (leadership.clock_drift's core range)"
check ld_bad "ld_bad/estimate_tolerance_s: missing" "missing estimate_tolerance_s"
check fp_bad "fp_bad/replanning_period_s: value 99 out of range" "out-of-range replanning_period_s"
check fp_bad "fp_bad/max_share_age_s: missing" "missing max_share_age_s"
check fp_bad "fp_bad/max_wind_estimate_age_s: missing" "missing max_wind_estimate_age_s"
check fp_bad "fp_bad/avoid_all_plans: missing" "missing avoid_all_plans (the avoidance rule without a mission)"
check fp_bad "limits.distance_max_m" "the missing YAML key limits.distance_max_m"
check fp_bad "formation_config: .*unknown key 'limits.distance_maximum_m'" "the unknown YAML key limits.distance_maximum_m"
check fp_bad "formation_config: .*unknown key 'safety_distance_m'" "the misplaced top-level YAML key safety_distance_m"
check gc_bad "ratio_threshold" "the out-of-range YAML key ratio_threshold"
check gc_vf "view_fusion.min_agreeing_views" "the out-of-range YAML key view_fusion.min_agreeing_views"
check gc_vf "view_fusion.elevation_max_deg" "the missing YAML key view_fusion.elevation_max_deg"
check vo_bad "vo_bad/uav_index: missing" "missing uav_index"
check vo_bad "vo_bad/max_state_age_s: missing" "missing max_state_age_s"
check lb_bad "key_file: .*chmod 600" "the key file's permissions"
check lb_bad "lb_bad/command_repeats: missing" "missing command_repeats (every problem at once)"
check lb_bad "lb_bad/command_senders: not a list of sender ids" "a sender list that is not a list (it meant: any sender)"
check lb_bad "lb_bad/max_rate_hz: not a number" "a mistyped max_rate_hz (it meant: the default)"
check od_bad "od_bad/camera_mount_rpy_rad\[1\]: 20.000000 rad is outside \[-pi, pi\]" "a mount angle in degrees"
for p in mission_file seed real_time_factor clock_step_s duration_s output_dir world_frame leader_camera_frame; do
  check sw_bad "sw_bad/$p: missing" "missing $p"
done
[ -n "$GF_TEST_VERBOSE" ] && cat "$T"/*_bad.log
[ $fails -eq 0 ] && echo "PASS: every broken config refused, every problem named"
exit $fails
