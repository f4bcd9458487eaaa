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

/// The longest a log command may spend in SQLite queries in all (issue 33:
/// the deadline was per query, so a `.db3` made to be slow took minutes).
pub const DEADLINE: std::time::Duration = std::time::Duration::from_secs(60);

/// Opens a log: a `.btlog` (either layout), or a `.db3` (told by SQLite's
/// magic) at `session` (default: its last). `-` is stdin (a `.btlog`
/// only), read as it comes. A regular file is streamed; anything else (a
/// FIFO, a device) is read as `btfsm view` reads it, through
/// `format::source`: never blocking on a FIFO without writer, within
/// `--max-file-bytes`, a pipe silent for 10 s an error. A `.db3`'s queries
/// all stop at `deadline`, one instant for the whole command.
pub fn open(
    path: &Path,
    session: Option<i64>,
    limits: &btfsm_format::Limits,
    deadline: std::time::Instant,
) -> Result<OpenedLog, String> {
    let stdin = path.as_os_str() == "-";
    let r: Box<dyn Read> = if stdin {
        Box::new(std::io::stdin())
    } else {
        let meta = std::fs::metadata(path).map_err(|e| format!("cannot read this file: {e}"))?;
        if meta.is_dir() {
            return Err("cannot read this file: it is a directory".into());
        }
        if meta.is_file() {
            let f = std::fs::File::open(path).map_err(|e| format!("cannot read this file: {e}"))?;
            Box::new(f)
        } else {
            let shown = path.display().to_string();
            let bytes = btfsm_format::source::read_bytes(path, &shown, limits, false)
                .map_err(|d| d.first().map(|d| d.message.clone()).unwrap_or_default())?;
            if bytes.starts_with(b"SQLite format 3\0") {
                return Err("a .db3 log must be a regular file (SQLite reads it in place)".into());
            }
            Box::new(std::io::Cursor::new(bytes))
        }
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
    open_db3(path, session, limits, deadline)
}

#[cfg(feature = "sqlite")]
fn open_db3(
    path: &Path,
    session: Option<i64>,
    limits: &btfsm_format::Limits,
    deadline: std::time::Instant,
) -> Result<OpenedLog, String> {
    let o = db3::open(path, session, limits, deadline).map_err(|e| e.0)?;
    Ok(OpenedLog {
        reader: Box::new(o.stream),
        sessions: o.sessions,
        more_sessions: o.more_sessions,
        session: Some(o.session),
    })
}

#[cfg(not(feature = "sqlite"))]
fn open_db3(
    _: &Path,
    _: Option<i64>,
    _: &btfsm_format::Limits,
    _: std::time::Instant,
) -> Result<OpenedLog, String> {
    Err("a .db3 (SqliteLogger) log, and this btfsm was built without the `sqlite` feature".into())
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    /// fig01.btlog's header (BehaviorTree.CPP wrote it) and its records.
    fn fig01() -> (Vec<u8>, Vec<u8>) {
        let b = std::fs::read(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/fixtures/logs/fig01.btlog"
        ))
        .unwrap();
        let xml = i32::from_le_bytes(b[19..23].try_into().unwrap()) as usize;
        let (h, r) = b.split_at(23 + xml + 8);
        (h.to_vec(), r.to_vec())
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

        /// Records mutated, cut or appended never panic any log command:
        /// each reads them or says what is wrong.
        #[test]
        fn mutated_logs_never_panic(
            cut in 0usize..4000,
            flips in proptest::collection::vec((0usize..4000, any::<u8>()), 0..8),
            tail in proptest::collection::vec(any::<u8>(), 0..64),
        ) {
            let (h, mut r) = fig01();
            for (i, v) in flips {
                let n = r.len();
                r[i % n] = v;
            }
            r.truncate(cut.min(r.len()));
            r.extend(tail);
            let mut b = h;
            b.extend(r);
            let _ = super::report::report("t", &b[..], 1 << 20);
            let _ = super::timeline::timeline("t", || Ok(&b[..]), 1 << 20, 200);
            let _ = super::replay::replay(&b[..], super::replay::At::Step(50), &btfsm_format::Limits::default());
            let x = super::compare::open("a", std::io::Cursor::new(b.clone()), None, 1 << 20);
            let y = super::compare::open("b", std::io::Cursor::new(b.clone()), None, 1 << 20);
            if let (Ok(x), Ok(y)) = (x, y) {
                let c = super::compare::compare(x, y, None, false);
                if let Ok(c) = c {
                    prop_assert!(c.same, "a log is the same as itself");
                }
            }
        }
    }
}
