#!/usr/bin/env python3
"""Runs the held-out gesture protocol (tools/gesture/heldout/protocol.yaml; docs/gestures.md §8)
through the product's own code and reports the figures beside the protocol's targets.

    /opt/gesture_formation/venv/bin/python tools/gesture/heldout_eval.py \
        --gfctl build/devel/lib/gesture_formation/gfctl [--rearm shipped,repeat] [--work DIR]

Nothing here chooses anything: the sets, seeds and targets are the protocol's, the model and the
filter/vote configuration are the shipped ones (third_party_models/gesture_lstm/gesture_lstm.onnx,
config/gestures.yaml). `--rearm` only selects the filter's re-arming mode(s) to report: `shipped`
(config/gestures.yaml as it is) or a mode name written into a copy of it (`rearm: <mode>`).

Chain (each step a gfctl command, i.e. the C++ product code):
  gfctl synth-gestures (protocol seed, count, generator settings; --views for the three cameras)
  -> gfctl classify per view (OpenCV DNN)
  -> gfctl fuse-views (gesture::ViewFusion, config/gestures.yaml)          [three cameras]
  -> gfctl gesture-filter (gesture::GestureFilter, config/gestures.yaml)   [three cameras]

Definitions: window label = the newest frame's label; a work window "read as a gesture" = a window
of a work-motion/idle sequence classified as any gesture; a gesture performance fires when its own
command fires while it is performed (motion_start_s <= t <= motion_end_s), latency = t_fire -
motion_start_s; every command during a work-motion/idle sequence is a false adaptation; a command
of another gesture during a gesture sequence is a wrong command.

Writes docs/results/gestures_heldout.md and docs/results/gestures_heldout.json (date, commit,
model sha256, machine and its load).
"""
import argparse
import datetime
import hashlib
import json
import os
import platform
import subprocess
import sys
import tempfile

import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evaluate_gesture_lstm as ev  # noqa: E402  (laid_out, classify, classify_view, fuse, confusion)
import gesture_data  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PROTOCOL = os.path.join(ROOT, "tools/gesture/heldout/protocol.yaml")
MODEL = os.path.join(ROOT, "third_party_models/gesture_lstm/gesture_lstm.onnx")
GESTURES_YAML = os.path.join(ROOT, "config/gestures.yaml")
CLASSES = ev.CLASSES


def set_paths(protocol, config):
    """The protocol and the configuration a run uses (the defaults: the held-out protocol and the shipped
    config/gestures.yaml; tuning runs pass their own and write elsewhere)."""
    global PROTOCOL, GESTURES_YAML
    PROTOCOL, GESTURES_YAML = os.path.abspath(protocol), os.path.abspath(config)


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def git(*args):
    r = subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else "unknown"


def machine():
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")), cpu)
    except OSError:
        pass
    return {"host_os": platform.platform(), "cpu": cpu, "cores": os.cpu_count(), "load_average": list(os.getloadavg())}


def synthesize(gfctl, name, spec, work):
    """The set's data directory (skeletons*.csv, sequences*.csv), generated from the protocol."""
    d = os.path.join(work, name)
    os.makedirs(d, exist_ok=True)
    cfg = os.path.join(d, "synth.yaml")
    with open(cfg, "w") as f:
        yaml.safe_dump(dict(spec["synth"]), f)
    views = spec.get("views_deg")
    return gesture_data.synthesize(gfctl, spec["seed"], spec["count"], d, cfg, views)


def in_envelope(md, env):
    d, e = float(md["distance_m"]), float(md["elevation_deg"])
    return env["distance_min_m"] <= d <= env["distance_max_m"] and env["elevation_min_deg"] <= e <= env["elevation_max_deg"]


def window_share(res, meta, keep):
    """(windows, windows read as a gesture) over the work-motion sequences with keep(meta)."""
    w = g = 0
    for seq, _, _, _, p, _ in res:
        md = meta[seq]
        if int(md["gesture_id"]) == 0 and keep(md):
            w += 1
            g += int(p != 0)
    return w, g


def single_camera(gfctl, model, spec, protocol, work, envelope):
    fps = protocol["fps"]
    d = synthesize(gfctl, "single_camera", spec, work)
    laid, keys, meta = ev.laid_out(d, fps)
    _, res = ev.classify(gfctl, model, laid, keys, fps, d)
    m = ev.confusion(res)
    w, g = window_share(res, meta, lambda md: True)
    by_motion = {}
    for seq, _, _, _, p, _ in res:
        md = meta[seq]
        if int(md["gesture_id"]) == 0:
            e = by_motion.setdefault(md["motion"], [0, 0])
            e[0] += 1
            e[1] += int(p != 0)
    inside = window_share(res, meta, lambda md: in_envelope(md, envelope))
    outside = window_share(res, meta, lambda md: not in_envelope(md, envelope))
    acc_in = [int(y == p) for seq, _, _, y, p, _ in res if in_envelope(meta[seq], envelope)]
    return {"seed": spec["seed"], "sequences": spec["count"], "windows": int(m.sum()),
            "work_windows": w, "work_windows_read_as_gesture": g,
            "work_share_read_as_gesture": round(g / w, 4) if w else None,
            "accuracy": round(float(np.trace(m) / m.sum()), 4),
            "per_class": ev.per_class(m), "confusion": m.tolist(),
            "work_share_by_motion": {k: {"windows": v[0], "share": round(v[1] / v[0], 4)} for k, v in sorted(by_motion.items())},
            "inside_classifier_envelope": {"accuracy": round(float(np.mean(acc_in)), 4) if acc_in else None,
                                           "work_windows": inside[0],
                                           "work_share_read_as_gesture": round(inside[1] / inside[0], 4) if inside[0] else None},
            "outside_classifier_envelope": {"work_windows": outside[0],
                                            "work_share_read_as_gesture": round(outside[1] / outside[0], 4) if outside[0] else None}}


def three_views(gfctl, model, name, spec, protocol, work):
    """Classifies every view and fuses them; returns (data dir, meta, leader csv, fused csv)."""
    fps = protocol["fps"]
    d = synthesize(gfctl, name, spec, work)
    _, _, meta = ev.laid_out(d, fps)
    views = [ev.classify_view(gfctl, model, d, "", fps, d)]
    views += [ev.classify_view(gfctl, model, d, f"_view{i + 1}", fps, d) for i in range(len(spec["views_deg"]))]
    fused = ev.fuse(gfctl, views, GESTURES_YAML, os.path.join(d, "fused.csv"))
    return d, meta, views[0], fused


def check_3d_counts(fused_csv):
    """Rows of the fused file checked in 3-D and rejected by it (view_fusion.require_3d; None without
    calibrated views)."""
    header, rows = ev.read_csv(fused_csv)
    if "rejected_3d" not in header:
        return None
    ic, ir = header.index("checked_3d"), header.index("rejected_3d")
    return {"rows": len(rows), "checked_3d": sum(int(r[ic]) for r in rows), "rejected_3d": sum(int(r[ir]) for r in rows)}


def run_filter(gfctl, ids_csv, config, out_dir, tag):
    """gfctl gesture-filter over t,gesture_id of `ids_csv`; returns [(t, gesture id)] fired."""
    inp = os.path.join(out_dir, f"filter_in_{tag}.csv")
    _, rows = ev.read_csv(ids_csv)
    with open(inp, "w") as f:
        f.write("t,gesture_id\n")
        for r in rows:
            f.write(f"{r[0]},{r[1]}\n")
    out = os.path.join(out_dir, f"commands_{tag}.csv")
    ev.run([gfctl, "gesture-filter", "--config", config, "--in", inp, "--out", out])
    _, fired = ev.read_csv(out)
    return [(float(r[0]), int(r[1])) for r in fired]


def score(fired, meta, gap_s, fps):
    """Per-sequence scoring of the fired commands (definitions: module docstring)."""
    by_seq = {}
    for t, g in fired:
        seq = int(t // gap_s)
        by_seq.setdefault(seq, []).append((t - gap_s * seq, g))
    n_g = succ = wrong = extra = 0
    latencies, false_list, missed = [], [], []
    work_s = 0.0
    for seq, md in sorted(meta.items()):
        gid = int(md["gesture_id"])
        fs = by_seq.get(seq, [])
        if gid == 0:
            work_s += int(md["frames"]) / fps
            false_list += [{"sequence": seq, "motion": md["motion"], "t_s": round(t, 3), "gesture": CLASSES[g],
                            "distance_m": float(md["distance_m"]), "elevation_deg": float(md["elevation_deg"]),
                            "azimuth_deg": float(md["azimuth_deg"])} for t, g in fs]
            continue
        n_g += 1
        t0, t1 = float(md["motion_start_s"]), float(md["motion_end_s"])
        wrong += sum(1 for _, g in fs if g != gid)
        ok = [t for t, g in fs if g == gid and t0 <= t <= t1]
        extra += max(0, sum(1 for _, g in fs if g == gid) - 1)
        if ok:
            succ += 1
            latencies.append(ok[0] - t0)
        else:
            missed.append({"sequence": seq, "gesture": CLASSES[gid], "hold_s": round(t1 - t0, 2), "commands": [
                [round(t, 3), CLASSES[g]] for t, g in fs], "distance_m": float(md["distance_m"]),
                "elevation_deg": float(md["elevation_deg"]), "azimuth_deg": float(md["azimuth_deg"])})
    return {"gestures": n_g, "fired": succ, "fired_share": round(succ / n_g, 4) if n_g else None,
            "mean_latency_s": round(float(np.mean(latencies)), 3) if latencies else None,
            "max_latency_s": round(float(np.max(latencies)), 3) if latencies else None,
            "wrong_commands": wrong, "repeated_commands": extra,
            "work_minutes": round(work_s / 60.0, 2), "false_adaptations": len(false_list),
            "false_adaptation_list": false_list, "missed_list": missed}


def filter_config(mode, work):
    if mode == "shipped":
        return GESTURES_YAML
    with open(GESTURES_YAML) as f:
        cfg = yaml.safe_load(f)
    cfg["rearm"] = mode
    path = os.path.join(work, f"gestures_rearm_{mode}.yaml")
    with open(path, "w") as f:
        yaml.safe_dump(cfg, f)
    return path


def shipped_rearm():
    with open(GESTURES_YAML) as f:
        return yaml.safe_load(f).get("rearm", "(default)")


def verdicts(single, three, targets):
    t1, t3 = targets["single_camera"], targets["three_cameras"]
    out = {"single_camera": {
        "work_windows_read_as_gesture": single["work_share_read_as_gesture"] <= t1["work_windows_read_as_gesture_max"],
        "window_accuracy": single["accuracy"] >= t1["window_accuracy_min"]}}
    for mode, r in three.items():
        w, g = r["work"]["three_cameras"], r["gestures"]["three_cameras"]
        out[f"three_cameras[{mode}]"] = {
            "enough_work_minutes": w["work_minutes"] >= t3["min_work_minutes"],
            "enough_gestures": g["gestures"] >= t3["min_gestures"],
            "false_adaptations": w["false_adaptations"] <= t3["false_adaptations_max"],
            "gestures_fired": (g["fired_share"] or 0.0) >= t3["gestures_fired_min"],
            "mean_latency": g["mean_latency_s"] is not None and g["mean_latency_s"] <= t3["mean_latency_max_s"]}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gfctl", required=True)
    ap.add_argument("--model", default=MODEL)
    ap.add_argument("--work", default=None, help="data directory (default: a new temporary one)")
    ap.add_argument("--rearm", default="shipped", help="comma-separated: shipped and/or mode names (release, repeat)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/results/gestures_heldout"), help="page/json path without extension")
    ap.add_argument("--protocol", default=PROTOCOL,
                    help="protocol file (default: the held-out one; tuning uses tools/gesture/tuning/protocol_tuning.yaml "
                         "with its own seeds and --out elsewhere)")
    ap.add_argument("--config", default=GESTURES_YAML, help="filter and vote configuration (default: the shipped one)")
    a = ap.parse_args()
    set_paths(a.protocol, a.config)
    with open(PROTOCOL) as f:
        protocol = yaml.safe_load(f)
    work = a.work or tempfile.mkdtemp(prefix="gf_heldout_")
    modes = [m.strip() for m in a.rearm.split(",") if m.strip()]
    load_start = os.getloadavg()
    with open(GESTURES_YAML) as f:
        envelope = yaml.safe_load(f)["view_fusion"]
    gap, fps, sets = protocol["sequence_gap_s"], protocol["fps"], protocol["sets"]
    assert gap == ev.SEQ_GAP_S, "the protocol's sequence gap must equal evaluate_gesture_lstm.SEQ_GAP_S"

    single = single_camera(a.gfctl, a.model, sets["single_camera"], protocol, work, envelope)
    print(f"single camera: accuracy {single['accuracy']:.4f} (target >= {protocol['targets']['single_camera']['window_accuracy_min']}), "
          f"work windows read as a gesture {single['work_share_read_as_gesture']:.4f} of {single['work_windows']} "
          f"(target <= {protocol['targets']['single_camera']['work_windows_read_as_gesture_max']})")
    data = {name: three_views(a.gfctl, a.model, name, sets[name], protocol, work)
            for name in ("three_cameras_work", "three_cameras_gestures")}
    checks = {name: check_3d_counts(data[name][3]) for name in data}
    three = {}
    for mode in modes:
        cfg = filter_config(mode, work)
        label = f"{mode} ({shipped_rearm()})" if mode == "shipped" else mode
        three[label] = {}
        for name, key in (("three_cameras_work", "work"), ("three_cameras_gestures", "gestures")):
            d, meta, leader, fused = data[name]
            three[label][key] = {
                "three_cameras": score(run_filter(a.gfctl, fused, cfg, d, f"fused_{mode}"), meta, gap, fps),
                "leader_camera_only": score(run_filter(a.gfctl, leader, cfg, d, f"leader_{mode}"), meta, gap, fps)}
        w, g = three[label]["work"]["three_cameras"], three[label]["gestures"]["three_cameras"]
        print(f"three cameras, rearm {label}: {w['false_adaptations']} false adaptations in {w['work_minutes']} min; "
              f"gestures fired {g['fired']}/{g['gestures']} = {g['fired_share']}, mean latency {g['mean_latency_s']} s "
              f"(max {g['max_latency_s']}), wrong {g['wrong_commands']}, repeated {g['repeated_commands']}")
    report = {"date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
              "commit": git("rev-parse", "--short", "HEAD"), "worktree_clean": git("status", "--porcelain", "--untracked-files=no") == "",
              "protocol": os.path.relpath(PROTOCOL, ROOT), "protocol_version": protocol["version"],
              "protocol_sha256": sha256(PROTOCOL), "model": os.path.relpath(a.model, ROOT), "model_sha256": sha256(a.model),
              "filter_config": os.path.relpath(GESTURES_YAML, ROOT), "filter_config_sha256": sha256(GESTURES_YAML),
              "machine": dict(machine(), load_average_start=list(load_start)), "targets": protocol["targets"],
              "single_camera": single, "three_cameras": three, "fused_rows_3d_check": checks}
    report["meets_target"] = verdicts(single, three, protocol["targets"])
    with open(a.out + ".json", "w") as f:
        json.dump(report, f, indent=1)
    with open(a.out + ".md", "w") as f:
        f.write(page(report, protocol))
    print(f"wrote {a.out}.md and .json")
    for k, v in report["meets_target"].items():
        print(f"  {k}: " + ", ".join(f"{n} {'MET' if ok else 'NOT MET'}" for n, ok in v.items()))


def yes(ok):
    return "**met**" if ok else "**not met**"


def page(r, protocol):
    t1, t3 = protocol["targets"]["single_camera"], protocol["targets"]["three_cameras"]
    s = r["single_camera"]
    lines = [
        "# Gestures on the held-out protocol",
        "",
        f"Written by `tools/gesture/heldout_eval.py` on {r['date_utc']} UTC, commit {r['commit']}"
        f"{'' if r['worktree_clean'] else ' (with uncommitted changes)'}; protocol "
        f"`{r['protocol']}` version {r['protocol_version']} (sha256 {r['protocol_sha256'][:16]}…); model `{r['model']}` sha256 "
        f"{r['model_sha256']}; filter and vote `{r['filter_config']}` (sha256 {r['filter_config_sha256'][:16]}…).",
        f"Machine: {r['machine']['cpu']}, {r['machine']['cores']} cores, {r['machine']['host_os']}; load average at the "
        f"start {', '.join(f'{x:.2f}' for x in r['machine']['load_average_start'])}, at the end "
        f"{', '.join(f'{x:.2f}' for x in r['machine']['load_average'])} (shared machine).",
        "",
        "Nothing was chosen on these figures (docs/gestures.md §8). Definitions: the script's docstring.",
        "",
        "## One camera (set single_camera, seed %d, %d sequences, %d windows)" % (s["seed"], s["sequences"], s["windows"]),
        "",
        "| figure | measured | target | |",
        "|---|---|---|---|",
        f"| work-motion/idle windows read as a gesture | {s['work_share_read_as_gesture']:.4f} "
        f"({s['work_windows_read_as_gesture']} of {s['work_windows']}) | ≤ {t1['work_windows_read_as_gesture_max']} | "
        f"{yes(r['meets_target']['single_camera']['work_windows_read_as_gesture'])} |",
        f"| window accuracy | {s['accuracy']:.4f} | ≥ {t1['window_accuracy_min']} | "
        f"{yes(r['meets_target']['single_camera']['window_accuracy'])} |",
        "",
        f"Inside the classifier's validated envelope (5–20 m, 0–45°): accuracy {s['inside_classifier_envelope']['accuracy']}, "
        f"work windows read as a gesture {s['inside_classifier_envelope']['work_share_read_as_gesture']} "
        f"(of {s['inside_classifier_envelope']['work_windows']}); outside it: "
        f"{s['outside_classifier_envelope']['work_share_read_as_gesture']} (of {s['outside_classifier_envelope']['work_windows']}).",
        "",
        "| class | precision | recall | windows |",
        "|---|---|---|---|",
    ]
    lines += [f"| {c} | {v['precision']} | {v['recall']} | {v['support']} |" for c, v in s["per_class"].items()]
    lines += ["", "Work windows read as a gesture, per motion: " +
              ", ".join(f"{k} {v['share']:.3f} ({v['windows']})" for k, v in s["work_share_by_motion"].items()) + ".", ""]
    sw, sg = protocol["sets"]["three_cameras_work"], protocol["sets"]["three_cameras_gestures"]
    lines += ["## Three cameras placed like the formation (classify → fuse-views → gesture-filter)", "",
              f"Sets three_cameras_work (seed {sw['seed']}, {sw['count']} work-motion/idle sequences) and "
              f"three_cameras_gestures (seed {sg['seed']}, {sg['count']} gesture performances), views at "
              f"{', '.join(f'{v:+d}°' for v in sw['views_deg'])} azimuth from the leader's. \"one camera only\": the "
              "leader's classifications straight into the same filter (for comparison).", "",
              "| rearm | minutes of work motions | false adaptations (target ≤ %d) | gestures fired (target ≥ %.0f %%) | "
              "mean (max) latency (target ≤ %.1f s) | wrong commands | repeated commands | one camera only: false adaptations, fired |"
              % (t3["false_adaptations_max"], 100 * t3["gestures_fired_min"], t3["mean_latency_max_s"]),
              "|---|---|---|---|---|---|---|---|"]
    for mode, m in r["three_cameras"].items():
        w, g = m["work"]["three_cameras"], m["gestures"]["three_cameras"]
        lw, lg = m["work"]["leader_camera_only"], m["gestures"]["leader_camera_only"]
        v = r["meets_target"][f"three_cameras[{mode}]"]
        lines.append(f"| {mode} | {w['work_minutes']} | {w['false_adaptations']} {yes(v['false_adaptations'])} | "
                     f"{g['fired']}/{g['gestures']} = {100 * (g['fired_share'] or 0):.1f} % {yes(v['gestures_fired'])} | "
                     f"{g['mean_latency_s']} s ({g['max_latency_s']}) {yes(v['mean_latency'])} | {g['wrong_commands']} | "
                     f"{g['repeated_commands']} | {lw['false_adaptations']}, {lg['fired']}/{lg['gestures']} |")
    for name, c in r.get("fused_rows_3d_check", {}).items():
        lines += ["", f"3-D check (view_fusion.require_3d) on {name}: " + ("no calibrated views" if c is None else
                  f"{c['checked_3d']} of {c['rows']} fused frames checked, {c['rejected_3d']} rejected")]
    lines += ["", "False adaptations (three cameras):", ""]
    for mode, m in r["three_cameras"].items():
        fl = m["work"]["three_cameras"]["false_adaptation_list"]
        lines.append(f"- rearm {mode}: " + ("none" if not fl else "; ".join(
            f"{x['gesture']} during {x['motion']} (sequence {x['sequence']}, t {x['t_s']} s, leader {x['distance_m']:.1f} m, "
            f"{x['elevation_deg']:.1f}°, azimuth {x['azimuth_deg']:.0f}°)" for x in fl)))
    lines += ["", "Gestures that did not fire while performed (three cameras):", ""]
    for mode, m in r["three_cameras"].items():
        ml = m["gestures"]["three_cameras"]["missed_list"]
        lines.append(f"- rearm {mode}: " + ("none" if not ml else "; ".join(
            f"{x['gesture']} (sequence {x['sequence']}, performed {x['hold_s']} s, commands {x['commands'] or 'none'}, "
            f"leader {x['distance_m']:.1f} m, {x['elevation_deg']:.1f}°, azimuth {x['azimuth_deg']:.0f}°)" for x in ml)))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
