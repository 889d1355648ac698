"""The campaign store: one SQLite file (WAL), one row per mission (tools/campaign.py;
docs/campaigns.md §Store).

A mission is keyed by (source commit, gfctl sha256, model sha256, scenario, fault profile,
seed, config hash). `missions` holds successful missions only, each written once, whole, in
one transaction by the client process; `failures` keeps every failed attempt (non-zero exit,
timeout, lost task, binary mismatch) with its log tail. A file that is not a store of this
tool (another SQLite database, a corrupt file, a newer schema) is refused before anything is
written to it: the header is read as plain bytes, then the database is opened read-only and
checked, and only then opened for writing.
"""
import csv
import datetime
import fcntl
import hashlib
import json
import os
import sqlite3

APPLICATION_ID = 0x47464350  # "GFCP": gesture_formation campaign store
SCHEMA_VERSION = 1
SQLITE_MAGIC = b"SQLite format 3\x00"

KEY_COLUMNS = ["source_commit", "gfctl_sha256", "model_sha256", "scenario", "profile", "seed", "config_hash"]
# metrics.json keys kept as columns (gfctl simulate, src/sim/mission_metrics.cpp); every key is
# also in metrics_json, so a key added later is not lost.
INT_METRICS = ["min_obstacle_uav", "collisions", "requests_applied", "false_adaptations", "requests_total",
               "operator_requests_applied", "gesture_requests_applied", "gestures_performed", "gestures_successful",
               "plans", "plans_fallback_previous", "plans_fallback_brake", "plans_skipped", "qp_sparse_timeouts",
               "plans_hold", "commands_stale", "commands_duplicate", "range_outliers", "messages_sent", "messages_lost",
               "messages_duplicated", "messages_reordered"]
REAL_METRICS = ["min_mutual_distance_m", "min_obstacle_distance_m", "min_obstacle_t_s", "min_human_distance_m",
                "distance_error_rms_m", "angle_error_rms_deg", "gesture_success_rate", "gesture_mean_latency_s",
                "planning_ms_median", "planning_ms_p99", "planning_ms_max", "human_estimate_error_rms_m",
                "visible_fraction", "sim_time_s", "wall_time_s", "real_time_factor"]
METRICS = REAL_METRICS + INT_METRICS

# The runs files of tools/run_fault_matrix.sh (docs/data/fault_matrix_runs*.csv, now imported).
LEGACY_CSV_COLUMNS = ["profile", "seed", "commit", "model_sha256", "min_mutual_distance_m", "min_obstacle_distance_m",
                      "min_obstacle_uav", "min_obstacle_t_s", "collisions", "requests_applied", "requests_total",
                      "false_adaptations", "human_estimate_error_rms_m", "min_human_distance_m", "plans_hold",
                      "plans_fallback_brake", "commands_stale", "distance_error_rms_m", "wall_time_s"]
LEGACY_SCENARIO = "config/scenarios/power_towers.yaml"
UNKNOWN_BINARY = "unknown"  # imported rows: the runs files did not record the binary


class StoreError(Exception):
    """A store that cannot be used; the message names the file and the reason."""


def config_hash(config):
    """16 hex digits of sha256 over the canonical JSON of a mission's config (overrides, duration)."""
    return hashlib.sha256(json.dumps(config, sort_keys=True, separators=(",", ":")).encode()).hexdigest()[:16]


BASE_CONFIG = {"duration_s": None, "overrides": {}}
BASE_CONFIG_HASH = config_hash(BASE_CONFIG)


def utc_now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


SCHEMA = f"""
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE missions (
  source_commit TEXT NOT NULL, gfctl_sha256 TEXT NOT NULL, model_sha256 TEXT NOT NULL, scenario TEXT NOT NULL,
  profile TEXT NOT NULL, seed INTEGER NOT NULL, config_hash TEXT NOT NULL,
  config_json TEXT NOT NULL, campaign TEXT NOT NULL, origin TEXT NOT NULL, worker TEXT, finished_utc TEXT,
  mission_s REAL,
  {", ".join(f"{m} REAL" for m in REAL_METRICS)},
  {", ".join(f"{m} INTEGER" for m in INT_METRICS)},
  metrics_json TEXT,
  PRIMARY KEY ({", ".join(KEY_COLUMNS)})
) WITHOUT ROWID;
CREATE TABLE failures (
  id INTEGER PRIMARY KEY, source_commit TEXT NOT NULL, gfctl_sha256 TEXT NOT NULL, model_sha256 TEXT NOT NULL,
  scenario TEXT NOT NULL, profile TEXT NOT NULL, seed INTEGER NOT NULL, config_hash TEXT NOT NULL,
  config_json TEXT NOT NULL, campaign TEXT NOT NULL, status TEXT NOT NULL, exit_code INTEGER, worker TEXT,
  finished_utc TEXT NOT NULL, mission_s REAL, log_tail TEXT NOT NULL
);
CREATE TABLE imports (file TEXT PRIMARY KEY, sha256 TEXT NOT NULL, rows INTEGER NOT NULL, imported_utc TEXT NOT NULL);
CREATE INDEX missions_by_commit ON missions (source_commit, scenario, profile);
"""
EXPECTED_TABLES = {"meta", "missions", "failures", "imports"}


def _check_header(path):
    """Plain-bytes checks of an existing file; raises StoreError. Nothing is opened for writing."""
    size = os.path.getsize(path)
    if size == 0:
        raise StoreError(f"{path}: empty file, not a campaign store (remove it or choose another --store)")
    with open(path, "rb") as f:
        header = f.read(100)
    if len(header) < 100 or header[:16] != SQLITE_MAGIC:
        raise StoreError(f"{path}: not an SQLite database (bad header): corrupt or another kind of file; left untouched")
    app_id = int.from_bytes(header[68:72], "big")
    if app_id != APPLICATION_ID:
        raise StoreError(f"{path}: a foreign SQLite database (application_id 0x{app_id:08x}, a campaign store has "
                         f"0x{APPLICATION_ID:08x}); left untouched")


def _check_readonly(path):
    """Opens read-only: schema version, tables, integrity. Raises StoreError."""
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    except sqlite3.Error as e:
        raise StoreError(f"{path}: cannot open read-only: {e}") from e
    try:
        version = con.execute("PRAGMA user_version").fetchone()[0]
        if version != SCHEMA_VERSION:
            raise StoreError(f"{path}: campaign store schema version {version}, this tool reads version "
                             f"{SCHEMA_VERSION}; left untouched")
        tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if not EXPECTED_TABLES <= tables:
            raise StoreError(f"{path}: campaign store without table(s) {sorted(EXPECTED_TABLES - tables)}; left untouched")
        problems = [r[0] for r in con.execute("PRAGMA quick_check")]
        if problems != ["ok"]:
            raise StoreError(f"{path}: corrupt SQLite database ({'; '.join(problems[:3])}); left untouched")
    except sqlite3.DatabaseError as e:
        raise StoreError(f"{path}: corrupt SQLite database ({e}); left untouched") from e
    finally:
        con.close()


def _create(path):
    """A new empty store, built aside and renamed into place: a crash leaves no half store."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.new-{os.getpid()}"
    if os.path.exists(tmp):
        os.remove(tmp)
    con = sqlite3.connect(tmp, isolation_level=None)
    try:
        con.execute("BEGIN")
        con.execute(f"PRAGMA application_id = {APPLICATION_ID}")
        con.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
        for statement in SCHEMA.split(";"):
            if statement.strip():
                con.execute(statement)
        con.execute("INSERT INTO meta VALUES ('created_utc', ?), ('tool', 'tools/campaign.py')", (utc_now(),))
        con.execute("COMMIT")
    finally:
        con.close()
    os.rename(tmp, path)


class Store:
    """An open campaign store. Store(path, create=True) creates a new one where no file is."""

    def __init__(self, path, create=True, lock=False):
        self.path = path
        self._lock_file = None
        if not os.path.exists(path):
            if not create:
                raise StoreError(f"{path}: no such campaign store")
            _create(path)
        _check_header(path)
        _check_readonly(path)
        if lock:
            self._take_lock()
        self.con = sqlite3.connect(path, timeout=60, isolation_level=None)  # explicit transactions below
        self.con.row_factory = sqlite3.Row
        self.con.execute("PRAGMA busy_timeout = 60000")
        self.con.execute("PRAGMA journal_mode = WAL")
        self.con.execute("PRAGMA synchronous = FULL")

    def _take_lock(self):
        """One campaign run per store at a time (another client would run the same missions)."""
        self._lock_file = open(self.path + ".lock", "a+")
        try:
            fcntl.flock(self._lock_file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as e:
            self._lock_file.seek(0)
            holder = self._lock_file.read().strip() or "?"
            raise StoreError(f"{self.path}: another campaign is running on this store (pid {holder})") from e
        self._lock_file.seek(0)
        self._lock_file.truncate()
        self._lock_file.write(str(os.getpid()))
        self._lock_file.flush()

    def transaction(self):
        store = self

        class _Tx:
            def __enter__(self):
                store.con.execute("BEGIN IMMEDIATE")

            def __exit__(self, exc_type, exc, tb):
                store.con.execute("COMMIT" if exc_type is None else "ROLLBACK")
                return False

        return _Tx()

    def close(self):
        if self.con is not None:
            self.con.close()
            self.con = None
        if self._lock_file is not None:
            self._lock_file.close()
            self._lock_file = None

    # ---- missions --------------------------------------------------------------------
    def stored_keys(self, commit, gfctl_sha, model_sha):
        rows = self.con.execute("SELECT scenario, profile, seed, config_hash FROM missions WHERE source_commit = ? AND "
                                "gfctl_sha256 = ? AND model_sha256 = ?", (commit, gfctl_sha, model_sha))
        return {(r[0], r[1], r[2], r[3]) for r in rows}

    def failed_keys(self, commit, gfctl_sha, model_sha):
        rows = self.con.execute("SELECT scenario, profile, seed, config_hash FROM failures WHERE source_commit = ? AND "
                                "gfctl_sha256 = ? AND model_sha256 = ?", (commit, gfctl_sha, model_sha))
        return {(r[0], r[1], r[2], r[3]) for r in rows}

    def add_mission(self, key, config_json, campaign, origin, metrics, metrics_json, worker=None, mission_s=None,
                    finished_utc=None):
        """Inserts one mission in its own transaction. False if the key was already stored
        (the row is never replaced)."""
        cols = KEY_COLUMNS + ["config_json", "campaign", "origin", "worker", "finished_utc", "mission_s"] + METRICS + \
            ["metrics_json"]
        values = [key[c] for c in KEY_COLUMNS] + [config_json, campaign, origin, worker, finished_utc or utc_now(),
                                                  mission_s]
        values += [_metric(metrics, m) for m in METRICS] + [metrics_json]
        with self.transaction():
            cur = self.con.execute(f"INSERT INTO missions ({', '.join(cols)}) VALUES ({', '.join('?' * len(cols))}) "
                                   "ON CONFLICT DO NOTHING", values)
        return cur.rowcount == 1

    def add_failure(self, key, config_json, campaign, status, exit_code, worker, mission_s, log_tail):
        cols = KEY_COLUMNS + ["config_json", "campaign", "status", "exit_code", "worker", "finished_utc", "mission_s",
                              "log_tail"]
        values = [key[c] for c in KEY_COLUMNS] + [config_json, campaign, status, exit_code, worker, utc_now(),
                                                  mission_s, log_tail]
        with self.transaction():
            self.con.execute(f"INSERT INTO failures ({', '.join(cols)}) VALUES ({', '.join('?' * len(cols))})", values)

    # ---- legacy runs files -----------------------------------------------------------
    def import_runs_csv(self, path, campaign):
        """Imports a runs file of tools/run_fault_matrix.sh once (all rows in one transaction).
        Returns (rows imported, rows already stored); (0, 0) if this file was imported before."""
        with open(path, "rb") as f:
            sha = hashlib.sha256(f.read()).hexdigest()
        name = os.path.basename(path)
        if self.con.execute("SELECT 1 FROM imports WHERE sha256 = ?", (sha,)).fetchone():
            return 0, 0
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            if reader.fieldnames != LEGACY_CSV_COLUMNS:
                raise StoreError(f"{path}: columns {reader.fieldnames} are not those of a fault-matrix runs file")
            rows = list(reader)
        added = dup = 0
        config_json = json.dumps(BASE_CONFIG, sort_keys=True)
        with self.transaction():
            for n, r in enumerate(rows, start=2):
                try:
                    key = {"source_commit": r["commit"], "gfctl_sha256": UNKNOWN_BINARY, "model_sha256": r["model_sha256"],
                           "scenario": LEGACY_SCENARIO, "profile": r["profile"], "seed": int(r["seed"]),
                           "config_hash": BASE_CONFIG_HASH}
                    metrics = {m: _number(r[m]) for m in LEGACY_CSV_COLUMNS[4:]}
                except ValueError as e:
                    raise StoreError(f"{path}:{n}: {e}") from e
                cols = KEY_COLUMNS + ["config_json", "campaign", "origin"] + METRICS
                values = [key[c] for c in KEY_COLUMNS] + [config_json, campaign, f"import:{name}"]
                values += [_metric(metrics, m) for m in METRICS]
                cur = self.con.execute(f"INSERT INTO missions ({', '.join(cols)}) VALUES "
                                       f"({', '.join('?' * len(cols))}) ON CONFLICT DO NOTHING", values)
                added += cur.rowcount
                dup += 1 - cur.rowcount
            self.con.execute("INSERT INTO imports VALUES (?, ?, ?, ?)", (name, sha, added, utc_now()))
        return added, dup

    # ---- queries ---------------------------------------------------------------------
    def rows(self, where="1", params=()):
        return [dict(r) for r in self.con.execute(f"SELECT * FROM missions WHERE {where}", params)]

    def failures(self, where="1", params=()):
        return [dict(r) for r in self.con.execute(f"SELECT * FROM failures WHERE {where} ORDER BY id", params)]

    def commits(self):
        """(commit, missions) of every commit in the store, most missions first."""
        return [tuple(r) for r in self.con.execute(
            "SELECT source_commit, COUNT(*) FROM missions GROUP BY source_commit ORDER BY 2 DESC, 1")]


def _number(v):
    if v is None or v == "":
        return None
    x = float(v)
    return int(x) if x.is_integer() and abs(x) < 2**53 else x


def _metric(metrics, name):
    v = metrics.get(name)
    if v is None:
        return None
    if name in INT_METRICS:
        return int(v)
    return float(v)
