//! SVG plot of a scenario's runs in the style of the paper's Fig. 17: the room
//! with axes in metres and a scale bar, its obstacles and stations, the
//! objects where they started and where the runs left them, and each
//! policy's trajectory with event markers (pick, place, battery low,
//! recharge, dock, disturbances). Labels are placed where they cover no
//! marker (`labels`). Written by hand: a few hundred SVG elements need no
//! crate.

mod labels;
mod marks;
#[cfg(test)]
mod tests;

use super::scenario::Scenario;
use super::trace::Run;
use super::world::{Layout, Place};
use btfsm_core::sanitize;
use labels::{BBox, Ink, Placer};
use std::collections::{BTreeMap, HashMap};
use std::fmt::Write;

/// The runs' colours, in policy order (the map of `btfsm view` uses them too).
pub const COLORS: &[&str] = &[
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
];
/// Pixels per metre.
const SCALE: f64 = 100.0;
const LEFT: f64 = 64.0;
const TOP: f64 = 44.0;
const RIGHT: f64 = 24.0;
/// Below the room: the x axis's tick labels and title.
const BELOW: f64 = 60.0;
/// Objects left closer than this (px) share one label.
const CLUSTER: f64 = 24.0;
/// Distance between two runs' drawings of one path, px.
const OFFSET: f64 = 2.5;
const LINE: f64 = 20.0;
/// A label's halo: white under the glyphs, so that a path crossing a label
/// does not hide it.
const HALO: &str =
    r#"stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke""#;

/// A string from the input, for SVG text: control characters escaped and
/// the length cut as in every report ([`sanitize::shown`]), then XML's
/// special characters.
fn esc(s: &str) -> String {
    sanitize::markup(s, sanitize::SHOWN_CHARS)
}

/// Metres to pixels.
struct Frame {
    x0: f64,
    y1: f64,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        LEFT + (x - self.x0) * SCALE
    }
    fn py(&self, y: f64) -> f64 {
        TOP + (self.y1 - y) * SCALE
    }
}

/// Where a point of the room, m, is drawn in [`svg`]'s picture, px (the
/// map of `btfsm view` moves its robots with it).
pub fn pixel(s: &Scenario, p: super::world::P2) -> (f64, f64) {
    let r = &s.world.layout.room;
    let f = Frame { x0: r.x0, y1: r.y1 };
    (f.px(p.0), f.py(p.1))
}

/// A tick spacing of 1, 2 or 5 times a power of ten giving at most eight
/// intervals over `span` metres.
fn tick_step(span: f64) -> f64 {
    let mut step = 0.1;
    for _ in 0..12 {
        for m in [1.0, 2.0, 5.0] {
            if span / (step * m) <= 8.0 {
                return step * m;
            }
        }
        step *= 10.0;
    }
    step
}

fn metres(v: f64) -> String {
    let s = format!("{:.2}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// The room's axes: ticks and values in metres outside the walls, and the
/// axis titles.
fn axes(o: &mut String, f: &Frame, r: &super::world::Rect) {
    let step = tick_step((r.x1 - r.x0).max(r.y1 - r.y0));
    let (bottom, left) = (f.py(r.y0) + 3.0, f.px(r.x0) - 3.0);
    let first = |lo: f64| (lo / step).ceil() as i64;
    let last = |hi: f64| (hi / step + 1e-9).floor() as i64;
    for k in first(r.x0)..=last(r.x1) {
        let x = k as f64 * step;
        let _ = writeln!(
            o,
            r##"<path d="M{px:.1},{bottom:.1} l0,6" stroke="#333"/><text x="{px:.1}" y="{:.1}" font-size="11" text-anchor="middle" fill="#333">{}</text>"##,
            bottom + 18.0,
            metres(x),
            px = f.px(x)
        );
    }
    for k in first(r.y0)..=last(r.y1) {
        let y = k as f64 * step;
        let _ = writeln!(
            o,
            r##"<path d="M{left:.1},{py:.1} l-6,0" stroke="#333"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end" fill="#333">{}</text>"##,
            left - 9.0,
            f.py(y) + 4.0,
            metres(y),
            py = f.py(y)
        );
    }
    let _ = writeln!(
        o,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" fill="#333">x (m)</text><text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" fill="#333" transform="rotate(-90 {:.1} {:.1})">y (m)</text>"##,
        (f.px(r.x0) + f.px(r.x1)) / 2.0,
        bottom + 36.0,
        LEFT - 44.0,
        (f.py(r.y0) + f.py(r.y1)) / 2.0,
        LEFT - 44.0,
        (f.py(r.y0) + f.py(r.y1)) / 2.0,
    );
}

/// A run's path as compared for "same path": its points rounded to the
/// centimetre, repeats dropped.
fn path_key(run: &Run) -> Vec<(i64, i64)> {
    let mut k: Vec<(i64, i64)> = Vec::new();
    for p in &run.trajectory {
        let q = ((p.0 * 100.0).round() as i64, (p.1 * 100.0).round() as i64);
        if k.last() != Some(&q) {
            k.push(q);
        }
    }
    k
}

/// Groups of two or more runs (indices, in order) whose paths are the same.
/// Linear in the runs' points: the paths are hashed into buckets.
pub(crate) fn same_paths(runs: &[Run]) -> Vec<Vec<usize>> {
    let mut buckets: HashMap<Vec<(i64, i64)>, Vec<usize>> = HashMap::new();
    let mut order = Vec::new();
    for (i, run) in runs.iter().enumerate() {
        let k = path_key(run);
        let e = buckets.entry(k).or_default();
        if e.is_empty() {
            order.push(i);
        }
        e.push(i);
    }
    let mut firsts: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (_, g) in buckets {
        if g.len() > 1 {
            firsts.insert(g[0], g);
        }
    }
    firsts.into_values().collect()
}

/// Where an object ended, per distinct position (centimetres): its name
/// and the runs that left it there. Objects in the gripper are left out.
type Ends = BTreeMap<(i64, i64), Vec<(String, Vec<usize>)>>;

fn ends(runs: &[Run]) -> Ends {
    let mut out: Ends = BTreeMap::new();
    for (k, run) in runs.iter().enumerate() {
        for (name, st) in &run.final_world.objects {
            if st.held {
                continue;
            }
            let key = ((st.x * 100.0).round() as i64, (st.y * 100.0).round() as i64);
            let at = out.entry(key).or_default();
            match at.iter_mut().find(|(n, _)| n == name) {
                Some((_, rs)) => rs.push(k),
                None => at.push((name.clone(), vec![k])),
            }
        }
    }
    out
}

/// Names for one label: at most three, then how many more.
fn names(list: &[&str]) -> String {
    let mut s = list.iter().take(3).copied().collect::<Vec<_>>().join(", ");
    if list.len() > 3 {
        let _ = write!(s, " +{}", list.len() - 3);
    }
    s
}

/// The SVG text.
pub fn svg(s: &Scenario, runs: &[Run]) -> String {
    let l = &s.world.layout;
    let r = &l.room;
    let f = Frame { x0: r.x0, y1: r.y1 };
    let groups = if runs.len() > 1 {
        same_paths(runs)
    } else {
        Vec::new()
    };
    let legend_lines = runs.len() + usize::from(runs.len() > 1) + groups.len() + 3;
    let w = (r.x1 - r.x0) * SCALE + LEFT + RIGHT;
    let room_bottom = f.py(r.y0);
    let h = room_bottom + BELOW + LINE * legend_lines as f64 + 16.0;
    let mut o = String::new();
    let mut ink = Placer::new(BBox {
        x0: f.px(r.x0),
        y0: f.py(r.y1),
        x1: f.px(r.x1),
        y1: f.py(r.y0),
    });
    head(&mut o, &f, s, (w, h));
    axes(&mut o, &f, r);
    marks::obstacles(&mut o, &f, s, &mut ink);
    marks::trajectories(&mut o, &f, runs, &mut ink);
    stations_and_waypoints(&mut o, &f, l, &mut ink);
    let starts = object_starts(&mut o, &f, s, &mut ink);
    let end_labels = object_ends(&mut o, &f, runs, &starts, &mut ink);
    // Labels, the most important first: they take the best places.
    for (n, p) in &l.stations {
        label(
            &mut o,
            &mut ink,
            (f.px(p.0), f.py(p.1)),
            6.0,
            n,
            (11.0, "#333"),
        );
    }
    for (q, n) in &starts {
        label(&mut o, &mut ink, *q, 5.0, n, (10.0, "#000"));
    }
    for (q, n) in &end_labels {
        label(&mut o, &mut ink, *q, 4.0, n, (10.0, "#5a4800"));
    }
    for (i, p) in l.waypoints.iter().enumerate() {
        label(
            &mut o,
            &mut ink,
            (f.px(p.0), f.py(p.1)),
            3.0,
            &format!("w{}", i + 1),
            (9.0, "#999"),
        );
    }
    marks::legend(&mut o, runs, &groups, room_bottom + BELOW);
    o.push_str("</svg>\n");
    o
}

/// The drawing's opening: the `<svg>` element `w` x `h` px, a white
/// background, the title, and the room's walls.
fn head(o: &mut String, f: &Frame, s: &Scenario, (w, h): (f64, f64)) {
    let r = &s.world.layout.room;
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="Helvetica, Arial, sans-serif">"#
    );
    let _ = writeln!(o, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<text x="{LEFT}" y="26" font-size="16">{}</text>"#,
        esc(&format!("scenario {} (seed {})", s.name, s.seed))
    );
    // Walls.
    let _ = writeln!(
        o,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#fafafa" stroke="#333" stroke-width="6"/>"##,
        f.px(r.x0),
        f.py(r.y1),
        (r.x1 - r.x0) * SCALE,
        (r.y1 - r.y0) * SCALE
    );
}

/// Stations (crosses) and waypoints (circles); their labels come once all
/// marks are down.
fn stations_and_waypoints(o: &mut String, f: &Frame, l: &Layout, ink: &mut Placer) {
    for (_, p) in &l.stations {
        let (x, y) = (f.px(p.0), f.py(p.1));
        let _ = writeln!(
            o,
            r##"<path d="M{x:.1},{:.1} l0,12 M{:.1},{y:.1} l12,0" stroke="#555" stroke-width="1.5"/>"##,
            y - 6.0,
            x - 6.0,
        );
        ink.mark(BBox::around(x, y, 6.0), Ink::Mark);
    }
    for p in &l.waypoints {
        let (x, y) = (f.px(p.0), f.py(p.1));
        let _ = writeln!(
            o,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="3" fill="none" stroke="#999"/>"##
        );
        ink.mark(BBox::around(x, y, 3.0), Ink::Mark);
    }
}

/// The objects where they started (hollow squares); their positions (px)
/// and names, for their labels.
fn object_starts<'s>(
    o: &mut String,
    f: &Frame,
    s: &'s Scenario,
    ink: &mut Placer,
) -> Vec<((f64, f64), &'s str)> {
    let mut starts: Vec<((f64, f64), &str)> = Vec::new();
    for ob in &s.world.objects {
        if let Place::At(p) | Place::Floor(p) = ob.place {
            let (x, y) = (f.px(p.0), f.py(p.1));
            let _ = writeln!(
                o,
                r##"<g><title>{} at the start</title><rect x="{:.1}" y="{:.1}" width="10" height="10" fill="#fff6c4" stroke="#7a6200" stroke-dasharray="2,1.5"/></g>"##,
                esc(&ob.name),
                x - 5.0,
                y - 5.0
            );
            ink.mark(BBox::around(x, y, 5.0), Ink::Mark);
            starts.push(((x, y), ob.name.as_str()));
        }
    }
    starts
}

/// The objects where the runs left them (solid squares); the labels of
/// those moved from their start, one per cluster of nearby squares.
fn object_ends(
    o: &mut String,
    f: &Frame,
    runs: &[Run],
    starts: &[((f64, f64), &str)],
    ink: &mut Placer,
) -> Vec<((f64, f64), String)> {
    let ends = ends(runs);
    let mut end_labels: Vec<((f64, f64), Vec<String>)> = Vec::new();
    let mut end_cells: HashMap<(i64, i64), usize> = HashMap::new();
    for ((cx, cy), objs) in &ends {
        let (x, y) = (f.px(*cx as f64 / 100.0), f.py(*cy as f64 / 100.0));
        let mut title = String::new();
        for (name, rs) in objs {
            let by: Vec<&str> = rs.iter().map(|&k| runs[k].policy.as_str()).collect();
            let _ = write!(title, "{} left here by {}; ", name, by.join(", "));
        }
        let _ = writeln!(
            o,
            r##"<g><title>{}</title><rect x="{:.1}" y="{:.1}" width="8" height="8" fill="#f2c200" stroke="#5a4800" stroke-width="1.5"/></g>"##,
            esc(title.trim_end_matches("; ")),
            x - 4.0,
            y - 4.0
        );
        ink.mark(BBox::around(x, y, 4.0), Ink::Mark);
        // An object left where it started is named by its start label.
        let moved: Vec<&str> = objs
            .iter()
            .map(|(n, _)| n.as_str())
            .filter(|n| {
                !starts
                    .iter()
                    .any(|(q, m)| m == n && (q.0 - x).abs() < 1.0 && (q.1 - y).abs() < 1.0)
            })
            .collect();
        if !moved.is_empty() {
            // Objects left side by side (five cubes on one table) share a
            // label, at the first square of a CLUSTER-pixel cell or of one
            // next to it.
            let cell = ((x / CLUSTER).floor() as i64, (y / CLUSTER).floor() as i64);
            let near = (-1..=1)
                .flat_map(|i| (-1..=1).map(move |j| (cell.0 + i, cell.1 + j)))
                .find_map(|c| end_cells.get(&c).copied());
            let at = near.unwrap_or_else(|| {
                end_labels.push(((x, y), Vec::new()));
                end_labels.len() - 1
            });
            end_cells.entry(cell).or_insert(at);
            end_labels[at].1.extend(moved.iter().map(|n| n.to_string()));
        }
    }
    end_labels
        .into_iter()
        .map(|(q, mut ns)| {
            ns.sort();
            ns.dedup();
            let ns: Vec<&str> = ns.iter().map(String::as_str).collect();
            (q, names(&ns))
        })
        .collect()
}

/// A label for a mark of radius `r` at `(x, y)`, where it covers no
/// other mark; `(size, fill)` of its text.
fn label(
    o: &mut String,
    ink: &mut Placer,
    (x, y): (f64, f64),
    r: f64,
    text: &str,
    (size, fill): (f64, &str),
) {
    let spot = ink.place(x, y, r, text, size);
    let _ = writeln!(
        o,
        r#"<text x="{:.1}" y="{:.1}" font-size="{size}" text-anchor="{}" fill="{fill}" {HALO}>{}</text>"#,
        spot.x,
        spot.y,
        spot.anchor,
        esc(text)
    );
}
