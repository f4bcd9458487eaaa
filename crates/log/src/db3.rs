//! BehaviorTree.CPP 4 `SqliteLogger` logs (`.db3`), read as the `.btlog`
//! stream of one session, so that every `btfsm log` command reads both.
//!
//! The schema, from BehaviorTree.CPP's `src/loggers/bt_sqlite_logger.cpp`
//! (read at commit 0ce11efc03ea35052f4b517adecbc7a67488a7a2, 4.x):
//! - `Definitions(session_id INTEGER PRIMARY KEY AUTOINCREMENT, date TEXT,
//!   xml_tree TEXT)`: one row per logger created, the tree as
//!   `WriteTreeToXML` writes it (with `_uid`s, as in a `.btlog`);
//! - `Nodes(session_id, fullpath, uid)`: not needed here;
//! - `Transitions(timestamp INTEGER PRIMARY KEY, session_id, uid, duration,
//!   state, metadata)`: one row per status change; `timestamp` is µs since
//!   the epoch, made strictly increasing by the logger (the row id);
//!   `state` 0 to 4 as in a `.btlog`. Some 4.x releases call the column
//!   `node_uid` (the header's comment does): both are read.
//!
//! The file is untrusted (issue 33): it is at most `--max-file-bytes`
//! (charged to the command's read budget); it is opened read-only and
//! immutable (`immutable=1`: no lock, no `-shm` or `-wal` created beside
//! it, and a WAL file left by a logger still running is not read);
//! `Definitions` and `Transitions` must be tables (not views, whose queries
//! the file would choose); values are bounded by SQLite's length limit (the
//! command's `--max-file-bytes`); every query stops at one deadline for the
//! whole command; and the plan of every query is the same whatever indexes
//! the file declares: tables are read `NOT INDEXED`, in row-id order, in
//! pages of [`PAGE`] rows by row id (a seek in the table's own b-tree, so
//! reading a session is one pass over the table, whatever its size, and
//! memory holds one page). The logger's `timestamp` is the row id and
//! increases with it; a transition whose time goes backwards is an error.

use super::Session;
use super::btlog::{MAGIC, Status};
use rusqlite::{Connection, OpenFlags, OptionalExtension, params};
use std::collections::BTreeSet;
use std::io::Read;
use std::path::Path;

/// Rows per query.
pub const PAGE: usize = 4096;
/// The first bytes of an SQLite database file.
pub const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";

/// The sessions listed at most.
pub const MAX_SESSIONS_LISTED: usize = 1000;

/// What is wrong with a `.db3`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Db3Error(pub String);

fn sql(e: rusqlite::Error) -> Db3Error {
    Db3Error(format!("not a readable SqliteLogger database: {e}"))
}

/// A session of a `.db3` as a `.btlog` byte stream (protocol 1).
pub struct Db3Stream {
    conn: Connection,
    session: i64,
    t0: i64,
    uids: BTreeSet<u16>,
    uid_col: &'static str,
    /// The name of the row id (`rowid`, `_rowid_` or `oid`: one the table
    /// does not use for a column).
    rowid: &'static str,
    /// The row id and the timestamp of the last transition read.
    last: Option<(i64, i64)>,
    buf: Vec<u8>,
    pos: usize,
    done: bool,
}

/// The sessions of a `.db3` (at most [`MAX_SESSIONS_LISTED`]), the one
/// chosen (`session`, or the last), and its stream.
pub struct Opened {
    pub sessions: Vec<Session>,
    pub more_sessions: bool,
    pub session: i64,
    pub stream: Db3Stream,
}

/// Opens a `.db3` for session `session` (default: the last one); every
/// query stops at `deadline`.
pub fn open(
    path: &Path,
    session: Option<i64>,
    limits: &btfsm_format::Limits,
    deadline: std::time::Instant,
) -> Result<Opened, Db3Error> {
    let len = std::fs::metadata(path)
        .map_err(|e| Db3Error(format!("cannot read this file: {e}")))?
        .len();
    if len > limits.max_file_bytes {
        return Err(Db3Error(format!(
            "a .db3 of {len} bytes, more than the limit of {} bytes (raise it with --max-file-bytes)",
            limits.max_file_bytes
        )));
    }
    if !limits.read_budget.charge(len) {
        return Err(Db3Error(format!(
            "a .db3 of {len} bytes, more than what remains of the {} bytes this command may read (raise it with --max-total-bytes)",
            limits.read_budget.limit()
        )));
    }
    open_within(path, session, limits.max_file_bytes, deadline)
}

/// [`open`] once the file's size is checked.
fn open_within(
    path: &Path,
    session: Option<i64>,
    max_bytes: u64,
    deadline: std::time::Instant,
) -> Result<Opened, Db3Error> {
    let conn = connect(path, max_bytes, deadline)?;
    check_tables(&conn)?;
    let (uid_col, rowid) = transition_columns(&conn)?;
    let def_rowid = free_rowid(&columns(&conn, "Definitions")?)
        .ok_or_else(|| Db3Error("table `Definitions` has no row id".into()))?;
    let (sessions, more_sessions) = list_sessions(&conn, def_rowid)?;
    let last: Option<i64> = conn
        .query_row(
            "SELECT MAX(session_id) FROM Definitions NOT INDEXED",
            [],
            |r| r.get(0),
        )
        .map_err(sql)?;
    let session = match (session, last) {
        (Some(s), _) => s,
        (None, Some(l)) => l,
        (None, None) => return Err(Db3Error("no session in table `Definitions`".into())),
    };
    let q = format!(
        "SELECT xml_tree FROM Definitions NOT INDEXED WHERE session_id = ?1 ORDER BY {def_rowid} LIMIT 1"
    );
    let xml: Option<String> = conn
        .query_row(&q, [session], |r| r.get(0))
        .optional()
        .map_err(sql)?;
    let Some(xml) = xml else {
        let ids: Vec<String> = sessions.iter().map(|s| s.id.to_string()).collect();
        return Err(Db3Error(format!(
            "no session {session} (the sessions are {})",
            ids.join(", ")
        )));
    };
    let tree = super::tree::parse(&xml).map_err(|e| Db3Error(format!("session {session}: {e}")))?;
    let t0: Option<i64> = conn
        .query_row(&first_query(rowid), [session], |r| r.get(0))
        .optional()
        .map_err(sql)?;
    let t0 = t0.unwrap_or(0);
    let mut buf = MAGIC.to_vec();
    buf.push(1);
    buf.extend((xml.len() as i32).to_le_bytes());
    buf.extend(xml.as_bytes());
    buf.extend(t0.to_le_bytes());
    Ok(Opened {
        sessions,
        more_sessions,
        session,
        stream: Db3Stream {
            conn,
            session,
            t0,
            uids: tree.nodes.keys().copied().collect(),
            uid_col,
            rowid,
            last: None,
            buf,
            pos: 0,
            done: false,
        },
    })
}

/// `file:` URI of `path` (absolute, every byte but unreserved ones as
/// `%HH`), read-only and immutable.
fn uri(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut u = String::from("file:");
    for &b in abs.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"/._-~".contains(&b) {
            u.push(b as char);
        } else {
            u.push_str(&format!("%{b:02X}"));
        }
    }
    u.push_str("?mode=ro&immutable=1");
    u
}

/// Opens the database read-only and immutable (nothing created beside it),
/// values bounded by `max_bytes`, every query interrupted once `deadline`
/// has passed.
fn connect(
    path: &Path,
    max_bytes: u64,
    deadline: std::time::Instant,
) -> Result<Connection, Db3Error> {
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY
        | OpenFlags::SQLITE_OPEN_NO_MUTEX
        | OpenFlags::SQLITE_OPEN_URI;
    let conn = Connection::open_with_flags(uri(path), flags).map_err(sql)?;
    let len = i32::try_from(max_bytes).unwrap_or(i32::MAX).max(1024);
    conn.set_limit(rusqlite::limits::Limit::SQLITE_LIMIT_LENGTH, len)
        .map_err(sql)?;
    conn.progress_handler(10_000, Some(move || std::time::Instant::now() > deadline))
        .map_err(sql)?;
    let _ = conn.execute_batch("PRAGMA trusted_schema = OFF; PRAGMA query_only = ON;");
    Ok(conn)
}

/// Checks that `Definitions` and `Transitions` are tables (not views).
fn check_tables(conn: &Connection) -> Result<(), Db3Error> {
    for t in ["Definitions", "Transitions"] {
        let kind: Option<String> = conn
            .query_row("SELECT type FROM sqlite_master WHERE name = ?1", [t], |r| {
                r.get(0)
            })
            .optional()
            .map_err(sql)?;
        match kind.as_deref() {
            Some("table") => {}
            Some(k) => {
                return Err(Db3Error(format!(
                    "`{t}` is a {}, not a table: not a SqliteLogger database",
                    btfsm_core::sanitize::shown(k)
                )));
            }
            None => {
                return Err(Db3Error(format!(
                    "no table `{t}`: not a BehaviorTree.CPP 4 SqliteLogger database (tables Definitions, Nodes, Transitions)"
                )));
            }
        }
    }
    Ok(())
}

/// The column names of table `t` (at most 64).
fn columns(conn: &Connection, t: &str) -> Result<Vec<String>, Db3Error> {
    let mut cols = Vec::new();
    let mut st = conn
        .prepare("SELECT name FROM pragma_table_info(?1)")
        .map_err(sql)?;
    let rows = st.query_map([t], |r| r.get::<_, String>(0)).map_err(sql)?;
    for c in rows.take(64) {
        cols.push(c.map_err(sql)?);
    }
    Ok(cols)
}

/// A name of the row id that no column of the table shadows.
fn free_rowid(cols: &[String]) -> Option<&'static str> {
    ["rowid", "_rowid_", "oid"]
        .into_iter()
        .find(|r| !cols.iter().any(|c| c.eq_ignore_ascii_case(r)))
}

/// The name of the node column of `Transitions` (`uid`, or `node_uid` in
/// some 4.x releases) and of its row id, once its other columns are
/// checked.
fn transition_columns(conn: &Connection) -> Result<(&'static str, &'static str), Db3Error> {
    let cols = columns(conn, "Transitions")?;
    let has = |c: &str| cols.iter().any(|x| x == c);
    let uid_col = if has("uid") {
        "uid"
    } else if has("node_uid") {
        "node_uid"
    } else {
        return Err(Db3Error(
            "table `Transitions` has no column `uid` (or `node_uid`)".into(),
        ));
    };
    for c in ["timestamp", "session_id", "state"] {
        if !has(c) {
            return Err(Db3Error(format!(
                "table `Transitions` has no column `{c}` (BehaviorTree.CPP 3's logger has none: a 4.x .db3 is needed)"
            )));
        }
    }
    let rowid =
        free_rowid(&cols).ok_or_else(|| Db3Error("table `Transitions` has no row id".into()))?;
    Ok((uid_col, rowid))
}

/// The sessions of `Definitions` in row order, at most
/// [`MAX_SESSIONS_LISTED`], and whether there are more.
fn list_sessions(conn: &Connection, rowid: &str) -> Result<(Vec<Session>, bool), Db3Error> {
    let mut sessions = Vec::new();
    let mut more_sessions = false;
    let q = format!(
        "SELECT session_id, date FROM Definitions NOT INDEXED ORDER BY {rowid} LIMIT {}",
        MAX_SESSIONS_LISTED + 1
    );
    let mut st = conn.prepare(&q).map_err(sql)?;
    let mut rows = st.query([]).map_err(sql)?;
    while let Some(r) = rows.next().map_err(sql)? {
        if sessions.len() == MAX_SESSIONS_LISTED {
            more_sessions = true;
            break;
        }
        sessions.push(Session {
            id: r.get(0).map_err(sql)?,
            date: r
                .get::<_, Option<String>>(1)
                .map_err(sql)?
                .unwrap_or_default(),
        });
    }
    Ok((sessions, more_sessions))
}

/// The time of a session's first transition.
fn first_query(rowid: &str) -> String {
    format!(
        "SELECT timestamp FROM Transitions NOT INDEXED WHERE session_id = ?1 ORDER BY {rowid} LIMIT 1"
    )
}

/// One page of a session's transitions after a row id: a seek in the
/// table's b-tree by row id, whatever indexes the file declares.
fn page_query(rowid: &str, uid_col: &str) -> String {
    format!(
        "SELECT {rowid}, timestamp, {uid_col}, state FROM Transitions NOT INDEXED WHERE session_id = ?1 AND {rowid} > ?2 ORDER BY {rowid} LIMIT {PAGE}"
    )
}

impl Db3Stream {
    /// The next page of transitions, encoded as 9-byte records.
    fn page(&mut self) -> Result<(), Db3Error> {
        self.buf.clear();
        self.pos = 0;
        let q = page_query(self.rowid, self.uid_col);
        let mut st = self.conn.prepare_cached(&q).map_err(sql)?;
        let after = self.last.map_or(i64::MIN, |(row, _)| row);
        let mut rows = st.query(params![self.session, after]).map_err(sql)?;
        let mut n = 0;
        while let Some(r) = rows.next().map_err(sql)? {
            n += 1;
            let row: i64 = r.get(0).map_err(sql)?;
            let ts: i64 = r
                .get(1)
                .map_err(|e| Db3Error(format!("a transition's timestamp: {e}")))?;
            let at = |what: String| {
                Db3Error(format!(
                    "session {}, transition at timestamp {ts}: {what}",
                    self.session
                ))
            };
            if let Some((_, before)) = self.last
                && ts < before
            {
                return Err(at(format!(
                    "time goes backwards (the transition before is at {before}; SqliteLogger writes them in order)"
                )));
            }
            let uid: i64 = r.get(2).map_err(|e| at(format!("its uid: {e}")))?;
            let state: i64 = r.get(3).map_err(|e| at(format!("its state: {e}")))?;
            let uid = u16::try_from(uid)
                .ok()
                .filter(|u| self.uids.contains(u))
                .ok_or_else(|| {
                    at(format!(
                        "node uid {uid}, which the session's tree does not have"
                    ))
                })?;
            let status = u8::try_from(state)
                .ok()
                .and_then(Status::from_u8)
                .ok_or_else(|| {
                    at(format!(
                        "state {state} (0 to 4: IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED)"
                    ))
                })?;
            let off = ts
                .checked_sub(self.t0)
                .and_then(|o| u64::try_from(o).ok())
                .filter(|&o| o < 1 << 48)
                .ok_or_else(|| at("more than 2^48 µs after the first".into()))?;
            self.buf.extend(&off.to_le_bytes()[..6]);
            self.buf.extend(uid.to_le_bytes());
            self.buf.push(status as u8);
            self.last = Some((row, ts));
        }
        if n < PAGE {
            self.done = true;
        }
        Ok(())
    }
}

impl Read for Db3Stream {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.pos == self.buf.len() {
            if self.done {
                return Ok(0);
            }
            self.page().map_err(|e| std::io::Error::other(e.0))?;
        }
        let n = out.len().min(self.buf.len() - self.pos);
        out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const XML: &str = r#"<root BTCPP_format="4"><BehaviorTree ID="M" _fullpath=""><Sequence _uid="1"><Go _uid="2"/></Sequence></BehaviorTree></root>"#;

    fn db(path: &Path, rows: &[(i64, i64, i64, i64)]) {
        let c = Connection::open(path).unwrap();
        c.execute_batch(
            "CREATE TABLE Transitions (timestamp INTEGER PRIMARY KEY NOT NULL, session_id INTEGER NOT NULL, uid INTEGER NOT NULL, duration INTEGER, state INTEGER NOT NULL, metadata VARCHAR);
             CREATE TABLE Nodes (session_id INTEGER NOT NULL, fullpath VARCHAR, uid INTEGER NOT NULL);
             CREATE TABLE Definitions (session_id INTEGER PRIMARY KEY AUTOINCREMENT, date TEXT NOT NULL, xml_tree TEXT NOT NULL);",
        )
        .unwrap();
        for s in [1, 2] {
            c.execute(
                "INSERT INTO Definitions (date, xml_tree) VALUES (?1, ?2)",
                params![format!("2026-01-0{s} 10:00:00"), XML],
            )
            .unwrap();
        }
        c.execute_batch("BEGIN").unwrap();
        for &(ts, s, u, st) in rows {
            c.execute(
                "INSERT INTO Transitions VALUES (?1, ?2, ?3, 0, ?4, NULL)",
                params![ts, s, u, st],
            )
            .unwrap();
        }
        c.execute_batch("COMMIT").unwrap();
    }

    fn open(p: &Path, session: Option<i64>, _: u64) -> Result<Opened, Db3Error> {
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        super::open(p, session, &btfsm_format::Limits::default(), deadline)
    }

    fn records(o: Opened) -> Result<Vec<super::super::btlog::Record>, String> {
        let mut r = std::io::BufReader::new(o.stream);
        let h = super::super::btlog::read_header(&mut r, 1 << 20).map_err(|e| e.to_string())?;
        super::super::btlog::Records::new(r, &h)
            .map(|x| x.map_err(|e| e.to_string()))
            .collect()
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("btfsm-db3-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d.join("t.db3")
    }

    #[test]
    fn a_session_streams_as_a_btlog_in_pages() {
        let p = scratch("pages");
        // Session 2 has more rows than a page, interleaved with session 1's.
        let mut rows = Vec::new();
        for i in 0..(PAGE as i64 + 10) {
            rows.push((1_000 + 2 * i, 2, 1 + i % 2, 1 + i % 3));
            rows.push((1_001 + 2 * i, 1, 2, 2));
        }
        db(&p, &rows);
        let o = open(&p, None, 1 << 20).unwrap();
        assert_eq!(o.session, 2, "the last session by default");
        assert_eq!(o.sessions.len(), 2);
        let mut r = std::io::BufReader::new(o.stream);
        let h = super::super::btlog::read_header(&mut r, 1 << 20).unwrap();
        assert_eq!(h.t0_usec, 1_000);
        let recs: Vec<_> = super::super::btlog::Records::new(r, &h)
            .map(Result::unwrap)
            .collect();
        assert_eq!(recs.len(), PAGE + 10);
        assert_eq!((recs[3].t_usec, recs[3].uid), (6, 2));
        // Every query runs under the deadline: with none left, reading the
        // transitions is interrupted (an error, not a hang).
        let mut out = Vec::new();
        let e = match open_within(&p, None, 1 << 20, std::time::Instant::now()) {
            Ok(mut o) => o.stream.read_to_end(&mut out).unwrap_err().to_string(),
            Err(e) => e.0,
        };
        assert!(e.contains("interrupted"), "{e}");
        std::fs::remove_dir_all(p.parent().unwrap()).unwrap();
    }

    #[test]
    fn a_foreign_or_broken_database_is_an_error() {
        let p = scratch("bad");
        db(&p, &[(5, 1, 9, 1)]);
        let o = open(&p, Some(1), 1 << 20).unwrap();
        let mut s = Vec::new();
        let e = std::io::BufReader::new(o.stream).read_to_end(&mut s);
        assert!(e.is_err());
        let e = open(&p, Some(7), 1 << 20).err().unwrap();
        assert!(e.0.contains("no session 7 (the sessions are 1, 2)"), "{e}");
        let c = Connection::open(&p).unwrap();
        c.execute_batch("DROP TABLE Transitions; CREATE VIEW Transitions AS SELECT 1;")
            .unwrap();
        drop(c);
        let e = open(&p, None, 1 << 20).err().unwrap();
        assert!(e.0.contains("`Transitions` is a view"), "{e}");
        std::fs::write(&p, b"SQLite format 3\0garbage").unwrap();
        assert!(open(&p, None, 1 << 20).is_err());
        std::fs::remove_dir_all(p.parent().unwrap()).unwrap();
    }

    /// A file whose `timestamp` is not the row id, with indexes of its
    /// own: each page is still a seek by row id (no index, no sort), so a
    /// session is read in one pass; its time going backwards is an error.
    #[test]
    fn the_plan_ignores_the_files_indexes_and_time_must_not_go_back() {
        let p = scratch("plan");
        let c = Connection::open(&p).unwrap();
        c.execute_batch(
            "CREATE TABLE Transitions (timestamp INTEGER NOT NULL, session_id INTEGER, uid INTEGER, duration INTEGER, state INTEGER, metadata VARCHAR);
             CREATE INDEX by_ts ON Transitions (timestamp, session_id);
             CREATE INDEX by_session ON Transitions (session_id, uid);
             CREATE TABLE Definitions (session_id INTEGER, date TEXT, xml_tree TEXT);
             CREATE INDEX by_id ON Definitions (session_id);",
        )
        .unwrap();
        c.execute("INSERT INTO Definitions VALUES (1, 'd', ?1)", [XML])
            .unwrap();
        for (plan_of, seek) in [
            (page_query("rowid", "uid"), true),
            (first_query("rowid"), false),
        ] {
            let mut st = c.prepare(&format!("EXPLAIN QUERY PLAN {plan_of}")).unwrap();
            let plan: Vec<String> = st
                .query_map(
                    rusqlite::params_from_iter(if seek { vec![1, 0] } else { vec![1] }),
                    |r| r.get::<_, String>(3),
                )
                .unwrap()
                .map(Result::unwrap)
                .collect();
            let plan = plan.join("; ");
            assert!(!plan.contains("INDEX") && !plan.contains("TEMP"), "{plan}");
            assert!(!seek || plan.contains("rowid>?"), "{plan}");
        }
        for (ts, st) in [(10, 1), (20, 2), (15, 1)] {
            c.execute(
                "INSERT INTO Transitions VALUES (?1, 1, 2, 0, ?2, NULL)",
                params![ts, st],
            )
            .unwrap();
        }
        drop(c);
        let e = records(open(&p, None, 0).unwrap()).unwrap_err();
        assert!(e.contains("time goes backwards"), "{e}");
        std::fs::remove_dir_all(p.parent().unwrap()).unwrap();
    }

    /// A WAL-mode database is read without anything created beside it (no
    /// `-shm`, no `-wal`), and a `.db3` past `--max-file-bytes` is refused.
    #[test]
    fn a_wal_database_is_read_in_place_and_the_size_is_bounded() {
        let p = scratch("wal");
        db(&p, &[(5, 1, 1, 1), (6, 1, 1, 2)]);
        let c = Connection::open(&p).unwrap();
        c.query_row("PRAGMA journal_mode = WAL", [], |_| Ok(()))
            .unwrap();
        drop(c);
        let dir = p.parent().unwrap();
        let names = || {
            let mut v: Vec<String> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        assert_eq!(names(), ["t.db3"]);
        let o = open(&p, Some(1), 0).unwrap();
        assert_eq!(records(o).unwrap().len(), 2);
        assert_eq!(names(), ["t.db3"], "files created beside the log");
        let small = btfsm_format::Limits {
            max_file_bytes: 100,
            ..Default::default()
        };
        let e = super::open(&p, None, &small, std::time::Instant::now())
            .err()
            .unwrap();
        assert!(e.0.contains("--max-file-bytes"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
