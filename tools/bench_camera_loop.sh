#!/usr/bin/env bash
# The rendered closed loop's cost (docs/simulation.md §8; issue 32 "Done when": the rendered
# mission's wall time per simulated second): flies the power-tower mission with
# `gfctl simulate --camera rendered` for GF_DURATION simulated seconds (default 60) and writes the
# wall time per simulated second, the per-frame times and the perception figures, with the machine
# and its load, to docs/results/camera_loop.md.
#
#   tools/bench_camera_loop.sh        # builds gfctl into build/ if needed
# Environment: GF_BUILD_DIR (default build), GF_DURATION (s, default 60), GF_SEED (default 1).
case "${1:-}" in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
set -eo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${GF_BUILD_DIR:-build}
DURATION=${GF_DURATION:-60}
SEED=${GF_SEED:-1}
GF_BUILD_DIR=$BUILD_DIR GF_JOBS=${GF_JOBS:-1} tools/build.sh gfctl >/dev/null
GFCTL=$BUILD_DIR/devel/lib/gesture_formation/gfctl
OUT=$(mktemp -d /tmp/gf-camera-loop.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
"$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --out "$OUT/rendered" --seed "$SEED" --duration "$DURATION" \
  --camera rendered --no-plot | tee "$OUT/rendered.log"
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
"$GFCTL" simulate --scenario config/scenarios/power_towers.yaml --out "$OUT/synthetic" --seed "$SEED" --duration "$DURATION" \
  --no-plot > "$OUT/synthetic.log"
mkdir -p docs/results
MD=$(mktemp /tmp/gf-camera-loop-md.XXXXXX)
/usr/bin/python3 - "$OUT" "$load_before" "$load_after" "$(git rev-parse --short HEAD)" "$SEED" > "$MD" <<'PY'
import datetime, json, re, subprocess, sys
out, before, after, commit, seed = sys.argv[1:6]
r = json.load(open(out + "/rendered/metrics.json"))
s = json.load(open(out + "/synthetic/metrics.json"))
p = r["perception"]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
gl = next((m.group(1) for m in map(re.compile(r"rendered camera \((.*)\), [0-9.]+ frames/s").search,
                                   open(out + "/rendered.log")) if m), "?")
per_s = r["wall_time_s"] / r["sim_time_s"]
print("# The rendered closed loop: cost\n")
print(f"Written by `tools/bench_camera_loop.sh` on {datetime.date.today().isoformat()} at commit {commit}: the power-tower "
      f"mission, seed {seed}, the first {r['sim_time_s']:.0f} simulated seconds, `gfctl simulate --camera rendered` "
      "(three UAV cameras at 15 frames/s, each rendered and through its own perception pipeline; docs/simulation.md §8).\n")
print(f"Machine: {cpu}, {subprocess.run(['nproc'], capture_output=True, text=True).stdout.strip()} cores; OpenGL `{gl}`. "
      f"Load average (1/5/15 min) before / after the run: {before} / {after} (the machine is shared: figures under load "
      "are upper bounds).\n")
print("| figure | rendered | synthetic (same seed and span) |")
print("| --- | --- | --- |")
print(f"| wall time per simulated second | **{per_s:.2f} s** | {s['wall_time_s'] / s['sim_time_s']:.3f} s |")
print(f"| real-time factor | {r['real_time_factor']:.2f}× | {s['real_time_factor']:.1f}× |")
print(f"| collisions; min mutual / obstacle / human distance [m] | {r['collisions']}; {r['min_mutual_distance_m']:.2f} / "
      f"{r['min_obstacle_distance_m']:.2f} / {r['min_human_distance_m']:.2f} | {s['collisions']}; "
      f"{s['min_mutual_distance_m']:.2f} / {s['min_obstacle_distance_m']:.2f} / {s['min_human_distance_m']:.2f} |")
print(f"| worker estimate error rms [m] | {r['human_estimate_error_rms_m']:.2f} | {s['human_estimate_error_rms_m']:.2f} |")
print(f"| camera frames with the worker found (leader) | {r['visible_fraction']:.3f} | {s['visible_fraction']:.3f} |\n")
print(f"Per camera frame (medians, all UAVs, {p['frames']} frames): render {p['render_ms_median']:.1f} ms, detector "
      f"{p['detect_ms_median']:.1f} ms (when it ran), tracker {p['track_ms_median']:.1f} ms, skeleton "
      f"{p['skeleton_ms_median']:.1f} ms; their sum {p['frame_ms_median']:.1f} ms.\n")
print(f"Perception against the truth: detected in {p['detected_in_view']} of {p['frames_in_view']} frames with the worker "
      f"in view ({p['detection_rate']:.3f}), keypoints a median {p['keypoint_error_px_median']:.1f} px "
      f"({p['keypoint_error_fraction_median']:.3f} of the figure) from the truth, box IoU {p['iou_median']:.2f}, "
      f"identity switches {p['identity_switches']}.\n")
print("| distance [m] | frames | detection rate | keypoint error [px] | of the figure |")
print("| --- | --- | --- | --- | --- |")
def n(v, fmt):
    return "–" if v is None else format(v, fmt)
for b in p["by_distance_m"]:
    print(f"| {b['bin']} | {b['frames']} | {n(b['detection_rate'], '.3f')} | {n(b['keypoint_error_px_median'], '.1f')} | "
          f"{n(b['keypoint_error_fraction_median'], '.3f')} |")
print("\n| camera elevation [deg] | frames | detection rate | keypoint error [px] | of the figure |")
print("| --- | --- | --- | --- | --- |")
for b in p["by_elevation_deg"]:
    print(f"| {b['bin']} | {b['frames']} | {n(b['detection_rate'], '.3f')} | {n(b['keypoint_error_px_median'], '.1f')} | "
          f"{n(b['keypoint_error_fraction_median'], '.3f')} |")
full = 451.0 * per_s
print(f"\nAt this rate the whole mission (451 s) takes about {full / 60:.0f} minutes per seed, and "
      f"`config/campaigns/camera_rendered.yaml` (5 seeds, rendered) about {5 * full / 3600:.1f} hours on one 2-core machine "
      "(one mission at a time: a mission already uses both cores).")
PY
mv "$MD" docs/results/camera_loop.md
echo "wrote docs/results/camera_loop.md"
