"""The campaign store: one SQLite file (WAL) holding the config and its hash, every proposal and every observation
(with the raw message it came in). The only module that touches the database.

An observation is committed before this module returns, so a caller that acknowledges after ``add_observation`` never
acknowledges something a crash could lose. One process writes a store at a time: a writer holds an exclusive lock
on ``<store>.lock`` (released by the operating system when the process ends, however it ends); readers
(``open_existing``: export, progress, dashboards) take no lock.
"""

from __future__ import annotations

import csv
import fcntl
import json
import os
import socket
import sqlite3
import threading
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .planner.config import label, units_of
from .planner.domain import Observation, Proposal
from .planner.errors import GryffinRosError
from .planner.molecules import smiles_of

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS proposals (
    experiment_id TEXT PRIMARY KEY, params TEXT NOT NULL, strategy REAL, created REAL NOT NULL, meta TEXT);
CREATE TABLE IF NOT EXISTS observations (
    seq INTEGER PRIMARY KEY AUTOINCREMENT, experiment_id TEXT NOT NULL UNIQUE, params TEXT NOT NULL,
    objectives TEXT NOT NULL, meta TEXT NOT NULL, raw TEXT, received REAL NOT NULL);
CREATE TABLE IF NOT EXISTS claims (
    experiment_id TEXT PRIMARY KEY, instrument TEXT NOT NULL, claimed REAL NOT NULL);
CREATE TABLE IF NOT EXISTS rejections (
    seq INTEGER PRIMARY KEY AUTOINCREMENT, experiment_id TEXT, reason TEXT NOT NULL, raw TEXT, received REAL NOT NULL);
CREATE TABLE IF NOT EXISTS molecules (
    smiles TEXT NOT NULL, feature TEXT NOT NULL, value REAL NOT NULL, PRIMARY KEY (smiles, feature));
"""
# A refused message is kept up to this many characters (what was wrong is in the reason; the rest is evidence).
REJECTED_RAW_CHARS = 4096


class StoreError(GryffinRosError):
    """The campaign store cannot be used (another campaign's file, unreadable, duplicate experiment)."""


def _hold(path: str):
    """Take the exclusive writer's lock of the store at `path` (a file beside it naming the holder), or raise
    StoreError naming the process that holds it."""
    lock_path = f"{path}.lock"
    try:
        handle = open(lock_path, "a+")
    except OSError as exc:
        raise StoreError(f"cannot create the lock file '{lock_path}' of campaign store '{path}': {exc.strerror}") \
            from None
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.seek(0)
        holder = handle.read().strip() or "another process"
        handle.close()
        raise StoreError(f"campaign store '{path}' is in use by {holder}; a store has one writer at a time: stop "
                         "that process first, or give this one another storage file") from None
    handle.seek(0)
    handle.truncate()
    handle.write(f"pid {os.getpid()} on {socket.gethostname()} since {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
    handle.flush()
    return handle


class CampaignStore:
    """A campaign's SQLite file. Opened with a config (the writer: holds the store exclusively, creates it when new,
    refuses another config's store) or by ``open_existing`` (read-only, no lock)."""

    def __init__(self, path: str | Path, config: dict, config_hash: str, *, readonly: bool = False):
        self.path = str(path)
        self.readonly = readonly
        self._lock = threading.Lock()
        self._holder = None
        self._db = None
        try:
            if readonly:
                self._open_reader()
            else:
                self._open_writer(config, config_hash)
        except BaseException:  # nothing stays open or locked behind a refusal
            self.close()
            raise

    def _open_reader(self) -> None:
        try:
            self._db = sqlite3.connect(f"file:{self.path}?mode=ro", uri=True, check_same_thread=False,
                                       isolation_level=None, timeout=30.0)
            self._db.execute("SELECT COUNT(*) FROM observations")
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"'{self.path}' is not a campaign store: {exc}") from None

    def _open_writer(self, config: dict, config_hash: str) -> None:
        if self.path != ":memory:":
            self._holder = _hold(self.path)
        try:
            self._db = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None, timeout=30.0)
            if self.path != ":memory:":
                self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=FULL")
            self._db.executescript(SCHEMA)
            columns = {row[1] for row in self._db.execute("PRAGMA table_info(proposals)")}
            if "meta" not in columns:  # a store written before proposals recorded how they were chosen
                self._db.execute("ALTER TABLE proposals ADD COLUMN meta TEXT")
            stored = self.get_meta("config_hash")
            if stored is None:
                with self._transaction():
                    self._set_meta("config", json.dumps(config, sort_keys=True))
                    self._set_meta("config_hash", config_hash)
                    self._set_meta("created", repr(time.time()))
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"cannot open campaign store '{self.path}': {exc}") from None
        if stored is not None and stored != config_hash:
            try:
                changes = config_differences(json.loads(self.get_meta("config") or "{}"), config)
            except (ValueError, TypeError):
                changes = []
            shown = "; ".join(changes[:MAX_DIFFERENCES_SHOWN]) + (
                f"; and {len(changes) - MAX_DIFFERENCES_SHOWN} more" if len(changes) > MAX_DIFFERENCES_SHOWN else "")
            raise StoreError(
                f"campaign store '{self.path}' belongs to a different config"
                + (f": {shown}" if changes else f" (stored hash {stored[:12]}, this config {config_hash[:12]})")
                + ". Start it with the config it was started with, or give the new config a new storage file; to carry "
                "the results over, export them (gryffin-ros export STORE --json FILE) and report them to the new "
                "campaign (Campaign(..., accept_unsolicited=True).observe, or Planner.tell): each is checked against "
                "the new config")

    @classmethod
    def open_existing(cls, path: str | Path) -> CampaignStore:
        """Open a store written earlier (or being written by a running campaign) for reading, without a lock."""
        if not Path(path).is_file():
            raise StoreError(f"no campaign store at '{path}'")
        try:
            db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
            try:
                rows = dict(db.execute("SELECT key, value FROM meta WHERE key IN ('config', 'config_hash')"))
            finally:
                db.close()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"'{path}' is not a campaign store: {exc}") from None
        if set(rows) != {"config", "config_hash"}:
            raise StoreError(f"'{path}' is not a campaign store (no config recorded)")
        return cls(path, json.loads(rows["config"]), rows["config_hash"], readonly=True)

    @classmethod
    def molecule_values_at(cls, path: str | Path) -> dict[tuple[str, str], float]:
        """The RDKit values kept by the store at `path` (see `molecule_values`); none when there is no store there
        yet (read without the writer's lock: they never change once stored)."""
        if str(path) == ":memory:" or not Path(path).is_file():
            return {}
        try:
            store = cls.open_existing(path)
        except StoreError:
            return {}  # not a store: opening it as the writer says so
        try:
            return store.molecule_values()
        finally:
            store.close()

    @property
    def config(self) -> dict:
        """The config the store was created with."""
        return json.loads(self.get_meta("config") or "{}")

    # ---- low level -------------------------------------------------------------------------------------------
    @contextmanager
    def _transaction(self) -> Iterator[None]:
        if self.readonly:
            raise StoreError(f"campaign store '{self.path}' is open for reading only")
        with self._lock:
            self._db.execute("BEGIN IMMEDIATE")
            try:
                yield
            except BaseException:
                self._db.execute("ROLLBACK")
                raise
            self._db.execute("COMMIT")

    def _set_meta(self, key: str, value: str) -> None:
        self._db.execute("INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", (key, value))

    def _query(self, sql: str, args: tuple = ()) -> list[tuple]:
        with self._lock:
            return self._db.execute(sql, args).fetchall()

    def get_meta(self, key: str) -> str | None:
        rows = self._query("SELECT value FROM meta WHERE key = ?", (key,))
        return rows[0][0] if rows else None

    def set_meta(self, key: str, value: str) -> None:
        with self._transaction():
            self._set_meta(key, value)

    def close(self) -> None:
        with self._lock:
            if self._db is not None:
                self._db.close()
        self._release()

    def _release(self) -> None:
        if self._holder is not None:
            fcntl.flock(self._holder, fcntl.LOCK_UN)
            self._holder.close()
            self._holder = None

    # ---- campaign data ---------------------------------------------------------------------------------------
    def add_proposals(self, proposals: Iterable[Proposal], meta: dict[str, str] | None = None) -> None:
        """Store proposals, and meta values that go with them, in one transaction."""
        now = time.time()
        with self._transaction():
            self._db.executemany(
                "INSERT INTO proposals (experiment_id, params, strategy, created, meta) VALUES (?, ?, ?, ?, ?)",
                [(p.experiment_id, json.dumps(p.params), p.strategy, now, json.dumps(p.meta)) for p in proposals])
            for key, value in (meta or {}).items():
                self._set_meta(key, value)

    def add_observation(self, observation: Observation, raw: str | None = None) -> None:
        """Commit one observation; a second one with the same experiment_id raises StoreError."""
        try:
            with self._transaction():
                self._db.execute(
                    "INSERT INTO observations (experiment_id, params, objectives, meta, raw, received) "
                    "VALUES (?, ?, ?, ?, ?, ?)",
                    (observation.experiment_id, json.dumps(observation.params), json.dumps(observation.objectives),
                     json.dumps(observation.meta), raw, time.time()))
        except sqlite3.IntegrityError:
            raise StoreError(f"experiment_id '{observation.experiment_id}' was already reported") from None

    def add_rejection(self, experiment_id: str | None, reason: str, raw: str | None = None) -> None:
        """Record an observation that was refused (nothing of it enters the campaign): for the dashboard and audits."""
        with self._transaction():
            self._db.execute("INSERT INTO rejections (experiment_id, reason, raw, received) VALUES (?, ?, ?, ?)",
                             (experiment_id, reason, None if raw is None else raw[:REJECTED_RAW_CHARS], time.time()))

    def rejections(self, since: float | None = None) -> list[dict[str, Any]]:
        """Refused observations, oldest first (received at `since`, a time.time(), or later when given; none in a
        store written before they were recorded)."""
        try:
            rows = self._query("SELECT experiment_id, reason, received FROM rejections WHERE received >= ? ORDER BY "
                               "seq", (float("-inf") if since is None else since,))
        except sqlite3.OperationalError:
            return []
        return [{"experiment_id": eid, "reason": reason, "received": received} for eid, reason, received in rows]

    def proposals(self) -> list[Proposal]:
        return self._proposals("")

    def _proposals(self, where: str) -> list[Proposal]:
        rows = self._query(f"SELECT experiment_id, params, strategy, meta FROM proposals {where} "
                           "ORDER BY created, rowid")
        return [Proposal(eid, json.loads(params), strategy, json.loads(meta) if meta else {})
                for eid, params, strategy, meta in rows]

    def observations(self, skip: int = 0) -> list[Observation]:
        """The stored observations in arrival order, after the first `skip` of them."""
        rows = self._query("SELECT experiment_id, params, objectives, meta FROM observations ORDER BY seq "
                           "LIMIT -1 OFFSET ?", (int(skip),))
        return [Observation(json.loads(p), json.loads(o), eid, json.loads(m)) for eid, p, o, m in rows]

    def pending(self) -> list[Proposal]:
        """Proposals without an observation yet, oldest first."""
        return self._proposals("WHERE experiment_id NOT IN (SELECT experiment_id FROM observations)")

    def add_claims(self, experiment_ids: Iterable[str], instrument: str) -> None:
        """Record that these experiments were handed to `instrument` (kept across restarts)."""
        now = time.time()
        with self._transaction():
            self._db.executemany("INSERT OR REPLACE INTO claims (experiment_id, instrument, claimed) VALUES (?, ?, ?)",
                                 [(i, instrument, now) for i in experiment_ids])

    def claims(self) -> dict[str, str]:
        """Pending experiment id -> the instrument it was handed to (none in a store written before claims)."""
        try:
            rows = self._query("SELECT experiment_id, instrument FROM claims WHERE experiment_id NOT IN "
                               "(SELECT experiment_id FROM observations) ORDER BY claimed, rowid")
        except sqlite3.OperationalError:
            return {}
        return dict(rows)

    def raw(self, experiment_id: str) -> str | None:
        """The message an observation arrived in, as it arrived (None when it came through the Python API)."""
        rows = self._query("SELECT raw FROM observations WHERE experiment_id = ?", (experiment_id,))
        return rows[0][0] if rows else None

    def counts(self) -> tuple[int, int, int]:
        """(observations, proposals, rejections) stored: changes whenever the store does."""
        rows = self._query("SELECT (SELECT COUNT(*) FROM observations), (SELECT COUNT(*) FROM proposals)")
        try:
            rejected = self._query("SELECT COUNT(*) FROM rejections")[0][0]
        except sqlite3.OperationalError:  # a store written before rejections were kept
            rejected = 0
        return int(rows[0][0]), int(rows[0][1]), int(rejected)

    def count_observations(self) -> int:
        return self._query("SELECT COUNT(*) FROM observations")[0][0]

    def molecule_values(self) -> dict[tuple[str, str], float]:
        """What RDKit computed for the SMILES options of the config, by (SMILES, feature), so that a restarted
        campaign needs no RDKit work (none in a store written before molecules were kept)."""
        try:
            rows = self._query("SELECT smiles, feature, value FROM molecules")
        except sqlite3.OperationalError:
            return {}
        return {(smiles, feature): value for smiles, feature, value in rows}

    def add_molecule_values(self, values: dict[tuple[str, str], float]) -> None:
        if values:
            with self._transaction():
                self._db.executemany("INSERT OR REPLACE INTO molecules (smiles, feature, value) VALUES (?, ?, ?)",
                                     [(smiles, feature, value) for (smiles, feature), value in values.items()])

    # ---- export ---------------------------------------------------------------------------------------------
    def rows(self, digits: int | None = None) -> list[dict[str, Any]]:
        """One flat row per observation: seq, experiment_id, parameters and objectives (headers with the config's
        units), failed, the strategy and surrogate of the proposal it reports, then meta values. `digits`: numbers
        rounded to that many significant digits (None: as stored)."""
        config = self.config
        units = units_of(config)
        names = set(units)  # parameters and objectives: meta values of the same name are not repeated
        proposals = {p.experiment_id: p for p in self.proposals()}
        smiles = smiles_of(config)

        def show(value: Any) -> Any:
            if digits is not None and isinstance(value, float):
                return float(f"{value:.{digits}g}")
            return value

        out = []
        for seq, observation in enumerate(self.observations(), start=1):
            row: dict[str, Any] = {"seq": seq, "experiment_id": observation.experiment_id}
            for k, v in observation.params.items():
                row[label(k, units)] = show(v)
                if k in smiles:  # a molecule's structure beside its name
                    row[f"{k} SMILES"] = smiles[k].get(v, "")
            row.update({label(k, units): ("" if v is None else show(v)) for k, v in observation.objectives.items()})
            proposal = proposals.get(observation.experiment_id)
            row["failed"] = observation.failed
            row["strategy"] = "" if proposal is None or proposal.strategy is None else proposal.strategy
            row["surrogate"] = "" if proposal is None else proposal.meta.get("surrogate", "")
            row.update({k: show(v) for k, v in observation.meta.items()
                        if k not in row and k not in names and not isinstance(v, (dict, list))})
            out.append(row)
        return out

    def export_csv(self, path: str | Path, digits: int = 6) -> int:
        """The experiments as CSV (numbers to `digits` significant digits; the JSON export keeps every digit)."""
        rows = self.rows(digits)
        columns: list[str] = []
        for row in rows:
            columns.extend(k for k in row if k not in columns)
        with open(path, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=columns or ["seq", "experiment_id"])
            writer.writeheader()
            writer.writerows(rows)
        return len(rows)

    def export_json(self, path: str | Path) -> int:
        document = {
            "config": json.loads(self.get_meta("config") or "{}"),
            "proposals": [p.to_dict() for p in self.proposals()],
            "observations": [o.to_dict() for o in self.observations()],
        }
        Path(path).write_text(json.dumps(document, indent=2))
        return len(document["observations"])


MAX_DIFFERENCES_SHOWN = 5


def config_differences(stored: Any, given: Any, where: str = "") -> list[str]:
    """What differs between two configs, as `path: stored -> given` lines (lists of parameters, objectives and
    constraints are compared entry by entry, a parameter or objective found by its name)."""
    if isinstance(stored, dict) and isinstance(given, dict):
        out = []
        for key in list(stored) + [k for k in given if k not in stored]:
            path = f"{where}.{key}" if where else str(key)
            if key not in given:
                out.append(f"{path} removed (was {stored[key]!r})")
            elif key not in stored:
                out.append(f"{path} added ({given[key]!r})")
            else:
                out += config_differences(stored[key], given[key], path)
        return out
    if isinstance(stored, list) and isinstance(given, list):
        named = all(isinstance(e, dict) and "name" in e for e in stored + given)
        if named:
            old, new = {e["name"]: e for e in stored}, {e["name"]: e for e in given}
            return config_differences(old, new, where) + (
                [f"{where}: order changed"] if list(old) != list(new) and set(old) == set(new) else [])
        out = [line for i, (a, b) in enumerate(zip(stored, given)) if a != b
               for line in config_differences(a, b, f"{where}[{i}]")]
        if len(stored) != len(given):
            out.append(f"{where}: {len(stored)} entries -> {len(given)}")
        return out
    return [] if stored == given else [f"{where}: {stored!r} -> {given!r}"]
