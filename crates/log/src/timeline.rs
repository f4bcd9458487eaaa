//! `btfsm log timeline LOG`: a BehaviorTree.CPP log as an SVG timeline,
//! written by hand (no Graphviz): one row per leaf (action or condition)
//! that ever left IDLE, in the tree's order; a bar where it was RUNNING;
//! its changes into RUNNING, SUCCESS and FAILURE marked in the colours of
//! `dot --trace` (gold, palegreen, tomato); a time axis in seconds.
//!
//! Bounded: the log is read twice as a stream (the first pass finds its
//! end, the second places every record at its pixel column). Bars that
//! touch within a pixel are one bar, marks of one status in one pixel
//! column one mark: a row holds at most `width` bars and `3 x width` marks,
//! so the SVG grows with rows x width, never with the number of records,
//! and at most [`MAX_ELEMENTS`] bars and marks are drawn (more is an error)
//! (a record older than one before it is drawn at the later time).

use super::btlog::{LogError, Records, Status, read_header};
use super::tree::{Tree, parse};
use btfsm_format::btcpp_xml::{Category, builtin};
use std::collections::BTreeMap;
use std::fmt::Write;
use std::io::{BufReader, Read};

/// Widest plot area, px.
pub const MAX_WIDTH: u32 = 20_000;
/// Most bars and marks in one drawing (about 100 bytes of SVG each).
pub const MAX_ELEMENTS: usize = 1_000_000;
const ROW_H: u32 = 18;
const TOP: u32 = 44;
const AXIS_H: u32 = 44;

const RUNNING: &str = "gold";
const SUCCESS: &str = "palegreen";
const FAILURE: &str = "tomato";

#[derive(Debug, Default)]
struct Row {
    /// Bars, in pixel columns: start and end (inclusive).
    bars: Vec<(u32, u32)>,
    /// Marks: pixel column and the statuses entered there (bit 0 RUNNING,
    /// 1 SUCCESS, 2 FAILURE).
    marks: Vec<(u32, u8)>,
    running_since: Option<u32>,
    ticked: bool,
}

impl Row {
    fn bar(&mut self, a: u32, b: u32) {
        match self.bars.last_mut() {
            Some(last) if last.1 + 1 >= a => last.1 = last.1.max(b),
            _ => self.bars.push((a, b)),
        }
    }

    fn mark(&mut self, x: u32, bit: u8) {
        match self.marks.last_mut() {
            Some(last) if last.0 == x => last.1 |= bit,
            _ => self.marks.push((x, bit)),
        }
    }
}

/// Whether a node gets a row: a leaf, action or condition.
fn is_leaf(t: &Tree, uid: u16) -> bool {
    let n = &t.nodes[&uid];
    n.children.is_empty()
        && n.tag != "SubTree"
        && matches!(
            n.category.or_else(|| builtin(&n.tag)),
            None | Some(Category::Action | Category::Condition)
        )
}

/// The figures of the drawing, for tests and the CLI's summary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Timeline {
    pub svg: String,
    pub rows: usize,
    pub records: u64,
    pub bars: usize,
    pub marks: usize,
}

fn esc(s: &str, max_chars: usize) -> String {
    btfsm_core::sanitize::shown_max(s, max_chars)
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A tick step of 1, 2 or 5 times a power of ten giving at most `n` ticks.
fn tick_step(span_s: f64, n: f64) -> f64 {
    let raw = (span_s / n).max(1e-6);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Draws a log `width` px wide (the plot area); `open` opens it (twice).
pub fn timeline<R: Read>(
    file: &str,
    mut open: impl FnMut() -> std::io::Result<R>,
    max_xml: u64,
    width: u32,
) -> Result<Timeline, LogError> {
    let width = width.clamp(100, MAX_WIDTH);
    let io = |e: std::io::Error| LogError::Io(e.to_string());
    // Pass 1: the end of the log (and every record checked).
    let mut r = BufReader::with_capacity(1 << 16, open().map_err(io)?);
    let h = read_header(&mut r, max_xml)?;
    let tree = parse(&h.xml).map_err(|what| LogError::Bad {
        offset: 23.min(h.records_at),
        what,
    })?;
    let end = last_time(Records::new(r, &h), &tree)?;
    // Pass 2: each record at its pixel column.
    let mut r = BufReader::with_capacity(1 << 16, open().map_err(io)?);
    let h2 = read_header(&mut r, max_xml)?;
    if h2.xml != h.xml || h2.records_at != h.records_at {
        return Err(LogError::Io("the log changed while read".into()));
    }
    let (rows, count) = place(Records::new(r, &h), &tree, end, width)?;
    let elements: usize = (rows.values())
        .map(|r| {
            r.bars.len()
                + r.marks
                    .iter()
                    .map(|m| m.1.count_ones() as usize)
                    .sum::<usize>()
        })
        .sum();
    if elements > MAX_ELEMENTS {
        return Err(LogError::Limit(format!(
            "the timeline would draw {elements} bars and marks in {} rows, more than {MAX_ELEMENTS}: draw it narrower (--width)",
            rows.len()
        )));
    }
    let d = Drawing {
        tree: &tree,
        rows: &rows,
        end,
        width,
        label_w: 280,
    };
    let mut o = String::new();
    d.head(&mut o, file, count);
    let (bars, marks) = d.rows(&mut o);
    d.time_axis(&mut o);
    o.push_str("</svg>\n");
    Ok(Timeline {
        svg: o,
        rows: rows.len(),
        records: count,
        bars,
        marks,
    })
}

/// The time of the last record, µs (every record checked to name a node
/// of the tree).
fn last_time<R: Read>(mut records: Records<R>, tree: &Tree) -> Result<u64, LogError> {
    let mut end = 0u64;
    loop {
        let at = records.offset();
        let Some(rec) = records.next() else { break };
        let rec = rec?;
        if !tree.nodes.contains_key(&rec.uid) {
            return Err(LogError::Bad {
                offset: at,
                what: format!("node UID {}, which the log's tree does not have", rec.uid),
            });
        }
        end = end.max(rec.t_usec);
    }
    Ok(end)
}

/// The rows of the leaves that ever left IDLE, each record placed at its
/// pixel column of `width` over `0..end` µs; and the number of records.
fn place<R: Read>(
    records: Records<R>,
    tree: &Tree,
    end: u64,
    width: u32,
) -> Result<(BTreeMap<u16, Row>, u64), LogError> {
    let span = end.max(1);
    let col = |t: u64| ((t as u128 * (width - 1) as u128) / span as u128) as u32;
    let mut rows: BTreeMap<u16, Row> = tree
        .nodes
        .keys()
        .filter(|&&u| is_leaf(tree, u))
        .map(|&u| (u, Row::default()))
        .collect();
    let mut count = 0u64;
    let mut last_t = 0u64;
    for rec in records {
        let rec = rec?;
        count += 1;
        // A record older than one before it is drawn at the later time:
        // columns never go back.
        last_t = last_t.max(rec.t_usec);
        let Some(row) = rows.get_mut(&rec.uid) else {
            continue;
        };
        let x = col(last_t.min(end));
        if let Some(s) = row.running_since.take() {
            row.bar(s, x);
        }
        match rec.status {
            Status::Running => {
                row.running_since = Some(x);
                row.mark(x, 1);
            }
            Status::Success => row.mark(x, 2),
            Status::Failure => row.mark(x, 4),
            Status::Idle | Status::Skipped => {}
        }
        if rec.status != Status::Idle {
            row.ticked = true;
        }
    }
    for row in rows.values_mut() {
        if let Some(s) = row.running_since.take() {
            row.bar(s, width - 1);
        }
    }
    rows.retain(|_, r| r.ticked);
    Ok((rows, count))
}

/// What the SVG is drawn from: the tree, its rows, the log's end (µs),
/// the plot's width and the labels' width (px).
struct Drawing<'a> {
    tree: &'a Tree,
    rows: &'a BTreeMap<u16, Row>,
    end: u64,
    width: u32,
    label_w: u32,
}

impl Drawing<'_> {
    /// The `<svg>` element, a white background, the title (the file, its
    /// `count` records and duration) and the legend.
    fn head(&self, o: &mut String, file: &str, count: u64) {
        let (w, h_px) = self.size();
        let _ = writeln!(
            o,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h_px}" viewBox="0 0 {w} {h_px}" font-family="Helvetica, Arial, sans-serif" font-size="11">"#
        );
        let _ = writeln!(o, r#"<rect width="100%" height="100%" fill="white"/>"#);
        let _ = writeln!(
            o,
            r#"<text x="8" y="18" font-size="14">{}</text>"#,
            esc(
                &format!("{file}: {count} records, {:.3} s", self.end as f64 / 1e6),
                300
            )
        );
        let _ = writeln!(
            o,
            r##"<text x="8" y="34" fill="#555">RUNNING bars and marks: gold; SUCCESS: green; FAILURE: red</text>"##
        );
    }

    /// The drawing's width and height, px.
    fn size(&self) -> (u32, u32) {
        (
            self.label_w + self.width + 30,
            TOP + ROW_H * self.rows.len() as u32 + AXIS_H,
        )
    }

    /// Every row: its label, bars and marks; how many bars and marks.
    fn rows(&self, o: &mut String) -> (usize, usize) {
        let (w, _) = self.size();
        let x0 = self.label_w;
        let (mut bars, mut marks) = (0, 0);
        for (i, (uid, row)) in self.rows.iter().enumerate() {
            let y = TOP + ROW_H * i as u32;
            let n = &self.tree.nodes[uid];
            if i % 2 == 1 {
                let _ = writeln!(
                    o,
                    r##"<rect x="0" y="{y}" width="{w}" height="{ROW_H}" fill="#f4f4f4"/>"##
                );
            }
            let label = if n.name == n.tag {
                n.name.clone()
            } else {
                format!("{} ({})", n.name, n.tag)
            };
            let _ = writeln!(
                o,
                r#"<text x="8" y="{}">{}</text>"#,
                y + 13,
                esc(&label, 60)
            );
            for &(a, b) in &row.bars {
                let _ = writeln!(
                    o,
                    r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{RUNNING}" stroke="goldenrod" stroke-width="0.5"/>"#,
                    x0 + a,
                    y + 4,
                    b - a + 1,
                    ROW_H - 8
                );
                bars += 1;
            }
            for &(x, bits) in &row.marks {
                for (bit, colour) in [(1u8, RUNNING), (2, SUCCESS), (4, FAILURE)] {
                    if bits & bit != 0 {
                        let _ = writeln!(
                            o,
                            r##"<rect x="{}" y="{}" width="2" height="{}" fill="{colour}" stroke="#333" stroke-width="0.3"/>"##,
                            x0 + x,
                            y + 1,
                            ROW_H - 2
                        );
                        marks += 1;
                    }
                }
            }
        }
        (bars, marks)
    }

    /// The time axis under the rows: its line, ticks and title.
    fn time_axis(&self, o: &mut String) {
        let (x0, width) = (self.label_w, self.width);
        let ya = TOP + ROW_H * self.rows.len() as u32 + 6;
        let _ = writeln!(
            o,
            r##"<line x1="{x0}" y1="{ya}" x2="{}" y2="{ya}" stroke="#333"/>"##,
            x0 + width
        );
        let span_s = self.end.max(1) as f64 / 1e6;
        let step = tick_step(span_s, 10.0);
        let mut k = 0u64;
        loop {
            let t = k as f64 * step;
            if t > span_s + 1e-12 {
                break;
            }
            let x = x0 as f64 + t / span_s * (width - 1) as f64;
            let label = format!("{:.*}", decimals(step), t);
            let _ = writeln!(
                o,
                r##"<line x1="{x:.1}" y1="{ya}" x2="{x:.1}" y2="{}" stroke="#333"/><text x="{x:.1}" y="{}" text-anchor="middle">{label}</text>"##,
                ya + 5,
                ya + 18
            );
            k += 1;
        }
        let _ = writeln!(
            o,
            r#"<text x="{}" y="{}" text-anchor="middle">time (s)</text>"#,
            x0 + width / 2,
            ya + 34
        );
    }
}

/// Decimals to print a multiple of `step`.
fn decimals(step: f64) -> usize {
    (-(step.log10().floor())).clamp(0.0, 6.0) as usize
}

#[cfg(test)]
mod tests {
    use super::super::btlog::MAGIC;
    use super::*;

    const XML: &str = r#"<root BTCPP_format="4"><BehaviorTree ID="M" _fullpath=""><Sequence _uid="1"><IsOk _uid="2" name="ok &lt;?"/><Go _uid="3"/><Never _uid="4"/></Sequence></BehaviorTree><TreeNodesModel><Condition ID="IsOk"/><Action ID="Go"/><Action ID="Never"/></TreeNodesModel></root>"#;

    fn log(records: impl Iterator<Item = (u64, u16, u8)>) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend((XML.len() as i32).to_le_bytes());
        b.extend(XML.as_bytes());
        b.extend(0i64.to_le_bytes());
        for (t, u, s) in records {
            b.extend(&t.to_le_bytes()[..6]);
            b.extend(u.to_le_bytes());
            b.push(s);
        }
        b
    }

    fn draw(b: &[u8], width: u32) -> Timeline {
        timeline("t.btlog", || Ok(b), 1 << 20, width).unwrap()
    }

    #[test]
    fn a_small_timeline() {
        let b = log([
            (0, 1, 1),
            (0, 2, 2),
            (100_000, 3, 1),
            (1_500_000, 3, 3),
            (1_600_000, 2, 3),
            (1_600_000, 1, 3),
            (2_000_000, 2, 0),
            (2_000_000, 3, 0),
        ]
        .into_iter());
        let t = draw(&b, 400);
        assert_eq!((t.rows, t.records, t.bars, t.marks), (2, 8, 1, 4));
        roxmltree::Document::parse(&t.svg).expect("well-formed XML");
        insta::assert_snapshot!(t.svg);
    }

    #[test]
    fn a_huge_log_draws_in_rows_times_width() {
        // 200,000 status changes of two leaves: the drawing holds at most
        // one bar and three marks per row and pixel column.
        let recs = (0..200_000u64).map(|i| (i * 10, 2 + (i % 2) as u16, 1 + (i / 2 % 3) as u8));
        let b = log(recs);
        let t = draw(&b, 300);
        assert_eq!((t.rows, t.records), (2, 200_000));
        assert!(t.bars <= 2 * 300 && t.marks <= 2 * 3 * 300, "{t:?}");
        assert!(t.svg.len() < 2 * 4 * 300 * 160 + 10_000, "{}", t.svg.len());
        roxmltree::Document::parse(&t.svg).expect("well-formed XML");
    }

    #[test]
    fn past_the_element_bound_a_timeline_is_refused() {
        // 18 leaves changing status in every pixel column of 20,000: 1.08
        // million marks, more than the bound.
        let leaves: String = (2..20).map(|u| format!(r#"<Go _uid="{u}"/>"#)).collect();
        let xml = format!(
            r#"<root><BehaviorTree ID="M" _fullpath=""><Parallel _uid="1">{leaves}</Parallel></BehaviorTree><TreeNodesModel><Action ID="Go"/></TreeNodesModel></root>"#
        );
        let mut b = MAGIC.to_vec();
        b.push(1);
        b.extend((xml.len() as i32).to_le_bytes());
        b.extend(xml.as_bytes());
        b.extend(0i64.to_le_bytes());
        for col in 0..20_000u64 {
            for u in 2..20u16 {
                for s in [1u8, 2, 3] {
                    b.extend(&(col * 10).to_le_bytes()[..6]);
                    b.extend(u.to_le_bytes());
                    b.push(s);
                }
            }
        }
        let e = match timeline("t", || Ok(&b[..]), 1 << 20, MAX_WIDTH) {
            Ok(t) => panic!("drawn: {} marks", t.marks),
            Err(e) => e.to_string(),
        };
        assert!(e.contains("1080018 bars and marks in 18 rows"), "{e}");
        // Narrower, it fits.
        let t = timeline("t", || Ok(&b[..]), 1 << 20, 1000).unwrap();
        assert!(t.marks + t.bars <= MAX_ELEMENTS && t.rows == 18);
    }

    #[test]
    fn tick_steps_are_one_two_five() {
        assert_eq!(tick_step(2.0, 10.0), 0.2);
        assert_eq!(tick_step(17.6, 10.0), 2.0);
        assert_eq!(tick_step(0.004, 10.0), 0.0005);
        assert_eq!(decimals(0.0005), 4);
    }
}
