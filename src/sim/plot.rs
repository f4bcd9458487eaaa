//! SVG plot of a scenario's runs in the style of the paper's Fig. 17: the room,
//! its obstacles and stations, the objects' start positions, and each policy's
//! trajectory with event markers (pick, place, battery low, recharge, dock,
//! disturbances). Written by hand: a few dozen SVG elements need no crate.

use super::scenario::Scenario;
use super::trace::Run;
use super::world::Place;
use std::fmt::Write;

const COLORS: &[&str] = &[
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
];
const SCALE: f64 = 100.0; // pixels per metre
const MARGIN: f64 = 40.0;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The SVG text.
pub fn svg(s: &Scenario, runs: &[Run]) -> String {
    let l = &s.world.layout;
    let r = &l.room;
    let legend_h = 22.0 * runs.len() as f64 + 70.0;
    let w = (r.x1 - r.x0) * SCALE + 2.0 * MARGIN;
    let h = (r.y1 - r.y0) * SCALE + 2.0 * MARGIN + legend_h;
    let px = |x: f64| MARGIN + (x - r.x0) * SCALE;
    let py = |y: f64| MARGIN + (r.y1 - y) * SCALE;
    let mut o = String::new();
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="Helvetica, Arial, sans-serif">"#
    );
    let _ = writeln!(o, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<text x="{MARGIN}" y="24" font-size="16">{}</text>"#,
        esc(&format!("scenario {} (seed {})", s.name, s.seed))
    );
    // Walls.
    let _ = writeln!(
        o,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#fafafa" stroke="#333" stroke-width="6"/>"##,
        px(r.x0),
        py(r.y1),
        (r.x1 - r.x0) * SCALE,
        (r.y1 - r.y0) * SCALE
    );
    // Obstacles; those that disturbances add (blocked paths) dashed in red.
    let blocked = s.disturbances.iter().filter_map(|d| match &d.effect {
        super::scenario::Effect::Block(ob) => Some(ob),
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
    for (ob, style, ink, label) in styled {
        let _ = writeln!(
            o,
            r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" {style}/><text x="{:.1}" y="{:.1}" font-size="10" text-anchor="middle" fill="{ink}">{}</text>"#,
            px(ob.x0),
            py(ob.y1),
            (ob.x1 - ob.x0) * SCALE,
            (ob.y1 - ob.y0) * SCALE,
            px((ob.x0 + ob.x1) / 2.0),
            py((ob.y0 + ob.y1) / 2.0) + 3.0,
            esc(&label)
        );
    }
    // Stations and waypoints.
    for (n, p) in &l.stations {
        let _ = writeln!(
            o,
            r##"<g><path d="M{x:.1},{y1:.1} L{x:.1},{y2:.1} M{x1:.1},{y:.1} L{x2:.1},{y:.1}" stroke="#555" stroke-width="1.5"/><text x="{tx:.1}" y="{ty:.1}" font-size="11" fill="#333">{}</text></g>"##,
            esc(n),
            x = px(p.0),
            y = py(p.1),
            x1 = px(p.0) - 6.0,
            x2 = px(p.0) + 6.0,
            y1 = py(p.1) - 6.0,
            y2 = py(p.1) + 6.0,
            tx = px(p.0) + 7.0,
            ty = py(p.1) - 7.0
        );
    }
    for (i, p) in l.waypoints.iter().enumerate() {
        let _ = writeln!(
            o,
            r##"<circle cx="{:.1}" cy="{:.1}" r="3" fill="none" stroke="#999"/><text x="{:.1}" y="{:.1}" font-size="9" fill="#999">w{}</text>"##,
            px(p.0),
            py(p.1),
            px(p.0) + 4.0,
            py(p.1) + 10.0,
            i + 1
        );
    }
    // Objects at the start.
    for ob in &s.world.objects {
        if let Place::At(p) | Place::Floor(p) = ob.place {
            let _ = writeln!(
                o,
                r##"<rect x="{:.1}" y="{:.1}" width="10" height="10" fill="#f2c200" stroke="#7a6200"/><text x="{:.1}" y="{:.1}" font-size="10">{}</text>"##,
                px(p.0) - 5.0,
                py(p.1) - 5.0,
                px(p.0) + 7.0,
                py(p.1) + 12.0,
                esc(&ob.name)
            );
        }
    }
    // Trajectories, offset slightly so that identical ones stay visible.
    for (k, run) in runs.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        let off = (k as f64 - (runs.len() as f64 - 1.0) / 2.0) * 2.5;
        let mut d = String::new();
        let mut last: Option<(f64, f64)> = None;
        for (i, p) in run.trajectory.iter().enumerate() {
            let q = (px(p.0) + off, py(p.1) + off);
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
            last = Some(q);
        }
        let dash = if k % 2 == 1 {
            r#" stroke-dasharray="7,4""#
        } else {
            ""
        };
        let _ = writeln!(
            o,
            r#"<path d="{d}" fill="none" stroke="{c}" stroke-width="2" stroke-opacity="0.85"{dash}/>"#
        );
        for e in &run.events {
            let (x, y) = (px(e.x) + off, py(e.y) + off);
            let marker = match (e.kind.as_str(), e.text.split('(').next().unwrap_or("")) {
                ("end", "Pick") if e.text.ends_with("success") => "pick",
                ("end", "Place") if e.text.ends_with("success") => "place",
                ("start", "Recharge") => "recharge",
                ("end", "Dock") if e.text.ends_with("success") => "dock",
                ("end", _) if e.text.ends_with("failure") => "failure",
                ("battery-low", _) => "battery-low",
                ("disturbance", _) => "disturbance",
                ("chattering", _) => "chattering",
                _ => continue,
            };
            let shape = match marker {
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
            };
            let _ = writeln!(
                o,
                "<g><title>{}</title>{shape}</g>",
                esc(&format!("{} s: {}", e.t, e.text))
            );
        }
    }
    // Legend.
    let mut y = (r.y1 - r.y0) * SCALE + 2.0 * MARGIN + 10.0;
    for (k, run) in runs.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        let dash = if k % 2 == 1 {
            r#" stroke-dasharray="7,4""#
        } else {
            ""
        };
        let _ = writeln!(
            o,
            r#"<path d="M{MARGIN},{y:.1} l30,0" stroke="{c}" stroke-width="3"{dash}/><text x="{:.1}" y="{:.1}" font-size="12">{}</text>"#,
            MARGIN + 38.0,
            y + 4.0,
            esc(&format!(
                "{} — {}, {:.1} s, {:.1} m",
                run.policy,
                run.outcome.as_str(),
                run.duration_s,
                run.distance_m
            ))
        );
        y += 22.0;
    }
    let _ = writeln!(
        o,
        r##"<text x="{MARGIN}" y="{:.1}" font-size="11" fill="#444">● pick  ■ place  ⚡ recharge start  ◆ dock  △ battery low  ◇ disturbance  ✕ failed action  ◌ chattering</text>"##,
        y + 6.0
    );
    o.push_str("</svg>\n");
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostic::SourceFile;
    use crate::format::Limits;
    use std::path::Path;

    #[test]
    fn plot_has_room_obstacles_trajectories_and_markers() {
        let f = SourceFile::new(
            "t.toml",
            r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 1.0
block = { name = "crate", rect = [-1.0, -2.9, -0.9, -2.5] }
"#,
        );
        let s =
            super::super::scenario::parse(&f, Path::new("policies/scenarios"), &Limits::default())
                .unwrap();
        let runs = super::super::run::run_scenario(&s, false);
        let svg = svg(&s, &runs);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains(">central table<") && svg.contains("crate (blocked later)"));
        assert!(svg.contains(r#"<path d="M"#), "a trajectory");
        assert!(
            svg.contains("Pick(object=cube2) -&gt; success"),
            "a pick marker"
        );
        assert_eq!(svg.matches("<svg").count(), 1);
    }
}
