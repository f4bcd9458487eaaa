//! BehaviorTree.CPP execution logs (issue 18): `btlog.rs` reads
//! `FileLogger2` `.btlog` files as a stream (both record layouts), `tree.rs`
//! the tree a log embeds, `report.rs` per-node figures and node and branch
//! coverage (`btfsm log report`), `replay.rs` the statuses at a moment
//! (`btfsm log dot`), `actions.rs` the actions a log executed and
//! `compare.rs` the first divergence of two runs (`btfsm log compare`),
//! `timeline.rs` the SVG timeline (`btfsm log timeline`); `db3.rs` reads
//! `SqliteLogger` `.db3` files (cargo feature `sqlite`, on by default) as the
//! `.btlog` stream of one session, which [`open`] gives every command.

pub mod actions;
pub mod btlog;
pub mod compare;
#[cfg(feature = "sqlite")]
pub mod db3;
pub mod replay;
pub mod report;
pub mod timeline;
pub mod tree;

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// One logging session of a `.db3`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Session {
    pub id: i64,
    pub date: String,
}

/// A log opened for reading: its bytes in the `.btlog` layout, and for a
/// `.db3` its sessions and the one read.
pub struct OpenedLog {
    pub reader: Box<dyn Read>,
    pub sessions: Vec<Session>,
    pub more_sessions: bool,
    pub session: Option<i64>,
}

/// Opens a log: a `.btlog` (either layout), or a `.db3` (told by SQLite's
/// magic) at `session` (default: its last). `-` is stdin (a `.btlog` only).
pub fn open(path: &Path, session: Option<i64>, max_bytes: u64) -> Result<OpenedLog, String> {
    let stdin = path.as_os_str() == "-";
    let r: Box<dyn Read> = if stdin {
        Box::new(std::io::stdin())
    } else {
        let f = std::fs::File::open(path).map_err(|e| format!("cannot read this file: {e}"))?;
        if f.metadata().is_ok_and(|m| m.is_dir()) {
            return Err("cannot read this file: it is a directory".into());
        }
        Box::new(f)
    };
    let mut r = BufReader::with_capacity(1 << 16, r);
    let head = r.fill_buf().map_err(|e| format!("cannot read: {e}"))?;
    let sqlite = head.starts_with(b"SQLite format 3\0");
    let btlog = |reader| OpenedLog {
        reader,
        sessions: Vec::new(),
        more_sessions: false,
        session: None,
    };
    if !sqlite {
        if session.is_some() {
            return Err("--session is for a .db3 (SqliteLogger) log, and this is not one".into());
        }
        return Ok(btlog(Box::new(r)));
    }
    if stdin {
        return Err("a .db3 log must be a file, not stdin".into());
    }
    open_db3(path, session, max_bytes)
}

#[cfg(feature = "sqlite")]
fn open_db3(path: &Path, session: Option<i64>, max_bytes: u64) -> Result<OpenedLog, String> {
    let o = db3::open(path, session, max_bytes).map_err(|e| e.0)?;
    Ok(OpenedLog {
        reader: Box::new(o.stream),
        sessions: o.sessions,
        more_sessions: o.more_sessions,
        session: Some(o.session),
    })
}

#[cfg(not(feature = "sqlite"))]
fn open_db3(_: &Path, _: Option<i64>, _: u64) -> Result<OpenedLog, String> {
    Err("a .db3 (SqliteLogger) log, and this btfsm was built without the `sqlite` feature".into())
}
