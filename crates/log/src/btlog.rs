//! BehaviorTree.CPP 4 `FileLogger2` logs (`.btlog`), read as a stream.
//!
//! Layout (little-endian; BehaviorTree.CPP's `src/loggers/bt_file_logger_v2.cpp`):
//! - current (protocol 1): the 18 bytes `BTCPP4-FileLogger2`, one protocol
//!   byte (1), an `i32` XML length, the tree XML (`WriteTreeToXML` with
//!   `_uid` attributes and the nodes model), an `i64` first timestamp
//!   (µs since the epoch), then 9-byte records: a 48-bit offset in µs from
//!   the first timestamp, a `u16` node UID, a `u8` status (0 IDLE, 1
//!   RUNNING, 2 SUCCESS, 3 FAILURE, 4 SKIPPED);
//! - older releases (4.0 to 4.3): no magic and no protocol byte, and 8-byte
//!   records, one `u64` holding the offset (bits 0-44), the UID (45-60) and
//!   the status (61-63).
//!
//! Every record is accounted for: a record cut short at the end, a status
//! out of range, an XML length past the file's, a time earlier than the
//! record before (the logger writes them in order; figures computed over
//! time going backwards would be wrong), all are errors with the byte
//! offset. Memory holds the header and one record, whatever the log's size.

use std::io::Read;

/// The magic of the current layout.
pub const MAGIC: &[u8] = b"BTCPP4-FileLogger2";

/// Which record layout a log uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// Magic, protocol 1, 9-byte records.
    Protocol1,
    /// No magic, 8-byte bit-field records.
    Legacy,
}

/// A node status as BehaviorTree.CPP numbers it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum Status {
    Idle,
    Running,
    Success,
    Failure,
    Skipped,
}

impl Status {
    pub fn from_u8(v: u8) -> Option<Status> {
        Some(match v {
            0 => Status::Idle,
            1 => Status::Running,
            2 => Status::Success,
            3 => Status::Failure,
            4 => Status::Skipped,
            _ => return None,
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Status::Idle => "IDLE",
            Status::Running => "RUNNING",
            Status::Success => "SUCCESS",
            Status::Failure => "FAILURE",
            Status::Skipped => "SKIPPED",
        }
    }
}

/// A status change of one node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// µs since the log's first timestamp.
    pub t_usec: u64,
    pub uid: u16,
    pub status: Status,
}

/// What is wrong with a log, and where.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LogError {
    #[error("byte {offset}: the log ends inside {what}")]
    Truncated { offset: u64, what: &'static str },
    #[error("byte {offset}: {what}")]
    Bad { offset: u64, what: String },
    #[error("cannot read the log: {0}")]
    Io(String),
    /// A bound of the output reached (not a fault of the log's bytes).
    #[error("{0}")]
    Limit(String),
}

/// A log's header: its layout, tree XML and first timestamp, and where its
/// records start.
#[derive(Debug, Clone)]
pub struct Header {
    pub layout: Layout,
    pub xml: String,
    pub t0_usec: i64,
    pub records_at: u64,
}

/// Reads exactly `buf.len()` bytes, or says what was cut short.
fn fill(r: &mut impl Read, buf: &mut [u8], at: u64, what: &'static str) -> Result<(), LogError> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => {
                return Err(LogError::Truncated {
                    offset: at + got as u64,
                    what,
                });
            }
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(LogError::Io(e.to_string())),
        }
    }
    Ok(())
}

/// Reads the header; the XML may be at most `max_xml` bytes.
pub fn read_header(r: &mut impl Read, max_xml: u64) -> Result<Header, LogError> {
    let mut first = [0u8; 4];
    fill(r, &mut first, 0, "the header")?;
    let (layout, mut at, len_bytes) = if first == MAGIC[..4] {
        let mut rest = [0u8; 14 + 1 + 4];
        fill(r, &mut rest, 4, "the header")?;
        if rest[..14] != MAGIC[4..] {
            return Err(LogError::Bad {
                offset: 0,
                what:
                    "not a BehaviorTree.CPP FileLogger2 log (the magic is not `BTCPP4-FileLogger2`)"
                        .into(),
            });
        }
        if rest[14] != 1 {
            return Err(LogError::Bad {
                offset: 18,
                what: format!("protocol {} (this reader knows protocol 1)", rest[14]),
            });
        }
        (
            Layout::Protocol1,
            23u64,
            [rest[15], rest[16], rest[17], rest[18]],
        )
    } else {
        (Layout::Legacy, 4u64, first)
    };
    let len = i32::from_le_bytes(len_bytes);
    if len < 0 || len as u64 > max_xml {
        return Err(LogError::Bad {
            offset: at - 4,
            what: format!("tree XML of {len} bytes (at most {max_xml}: --max-file-bytes)"),
        });
    }
    let mut xml = vec![0u8; len as usize];
    fill(r, &mut xml, at, "the tree XML")?;
    let xml = String::from_utf8(xml).map_err(|e| LogError::Bad {
        offset: at + e.utf8_error().valid_up_to() as u64,
        what: "the tree XML is not UTF-8".into(),
    })?;
    at += len as u64;
    let mut t0 = [0u8; 8];
    fill(r, &mut t0, at, "the first timestamp")?;
    at += 8;
    Ok(Header {
        layout,
        xml,
        t0_usec: i64::from_le_bytes(t0),
        records_at: at,
    })
}

/// The records after a header, one at a time.
pub struct Records<R> {
    r: R,
    layout: Layout,
    at: u64,
    done: bool,
    /// The time of the record before.
    last_t: u64,
}

impl<R: Read> Records<R> {
    pub fn new(r: R, h: &Header) -> Self {
        Records {
            r,
            layout: h.layout,
            at: h.records_at,
            done: false,
            last_t: 0,
        }
    }

    /// The byte offset of the next record.
    pub fn offset(&self) -> u64 {
        self.at
    }
}

impl<R: Read> Iterator for Records<R> {
    type Item = Result<Record, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let size = match self.layout {
            Layout::Protocol1 => 9,
            Layout::Legacy => 8,
        };
        let mut buf = [0u8; 9];
        // The first byte tells the end of the log from a record cut short.
        match self.r.read(&mut buf[..1]) {
            Ok(0) => {
                self.done = true;
                return None;
            }
            Ok(_) => {}
            Err(e) => {
                self.done = true;
                return Some(Err(LogError::Io(e.to_string())));
            }
        }
        if let Err(e) = fill(&mut self.r, &mut buf[1..size], self.at + 1, "a record") {
            self.done = true;
            return Some(Err(match e {
                LogError::Truncated { .. } => LogError::Truncated {
                    offset: self.at,
                    what: "a record",
                },
                other => other,
            }));
        }
        let (t_usec, uid, raw) = match self.layout {
            Layout::Protocol1 => {
                let mut t = [0u8; 8];
                t[..6].copy_from_slice(&buf[..6]);
                (
                    u64::from_le_bytes(t),
                    u16::from_le_bytes([buf[6], buf[7]]),
                    buf[8],
                )
            }
            Layout::Legacy => {
                let mut v = [0u8; 8];
                v.copy_from_slice(&buf[..8]);
                let v = u64::from_le_bytes(v);
                (
                    v & ((1 << 45) - 1),
                    ((v >> 45) & 0xffff) as u16,
                    (v >> 61) as u8,
                )
            }
        };
        let at = self.at;
        self.at += size as u64;
        if t_usec < self.last_t {
            self.done = true;
            return Some(Err(LogError::Bad {
                offset: at,
                what: format!(
                    "time goes backwards: node {uid} at {t_usec} µs after a record at {} µs (FileLogger2 writes its records in time order)",
                    self.last_t
                ),
            }));
        }
        self.last_t = t_usec;
        match Status::from_u8(raw) {
            Some(status) => Some(Ok(Record {
                t_usec,
                uid,
                status,
            })),
            None => {
                self.done = true;
                Some(Err(LogError::Bad {
                    offset: at,
                    what: format!(
                        "status {raw} of node {uid} (0 to 4: IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED)"
                    ),
                }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v1(xml: &str, records: &[(u64, u16, u8)]) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend((xml.len() as i32).to_le_bytes());
        b.extend(xml.as_bytes());
        b.extend(1_700_000_000_000_000i64.to_le_bytes());
        for &(t, u, s) in records {
            b.extend(&t.to_le_bytes()[..6]);
            b.extend(u.to_le_bytes());
            b.push(s);
        }
        b
    }

    #[test]
    fn both_layouts_are_read_record_by_record() {
        let b = v1("<root/>", &[(5, 1, 1), (9, 1, 2)]);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        assert_eq!(
            (h.layout, h.xml.as_str(), h.records_at),
            (Layout::Protocol1, "<root/>", 38)
        );
        let recs: Vec<Record> = Records::new(r, &h).map(Result::unwrap).collect();
        assert_eq!(recs.len(), 2);
        assert_eq!(
            (recs[1].t_usec, recs[1].uid, recs[1].status),
            (9, 1, Status::Success)
        );
        // The older layout: bit fields in one u64.
        let mut old = (7i32).to_le_bytes().to_vec();
        old.extend(b"<root/>");
        old.extend(0i64.to_le_bytes());
        old.extend((1234u64 | (3u64 << 45) | (3u64 << 61)).to_le_bytes());
        let mut r = &old[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        let recs: Vec<Record> = Records::new(r, &h).map(Result::unwrap).collect();
        assert_eq!(
            (h.layout, recs[0].t_usec, recs[0].uid, recs[0].status),
            (Layout::Legacy, 1234, 3, Status::Failure)
        );
    }

    #[test]
    fn a_cut_or_corrupt_log_is_an_error_with_its_offset() {
        let mut b = v1("<root/>", &[(5, 1, 1), (9, 1, 2)]);
        b.truncate(b.len() - 4);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        let last = Records::new(r, &h).last().unwrap();
        assert_eq!(
            last,
            Err(LogError::Truncated {
                offset: 47,
                what: "a record"
            })
        );
        let mut b = v1("<root/>", &[(5, 1, 7)]);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        assert!(matches!(
            Records::new(r, &h).next(),
            Some(Err(LogError::Bad { offset: 38, .. }))
        ));
        b.truncate(30);
        assert_eq!(
            read_header(&mut &b[..], 1 << 20).unwrap_err(),
            LogError::Truncated {
                offset: 30,
                what: "the first timestamp"
            }
        );
        assert!(matches!(
            read_header(&mut &v1("<root/>", &[])[..], 3),
            Err(LogError::Bad { offset: 19, .. })
        ));
    }

    #[test]
    fn time_going_backwards_is_an_error_at_its_record() {
        let b = v1("<root/>", &[(5, 1, 1), (5, 1, 2), (9, 1, 1), (4, 1, 2)]);
        let mut r = &b[..];
        let h = read_header(&mut r, 1 << 20).unwrap();
        let recs: Vec<_> = Records::new(r, &h).collect();
        assert_eq!(recs.len(), 4);
        assert!(recs[..3].iter().all(Result::is_ok));
        match &recs[3] {
            Err(LogError::Bad { offset: 65, what }) => {
                assert!(what.contains("time goes backwards"), "{what}");
            }
            other => panic!("{other:?}"),
        }
    }
}
