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
//! The file is untrusted: opened read-only, `Definitions` and `Transitions`
//! must be tables (not views, whose queries the file would choose), values
//! are bounded by SQLite's length limit (the command's `--max-file-bytes`),
//! a query is interrupted after [`DEADLINE`], and transitions are read in
//! pages of [`PAGE`] rows by their row id: memory holds one page, whatever
//! the number of rows.

use super::Session;
use super::btlog::{MAGIC, Status};
use rusqlite::{Connection, OpenFlags, OptionalExtension, params};
use std::collections::BTreeSet;
use std::io::Read;
use std::path::Path;

/// Rows per query.
pub const PAGE: usize = 4096;
/// The longest any one query may run.
pub const DEADLINE: std::time::Duration = std::time::Duration::from_secs(60);
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
    last: Option<i64>,
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

/// Opens a `.db3` for session `session` (default: the last one).
pub fn open(path: &Path, session: Option<i64>, max_bytes: u64) -> Result<Opened, Db3Error> {
    open_within(path, session, max_bytes, DEADLINE)
}

/// [`open`] with every query interrupted after `deadline`.
fn open_within(
    path: &Path,
    session: Option<i64>,
    max_bytes: u64,
    deadline: std::time::Duration,
) -> Result<Opened, Db3Error> {
    let conn = connect(path, max_bytes, deadline)?;
    check_tables(&conn)?;
    let uid_col = uid_column(&conn)?;
    let (sessions, more_sessions) = list_sessions(&conn)?;
    let last: Option<i64> = conn
        .query_row("SELECT MAX(session_id) FROM Definitions", [], |r| r.get(0))
        .map_err(sql)?;
    let session = match (session, last) {
        (Some(s), _) => s,
        (None, Some(l)) => l,
        (None, None) => return Err(Db3Error("no session in table `Definitions`".into())),
    };
    let xml: Option<String> = conn
        .query_row(
            "SELECT xml_tree FROM Definitions WHERE session_id = ?1",
            [session],
            |r| r.get(0),
        )
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
    let q = "SELECT timestamp FROM Transitions WHERE session_id = ?1 ORDER BY timestamp LIMIT 1";
    let t0: Option<i64> = conn
        .query_row(q, [session], |r| r.get(0))
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
            last: None,
            buf,
            pos: 0,
            done: false,
        },
    })
}

/// Opens the database read-only, values bounded by `max_bytes`, every
/// query interrupted once `deadline` has passed from now.
fn connect(
    path: &Path,
    max_bytes: u64,
    deadline: std::time::Duration,
) -> Result<Connection, Db3Error> {
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    let conn = Connection::open_with_flags(path, flags).map_err(sql)?;
    let len = i32::try_from(max_bytes).unwrap_or(i32::MAX).max(1024);
    conn.set_limit(rusqlite::limits::Limit::SQLITE_LIMIT_LENGTH, len)
        .map_err(sql)?;
    let deadline = std::time::Instant::now() + deadline;
    conn.progress_handler(10_000, Some(move || std::time::Instant::now() > deadline))
        .map_err(sql)?;
    let _ = conn.execute_batch("PRAGMA trusted_schema = OFF;");
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

/// The name of the node column of `Transitions` (`uid`, or `node_uid` in
/// some 4.x releases), once its other columns are checked.
fn uid_column(conn: &Connection) -> Result<&'static str, Db3Error> {
    let mut cols = Vec::new();
    {
        let mut st = conn
            .prepare("SELECT name FROM pragma_table_info('Transitions')")
            .map_err(sql)?;
        let rows = st.query_map([], |r| r.get::<_, String>(0)).map_err(sql)?;
        for c in rows.take(64) {
            cols.push(c.map_err(sql)?);
        }
    }
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
    Ok(uid_col)
}

/// The sessions of `Definitions`, at most [`MAX_SESSIONS_LISTED`], and
/// whether there are more.
fn list_sessions(conn: &Connection) -> Result<(Vec<Session>, bool), Db3Error> {
    let mut sessions = Vec::new();
    let mut more_sessions = false;
    let mut st = conn
        .prepare("SELECT session_id, date FROM Definitions ORDER BY session_id")
        .map_err(sql)?;
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

impl Db3Stream {
    /// The next page of transitions, encoded as 9-byte records.
    fn page(&mut self) -> Result<(), Db3Error> {
        self.buf.clear();
        self.pos = 0;
        let q = format!(
            "SELECT timestamp, {}, state FROM Transitions WHERE session_id = ?1 AND timestamp > ?2 ORDER BY timestamp LIMIT {PAGE}",
            self.uid_col
        );
        let mut st = self.conn.prepare_cached(&q).map_err(sql)?;
        let mut rows = st
            .query(params![self.session, self.last.unwrap_or(i64::MIN)])
            .map_err(sql)?;
        let mut n = 0;
        while let Some(r) = rows.next().map_err(sql)? {
            n += 1;
            let ts: i64 = r
                .get(0)
                .map_err(|e| Db3Error(format!("a transition's timestamp: {e}")))?;
            let at = |what: String| {
                Db3Error(format!(
                    "session {}, transition at timestamp {ts}: {what}",
                    self.session
                ))
            };
            let uid: i64 = r.get(1).map_err(|e| at(format!("its uid: {e}")))?;
            let state: i64 = r.get(2).map_err(|e| at(format!("its state: {e}")))?;
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
            let off = u64::try_from(ts - self.t0)
                .ok()
                .filter(|&o| o < 1 << 48)
                .ok_or_else(|| at("more than 2^48 µs after the first".into()))?;
            self.buf.extend(&off.to_le_bytes()[..6]);
            self.buf.extend(uid.to_le_bytes());
            self.buf.push(status as u8);
            self.last = Some(ts);
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
        let e = match open_within(&p, None, 1 << 20, std::time::Duration::ZERO) {
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
}
