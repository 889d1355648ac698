"""One mission of a campaign, run on a Dask worker (tools/campaign.py; docs/campaigns.md).

Standard library only: tools/campaign.py sends this file to the scheduler and the workers
(Client.upload_file), so a worker needs the tools venv's Python and Dask, the gfctl build and
the model file, not this source tree. The worker checks that its gfctl and model have the sha256
the client expects before it runs anything: a row is never labelled with a binary or a model
other than the one that produced it.

run_mission(spec) never raises for a mission's own failure: it returns a result dict with
status "ok" (metrics read from metrics.json), "failed" (non-zero exit, missing or unreadable
metrics.json), "timeout" or "mismatch" (binary or model differ from the client's), with the
tail of gfctl's log.
"""
import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time

LOG_TAIL_BYTES = 4000
_HASH_CACHE = {}  # (path, size, mtime_ns) -> sha256 hex; per worker process


def file_sha256(path):
    """sha256 hex of a file, cached per (path, size, mtime) for the worker's lifetime."""
    st = os.stat(path)
    key = (os.path.realpath(path), st.st_size, st.st_mtime_ns)
    if key not in _HASH_CACHE:
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        _HASH_CACHE[key] = h.hexdigest()
    return _HASH_CACHE[key]


def project_libraries(binary, env=None):
    """The project's shared libraries the binary loads (ldd, as the binary would run), sorted;
    cached per (binary, size, mtime, LD_LIBRARY_PATH) for the worker's lifetime."""
    st = os.stat(binary)
    key = ("ldd", os.path.realpath(binary), st.st_size, st.st_mtime_ns, (env or os.environ).get("LD_LIBRARY_PATH"))
    if key not in _HASH_CACHE:
        _HASH_CACHE[key] = _ldd(binary, env)
    return _HASH_CACHE[key]


def _ldd(binary, env):
    try:
        out = subprocess.run(["ldd", binary], capture_output=True, text=True, timeout=30, env=env).stdout
    except (OSError, subprocess.TimeoutExpired):
        return []
    libs = set()
    for line in out.splitlines():
        parts = line.split("=>")
        if len(parts) == 2 and "gesture_formation" in parts[0]:
            path = parts[1].strip().split(" (")[0].strip()
            if path.startswith("/"):
                libs.add(path)
    return sorted(libs)


def binary_sha256(binary, env=None):
    """sha256 of gfctl together with the project libraries it loads (the core library holds
    most of the code: gfctl's own bytes do not change when only the core does)."""
    parts = [f"gfctl {file_sha256(binary)}"]
    parts += [f"{os.path.basename(p)} {file_sha256(p)}" for p in project_libraries(binary, env)]
    if len(parts) == 1:
        return file_sha256(binary)
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _pdeathsig_prefix():
    """util-linux setpriv: gfctl gets SIGKILL when the worker thread that started it dies (a
    worker killed with kill -9 leaves no orphan mission burning a core). Not a preexec_fn:
    forking Python code in a threaded worker can deadlock."""
    setpriv = shutil.which("setpriv")
    return [setpriv, "--pdeathsig", "KILL", "--"] if setpriv else []


def _tail(path):
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - LOG_TAIL_BYTES))
            return f.read().decode("utf-8", "replace")
    except OSError as e:
        return f"(no log: {e})"


def _resolve(spec):
    """gfctl and model paths as this worker sees them: GF_CAMPAIGN_GFCTL / GF_CAMPAIGN_MODEL on
    the worker override the client's paths (a cluster whose nodes mount the build elsewhere), GF_CAMPAIGN_WORK the
    scratch directory of the missions."""
    gfctl = os.environ.get("GF_CAMPAIGN_GFCTL", spec["gfctl"])
    model = os.environ.get("GF_CAMPAIGN_MODEL", spec["model"]) if spec.get("model") else None
    work_root = os.environ.get("GF_CAMPAIGN_WORK", spec["work_root"])
    return gfctl, model, work_root


def run_mission(spec):
    """Runs one mission (see module doc). spec: key fields, gfctl, gfctl_sha256, model,
    model_sha256, scenario_text, faults_text (or None), duration_s, timeout_s, threads,
    work_root, keep_dir (or None)."""
    t_start = time.time()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    result = {"key": spec["key"], "worker": worker, "t_start": t_start, "exit_code": None, "metrics": None,
              "log_tail": "", "mission_s": 0.0}

    def done(status, **kw):
        result.update(status=status, t_end=time.time(), **kw)
        return result

    gfctl, model, work_root = _resolve(spec)
    try:
        sha = binary_sha256(gfctl)
        if sha != spec["gfctl_sha256"]:
            return done("mismatch", log_tail=f"{worker}: {gfctl} has sha256 {sha}, the client expects "
                        f"{spec['gfctl_sha256']} (set GF_CAMPAIGN_GFCTL on the worker to the same build)")
        if model:
            msha = file_sha256(model)
            if msha != spec["model_sha256"]:
                return done("mismatch", log_tail=f"{worker}: {model} has sha256 {msha}, the client expects "
                            f"{spec['model_sha256']} (set GF_CAMPAIGN_MODEL on the worker)")
    except OSError as e:
        return done("mismatch", log_tail=f"{worker}: {e}")

    os.makedirs(work_root, exist_ok=True)
    work = tempfile.mkdtemp(prefix="mission_", dir=work_root)
    try:
        scenario = os.path.join(work, "scenario.yaml")
        with open(scenario, "w") as f:
            f.write(spec["scenario_text"])
        out = os.path.join(work, "out")
        cmd = [gfctl, "simulate", "--scenario", scenario, "--seed", str(spec["key"]["seed"]), "--out", out,
               "--no-plot", "--threads", str(spec["threads"])]
        if model:
            cmd += ["--model", model]
        if spec.get("faults_text") is not None:
            faults = os.path.join(work, "faults.yaml")
            with open(faults, "w") as f:
                f.write(spec["faults_text"])
            cmd += ["--faults", faults]
        if spec.get("duration_s"):
            cmd += ["--duration", repr(float(spec["duration_s"]))]
        if spec.get("camera"):  # gfctl simulate --camera rendered (docs/simulation.md §8)
            cmd += ["--camera", spec["camera"]]
        log = os.path.join(work, "gfctl.log")
        t0 = time.time()
        with open(log, "wb") as logf:
            # Own session: a timeout kills gfctl and anything it started together.
            proc = subprocess.Popen(_pdeathsig_prefix() + cmd, stdout=logf, stderr=subprocess.STDOUT,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                rc = proc.wait(timeout=spec["timeout_s"])
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                return done("timeout", mission_s=time.time() - t0, log_tail=_tail(log) +
                            f"\n[campaign] killed after the per-mission timeout of {spec['timeout_s']} s")
        mission_s = time.time() - t0
        result.update(exit_code=rc, mission_s=mission_s, log_tail=_tail(log))
        if rc != 0:
            return done("failed")
        try:
            with open(os.path.join(out, "metrics.json")) as f:
                result["metrics_json"] = f.read()
            result["metrics"] = json.loads(result["metrics_json"])
        except (OSError, ValueError) as e:
            return done("failed", log_tail=result["log_tail"] + f"\n[campaign] metrics.json: {e}")
        if spec.get("keep_dir"):
            dest = spec["keep_dir"]
            shutil.rmtree(dest, ignore_errors=True)
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            shutil.move(out, dest)
        return done("ok")
    finally:
        shutil.rmtree(work, ignore_errors=True)
