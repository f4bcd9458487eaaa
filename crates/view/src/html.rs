//! The page of a replay: one self-contained HTML file (no server, no
//! network: a Content-Security-Policy forbids every fetch, and nothing is
//! loaded from outside it). Each panel's diagram is Graphviz's SVG inlined
//! (prolog, doctype and comments dropped, element ids prefixed per panel so
//! that two drawings of one policy do not share ids); the timelines are
//! `timeline.rs`'s SVG; the statuses travel as JSON in a
//! `<script type="application/json">` block where `<`, `>` and `&` are
//! `\u` escapes, so no input string can close the block; `page.js` applies
//! them. Every input string in the HTML itself is escaped by [`esc`].

use super::timeline::{self, Axis};
use super::{CHECKPOINT_EVERY, Panel, Replay, ViewError};
use btfsm_render::dot::{DotOptions, RenderFormat, Status, policy_dot, render, svg_id};
use serde::Serialize;
use std::fmt::Write;
use std::time::Duration;

const SCRIPT: &str = include_str!("page.js");
const STYLE: &str = include_str!("page.css");

/// An input string as HTML text or attribute value: control characters
/// escaped (`sanitize`), then `&`, `<`, `>`, `"`, `'` as entities.
pub fn esc(s: &str) -> String {
    btfsm_core::sanitize::markup(s, 400)
}

/// JSON that can sit in a `<script>` block: no `<`, `>` or `&` (outside
/// strings JSON has none; inside they become `\u` escapes, the same data),
/// no raw control or bidirectional character ([`btfsm_core::sanitize::json`]).
pub fn script_json(v: &impl Serialize) -> String {
    let s = btfsm_core::sanitize::json(serde_json::to_string(v).expect("serializable"));
    s.replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026")
}

/// Graphviz's SVG made fit to inline: from `<svg` on (no XML prolog nor
/// doctype), without comments (Graphviz writes node names in them), every
/// `id="` given the panel's prefix.
pub fn inline_svg(svg: &str, prefix: &str) -> String {
    let body = svg.find("<svg").map_or(svg, |i| &svg[i..]);
    let mut out = String::with_capacity(body.len());
    let mut rest = body;
    while let Some(i) = rest.find("<!--") {
        out.push_str(&rest[..i]);
        match rest[i..].find("-->") {
            Some(j) => rest = &rest[i + j + 3..],
            None => {
                rest = "";
                break;
            }
        }
    }
    out.push_str(rest);
    out.replace(" id=\"", &format!(" id=\"{prefix}-"))
}

#[derive(Serialize)]
struct PanelData<'a> {
    /// Per node: the id of its SVG element (without the panel's prefix).
    ids: Vec<String>,
    keys: &'a [String],
    times: Vec<f64>,
    /// Per step: `[node, status, node, status, ...]`.
    deltas: Vec<Vec<u32>>,
    axis: Axis,
    /// Decimals of the times shown.
    digits: usize,
}

#[derive(Serialize)]
struct Divergence<'a> {
    a: usize,
    b: usize,
    text: &'a str,
    step: usize,
}

#[derive(Serialize)]
struct Data<'a> {
    checkpoint: usize,
    /// CSS fill per status code (none, RUNNING, SUCCESS, FAILURE).
    fill: [&'static str; 4],
    panels: Vec<PanelData<'a>>,
    divergences: Vec<Divergence<'a>>,
    /// Per panel, the robot's positions on the map: `[step, x, y, ...]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    map: Option<&'a [Vec<f32>]>,
}

fn round(t: f64) -> f64 {
    if t.is_finite() {
        (t * 1e4).round() / 1e4
    } else {
        0.0
    }
}

/// The page of a replay; each diagram rendered by Graphviz within `timeout`.
pub fn page(r: &Replay, timeout: Duration) -> Result<String, ViewError> {
    let mut body = String::new();
    let mut panels = Vec::new();
    let steps = r
        .panels
        .iter()
        .map(|p| p.rec.times.len())
        .max()
        .unwrap_or(0);
    // One time axis for all the timelines, so that their cursors line up.
    let t_end = (r.panels.iter())
        .flat_map(|p| {
            (p.rec.times.iter().copied())
                .chain(p.rows.iter().flat_map(|r| r.spans.iter().map(|s| s.start)))
        })
        .filter(|t| t.is_finite())
        .fold(0.0f64, f64::max);
    let map = r
        .map
        .as_ref()
        .map(|m| map_section(r, m))
        .unwrap_or_default();
    for (i, p) in r.panels.iter().enumerate() {
        panels.push(panel(&mut body, i, p, t_end, timeout)?);
    }
    let data = Data {
        checkpoint: CHECKPOINT_EVERY,
        fill: [
            "",
            Status::Running.fill_color(),
            Status::Success.fill_color(),
            Status::Failure.fill_color(),
        ],
        panels,
        divergences: divergence_steps(r, steps),
        map: r.map.as_ref().map(|m| m.tracks.as_slice()),
    };
    let body = format!("{map}<main class=\"panels cols-{}\">{body}</main>", cols(r));
    Ok(document(r, &body, &divergence_list(r), &data, steps))
}

/// Panel `i`'s section (its diagram and timeline) appended to `body`, and
/// the data the page's script needs to replay it.
fn panel<'a>(
    body: &mut String,
    i: usize,
    p: &'a Panel,
    t_end: f64,
    timeout: Duration,
) -> Result<PanelData<'a>, ViewError> {
    let prefix = format!("p{i}");
    let opts = DotOptions {
        svg_ids: true,
        ..Default::default()
    };
    let svg = render(&policy_dot(&p.policy, &opts), RenderFormat::Svg, timeout)?;
    let svg = inline_svg(&String::from_utf8_lossy(&svg), &prefix);
    let (tl, axis) = timeline::svg(&prefix, &p.rows, &p.marks, t_end);
    let _ = write!(
        body,
        r#"<section class="panel" id="{prefix}"><h2>{}</h2><p class="sub">{}</p><p class="now" id="{prefix}-now"></p><div class="diagram">{svg}</div><div class="tl">{tl}</div></section>"#,
        esc(&p.title),
        esc(&p.subtitle),
    );
    Ok(PanelData {
        ids: p.rec.keys.iter().map(|k| svg_id(k)).collect(),
        keys: &p.rec.keys,
        times: p.rec.times.iter().map(|&t| round(t)).collect(),
        deltas: p
            .rec
            .deltas
            .iter()
            .map(|d| d.iter().flat_map(|&(n, s)| [n, s as u32]).collect())
            .collect(),
        axis,
        digits: timeline::digits(t_end / 100.0).max(2),
    })
}

/// The map's section: `sim --plot`'s picture of the room and the runs'
/// paths, with one robot per panel (a circle in the run's colour, its
/// policy named in its tooltip) that the page's script moves.
fn map_section(r: &Replay, m: &super::Map) -> String {
    let svg = inline_svg(&m.svg, "map");
    let mut robots = String::new();
    for (i, p) in r.panels.iter().enumerate() {
        let c = btfsm_sim::plot::COLORS[i % btfsm_sim::plot::COLORS.len()];
        let _ = write!(
            robots,
            r##"<circle id="map-robot-{i}" class="robot" r="7" fill="{c}" stroke="#000" stroke-width="1.5" visibility="hidden"><title>{}</title></circle>"##,
            esc(&p.title)
        );
    }
    let svg = match svg.rfind("</svg>") {
        Some(k) => format!("{}{robots}{}", &svg[..k], &svg[k..]),
        None => svg,
    };
    format!(
        r#"<section class="map" id="map"><h2>Room</h2><p class="sub">the runs' paths (arrows: direction of travel); a circle per run is the robot at the current step</p><div class="room">{svg}</div></section>"#
    )
}

/// Each divergence with the step it is at (in its first panel's steps,
/// at most the last of the page's `steps`).
fn divergence_steps(r: &Replay, steps: usize) -> Vec<Divergence<'_>> {
    r.divergences
        .iter()
        .map(|d| Divergence {
            a: d.a,
            b: d.b,
            text: &d.text,
            step: r.panels[d.a]
                .rec
                .times
                .partition_point(|&t| t < d.t - 1e-9)
                .min(steps.saturating_sub(1)),
        })
        .collect()
}

/// The header's list of divergences, each with a button that goes to it
/// (or a line saying the runs are the same).
fn divergence_list(r: &Replay) -> String {
    let mut divs = String::new();
    if !r.divergences.is_empty() {
        divs.push_str(r#"<ul class="divs">"#);
        for (k, d) in r.divergences.iter().enumerate() {
            let _ = write!(
                divs,
                r#"<li><button class="go" data-div="{k}">go</button> <b>{}</b> vs <b>{}</b>: {}</li>"#,
                esc(&r.panels[d.a].title),
                esc(&r.panels[d.b].title),
                esc(&d.text)
            );
        }
        divs.push_str("</ul>");
    } else if r.panels.len() > 1 && r.compared_all {
        divs.push_str(r#"<p class="same">The executed skills of all the runs are the same, in the same order.</p>"#);
    }
    if r.panels.len() > 1 && !r.compared_all {
        divs.push_str(r#"<p class="same">Not every pair of runs was compared: runs of different inputs are compared when both are BehaviorTree.CPP logs (<code>btfsm log compare</code> compares a log with a simulator run).</p>"#);
    }
    divs
}

/// The whole HTML document: head, controls, the panels' `body`, the data
/// and the script.
fn document(r: &Replay, body: &str, divs: &str, data: &Data<'_>, steps: usize) -> String {
    let swatch = |s: Status, name: &str| {
        format!(
            r#"<span class="sw" style="background:{}"></span>{name} "#,
            s.fill_color()
        )
    };
    let mut html = String::with_capacity(body.len() + 4096);
    let _ = write!(
        html,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; script-src 'unsafe-inline'; img-src data:">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="btfsm view">
<title>{title}</title>
<style>{STYLE}</style></head>
<body>
<header><h1>{title}</h1><p class="sub">{sub}</p>{divs}</header>
<nav class="controls">
<button id="first" title="first step (Home)">|◀ first</button><button id="prev" title="previous step (←)">◀ prev</button><button id="play" title="play / pause (space)">play</button><button id="next" title="next step (→)">next ▶</button><button id="last" title="last step (End)">last ▶|</button>
<input id="slider" type="range" min="0" max="{max}" value="0" step="1" aria-label="step">
<span id="pos"></span>
<span class="legend">{r}{s}{f}</span>
<span class="hint">one step: {step_name}</span>
</nav>
{body}
<script type="application/json" id="btfsm-data">{json}</script>
<script>{SCRIPT}</script>
</body></html>
"#,
        title = esc(&r.title),
        sub = esc(&r.subtitle),
        max = steps.saturating_sub(1),
        r = swatch(Status::Running, "RUNNING"),
        s = swatch(Status::Success, "SUCCESS"),
        f = swatch(Status::Failure, "FAILURE"),
        step_name = esc(&r.step_name),
        json = script_json(data),
    );
    html
}

/// Columns of the panels' grid: four panels as two rows of two, more in
/// rows of three.
fn cols(r: &Replay) -> usize {
    match r.panels.len() {
        0 | 1 => 1,
        2 | 4 => 2,
        _ => 3,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn script_json_cannot_close_its_block() {
        let v = serde_json::json!({"k": "</script><script>alert(1)</script> & <!-- \u{202e}"});
        let s = script_json(&v);
        assert!(!s.contains('<') && !s.contains('>') && !s.contains('&'));
        assert!(!s.contains('\u{202e}'));
        let back: serde_json::Value = serde_json::from_str(&s).unwrap();
        assert_eq!(back, v, "the same data");
    }

    #[test]
    fn inline_svg_drops_the_prolog_and_comments_and_prefixes_ids() {
        let svg = "<?xml version=\"1.0\"?>\n<!DOCTYPE svg>\n<!-- x -->\n<svg a=\"1\"><g id=\"node1\"><!-- a --> --></g><title>t</title></svg>";
        assert_eq!(
            inline_svg(svg, "p3"),
            "<svg a=\"1\"><g id=\"p3-node1\"> --></g><title>t</title></svg>"
        );
    }

    #[test]
    fn esc_escapes_markup_and_controls() {
        assert_eq!(
            esc("<a href='x'>&\"\u{1b}"),
            "&lt;a href=&#39;x&#39;&gt;&amp;&quot;\\u{1b}"
        );
    }
}
