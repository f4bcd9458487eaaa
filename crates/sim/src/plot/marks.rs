//! What the simulator plot draws besides the room and its labels: the
//! obstacles (those a disturbance adds dashed in red), each run's trajectory
//! with its event markers, and the legend with a one-metre scale bar (the
//! marker set follows the paper's Fig. 17).

use super::labels::{BBox, Ink, Placer};
use super::{COLORS, Frame, LEFT, LINE, OFFSET, SCALE, esc};
use crate::scenario::{Effect, Scenario};
use crate::trace::Run;
use std::fmt::Write;

/// The obstacles with their names inside; their edges and names are ink for
/// the labels placed later.
pub(super) fn obstacles(o: &mut String, f: &Frame, s: &Scenario, ink: &mut Placer) {
    let l = &s.world.layout;
    let blocked = s.disturbances.iter().filter_map(|d| match &d.effect {
        Effect::Block(ob) => Some(ob),
        _ => None,
    });
    let styled = l
        .obstacles
        .iter()
        .map(|ob| {
            (
                ob,
                r##"fill="#c8b89a" stroke="#6b5a3a""##,
                "#4a3d27",
                ob.name.clone(),
            )
        })
        .chain(blocked.map(|ob| {
            (
                ob,
                r##"fill="#f4b6b6" stroke="#b00" stroke-dasharray="4,3""##,
                "#900",
                format!("{} (blocked later)", ob.name),
            )
        }));
    for (ob, style, fill, label) in styled {
        let (x0, y0, x1, y1) = (f.px(ob.x0), f.py(ob.y1), f.px(ob.x1), f.py(ob.y0));
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0 + 3.0);
        let _ = writeln!(
            o,
            r#"<rect x="{x0:.1}" y="{y0:.1}" width="{:.1}" height="{:.1}" {style}/><text x="{cx:.1}" y="{cy:.1}" font-size="10" text-anchor="middle" fill="{fill}">{}</text>"#,
            x1 - x0,
            y1 - y0,
            esc(&label)
        );
        for (a, b) in [
            ((x0, y0), (x1, y0)),
            ((x1, y0), (x1, y1)),
            ((x1, y1), (x0, y1)),
            ((x0, y1), (x0, y0)),
        ] {
            ink.line(a, b, Ink::Edge);
        }
        let half = label.chars().count() as f64 * 2.8;
        ink.mark(
            BBox {
                x0: cx - half,
                y0: cy - 9.0,
                x1: cx + half,
                y1: cy + 2.0,
            },
            Ink::Text,
        );
    }
}

/// Each run's path and markers, offset by [`OFFSET`] per run so that runs
/// on one path stay visible (the legend says so).
pub(super) fn trajectories(o: &mut String, f: &Frame, runs: &[Run], ink: &mut Placer) {
    for (k, run) in runs.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        let off = (k as f64 - (runs.len() as f64 - 1.0) / 2.0) * OFFSET;
        let mut d = String::new();
        let mut last: Option<(f64, f64)> = None;
        for (i, p) in run.trajectory.iter().enumerate() {
            let q = (f.px(p.0) + off, f.py(p.1) + off);
            if last.is_some_and(|l| (l.0 - q.0).abs() < 0.5 && (l.1 - q.1).abs() < 0.5)
                && i + 1 < run.trajectory.len()
            {
                continue;
            }
            let _ = write!(
                d,
                "{}{:.1},{:.1} ",
                if i == 0 { "M" } else { "L" },
                q.0,
                q.1
            );
            if let Some(l) = last {
                ink.line(l, q, Ink::Path);
            }
            last = Some(q);
        }
        let _ = writeln!(
            o,
            r#"<path d="{d}" fill="none" stroke="{c}" stroke-width="2" stroke-opacity="0.85"{}/>"#,
            dash(k)
        );
        let pts: Vec<(f64, f64)> = (run.trajectory.iter())
            .map(|p| (f.px(p.0) + off, f.py(p.1) + off))
            .collect();
        let heads = arrows(&pts);
        if !heads.is_empty() {
            let _ = writeln!(
                o,
                r#"<path class="arrows" d="{heads}" fill="{c}" stroke="none"/>"#
            );
        }
        for e in &run.events {
            let (x, y) = (f.px(e.x) + off, f.py(e.y) + off);
            let Some(shape) = marker(e.kind.as_str(), &e.text, x, y, c) else {
                continue;
            };
            ink.mark(BBox::around(x, y, 8.0), Ink::Mark);
            let _ = writeln!(
                o,
                "<g><title>{}</title>{shape}</g>",
                esc(&format!("{} s: {}", e.t, e.text))
            );
        }
    }
}

/// Arrow spacing along a path, px (1 m), widened so that a run draws at
/// most [`MAX_ARROWS`].
const ARROW_EVERY: f64 = 100.0;
pub(super) const MAX_ARROWS: usize = 200;

/// Arrowheads along a path (screen points) in its direction of travel,
/// every metre of drawn length (the first half a metre in): an
/// out-and-back trip on one corridor shows arrows both ways. SVG path data
/// of closed triangles; linear in the points.
pub(super) fn arrows(pts: &[(f64, f64)]) -> String {
    let total: f64 = pts.windows(2).map(|w| seg_len(w[0], w[1])).sum();
    let every = ARROW_EVERY.max(total / MAX_ARROWS as f64);
    let mut next = every / 2.0;
    let (mut done, mut out) = (0.0, String::new());
    for w in pts.windows(2) {
        let len = seg_len(w[0], w[1]);
        while len > 1e-9 && next <= done + len {
            let s = (next - done) / len;
            let (dx, dy) = ((w[1].0 - w[0].0) / len, (w[1].1 - w[0].1) / len);
            let (x, y) = (w[0].0 + dx * len * s, w[0].1 + dy * len * s);
            // A 9 px long, 7 px wide head, its tip at the point.
            let (bx, by) = (x - 9.0 * dx, y - 9.0 * dy);
            let _ = write!(
                out,
                "M{x:.1},{y:.1} L{:.1},{:.1} L{:.1},{:.1} Z ",
                bx - 3.5 * dy,
                by + 3.5 * dx,
                bx + 3.5 * dy,
                by - 3.5 * dx
            );
            next += every;
        }
        done += len;
    }
    out
}

fn seg_len(a: (f64, f64), b: (f64, f64)) -> f64 {
    ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt()
}

fn dash(k: usize) -> &'static str {
    if k % 2 == 1 {
        r#" stroke-dasharray="7,4""#
    } else {
        ""
    }
}

/// The marker of an event, if it has one.
fn marker(kind: &str, text: &str, x: f64, y: f64, c: &str) -> Option<String> {
    let ok = text.ends_with("success");
    let m = match (kind, text.split('(').next().unwrap_or("")) {
        ("end", "Pick") if ok => "pick",
        ("end", "Place") if ok => "place",
        ("start", "Recharge") => "recharge",
        ("end", "Dock") if ok => "dock",
        ("end", _) if text.ends_with("failure") => "failure",
        ("battery-low", _) => "battery-low",
        ("disturbance", _) => "disturbance",
        ("chattering", _) => "chattering",
        _ => return None,
    };
    Some(match m {
        "pick" => format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="6" fill="{c}"/>"#),
        "place" => format!(
            r#"<rect x="{:.1}" y="{:.1}" width="11" height="11" fill="{c}"/>"#,
            x - 5.5,
            y - 5.5
        ),
        "recharge" => format!(
            r##"<path d="M{:.1},{:.1} l8,-13 l-3,9 l7,0 l-8,13 l3,-9 z" fill="#ffd400" stroke="{c}"/>"##,
            x - 6.0,
            y + 2.0
        ),
        "dock" => format!(
            r#"<path d="M{:.1},{:.1} l7,-7 l7,7 l-7,7 z" fill="{c}"/>"#,
            x - 7.0,
            y
        ),
        "failure" => format!(
            r##"<path d="M{:.1},{:.1} l10,10 M{:.1},{:.1} l-10,10" stroke="#d00" stroke-width="3"/>"##,
            x - 5.0,
            y - 5.0,
            x + 5.0,
            y - 5.0
        ),
        "battery-low" => format!(
            r##"<path d="M{x:.1},{:.1} l7,12 l-14,0 z" fill="none" stroke="#e06000" stroke-width="2"/>"##,
            y - 8.0
        ),
        "chattering" => format!(
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="12" fill="none" stroke="#d00" stroke-width="2" stroke-dasharray="3,2"/>"##
        ),
        _ => format!(
            r##"<path d="M{:.1},{y:.1} l5,-5 l5,5 l-5,5 z" fill="none" stroke="#000" stroke-width="1.5"/>"##,
            x - 5.0
        ),
    })
}

/// The legend from `top` down: one line per run, how runs on one path are
/// drawn and which share one, the markers, the objects and a scale bar.
pub(super) fn legend(o: &mut String, runs: &[Run], groups: &[Vec<usize>], top: f64) {
    let mut y = top;
    for (k, run) in runs.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        let _ = writeln!(
            o,
            r#"<path d="M{LEFT},{y:.1} l30,0" stroke="{c}" stroke-width="3"{}/><text x="{:.1}" y="{:.1}" font-size="12">{}</text>"#,
            dash(k),
            LEFT + 38.0,
            y + 4.0,
            esc(&format!(
                "{} — {}, {:.1} s, {:.1} m",
                run.policy,
                run.outcome.as_str(),
                run.duration_s,
                run.distance_m
            ))
        );
        y += LINE;
    }
    let note = |o: &mut String, y: f64, text: &str| {
        let _ = writeln!(
            o,
            r##"<text x="{LEFT}" y="{:.1}" font-size="11" fill="#444">{}</text>"##,
            y + 4.0,
            esc(text)
        );
    };
    if runs.len() > 1 {
        note(
            o,
            y,
            &format!(
                "Paths are drawn {OFFSET} px apart, one run beside the other, so that runs on one path stay visible."
            ),
        );
        y += LINE;
    }
    for g in groups {
        let who: Vec<&str> = g.iter().map(|&k| runs[k].policy.as_str()).collect();
        note(o, y, &format!("Same path: {}.", who.join(" = ")));
        y += LINE;
    }
    let _ = writeln!(
        o,
        r##"<text x="{LEFT}" y="{:.1}" font-size="11" fill="#444">▶ direction of travel (every metre)  ● pick  ■ place  ⚡ recharge start  ◆ dock  △ battery low  ◇ disturbance  ✕ failed action  ◌ chattering</text>"##,
        y + 4.0
    );
    y += LINE;
    let _ = writeln!(
        o,
        r##"<rect x="{LEFT}" y="{:.1}" width="10" height="10" fill="#fff6c4" stroke="#7a6200" stroke-dasharray="2,1.5"/><text x="{:.1}" y="{:.1}" font-size="11" fill="#444">object at the start</text><rect x="{:.1}" y="{:.1}" width="8" height="8" fill="#f2c200" stroke="#5a4800" stroke-width="1.5"/><text x="{:.1}" y="{:.1}" font-size="11" fill="#444">where the runs left it (tooltip: which runs)</text>"##,
        y - 5.0,
        LEFT + 16.0,
        y + 4.0,
        LEFT + 150.0,
        y - 4.0,
        LEFT + 164.0,
        y + 4.0
    );
    y += LINE;
    // Scale bar: one metre.
    let _ = writeln!(
        o,
        r##"<path d="M{LEFT},{:.1} l0,8 M{LEFT},{:.1} l{SCALE},0 M{:.1},{:.1} l0,8" stroke="#000" stroke-width="2"/><text x="{:.1}" y="{:.1}" font-size="11">1 m</text>"##,
        y - 4.0,
        y,
        LEFT + SCALE,
        y - 4.0,
        LEFT + SCALE + 8.0,
        y + 4.0
    );
}
