//! The timeline of a replay panel as SVG: one row per action (a skill with
//! its arguments, or a log's leaf node), a bar for each span it ran
//! (RUNNING, in the status colour `dot --trace` fills with), a mark at its
//! end in the colour of how it ended (SUCCESS green, FAILURE red, halted
//! grey), the first divergence from another run as a dashed red line, and
//! the cursor the page's script moves to the current step.

use super::html::esc;
use super::{Mark, Row, Span};
use btfsm_render::dot::Status;
use std::fmt::Write;

/// Width of the row labels, px.
const LABEL_W: f64 = 190.0;
/// Width of the time axis, px.
const PLOT_W: f64 = 560.0;
const ROW_H: f64 = 16.0;
const TOP: f64 = 8.0;
const AXIS_H: f64 = 26.0;
/// Rows drawn at most; the others are counted in a last row.
pub const MAX_ROWS: usize = 60;
/// Spans drawn at most (a bar each); past it the rest are counted.
pub const MAX_SPANS: usize = 20_000;

/// How a timeline maps time to x: what the page's script needs to move
/// the cursor.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Axis {
    /// x of time 0, px.
    pub x0: f64,
    /// px per second.
    pub scale: f64,
}

/// The fill of a mark for an action's outcome.
fn outcome_fill(outcome: &str) -> &'static str {
    match outcome {
        "success" => Status::Success.fill_color(),
        "failure" => Status::Failure.fill_color(),
        "running" => Status::Running.fill_color(),
        _ => "lightgrey",
    }
}

/// A step of 1, 2 or 5 times a power of ten giving about 6 ticks over `t`.
fn tick_step(t: f64) -> f64 {
    if !(t.is_finite() && t > 0.0) {
        return 1.0;
    }
    let raw = t / 6.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Decimals that tell apart times `step` apart (at least 2 for spans).
pub fn digits(step: f64) -> usize {
    if !(step.is_finite() && step > 0.0) {
        return 2;
    }
    (-step.log10().floor()).clamp(0.0, 9.0) as usize
}

/// `x` with at most `d` decimals, trailing zeros dropped.
fn num_with(x: f64, d: usize) -> String {
    let s = format!("{x:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The timeline SVG of a panel (`id` prefixes its element ids), over
/// `0..t_end` seconds, and its axis.
pub fn svg(id: &str, rows: &[Row], marks: &[Mark], t_end: f64) -> (String, Axis) {
    let t_end = if t_end.is_finite() && t_end > 0.0 {
        t_end
    } else {
        1.0
    };
    let scale = PLOT_W / t_end;
    let axis = Axis { x0: LABEL_W, scale };
    let step = tick_step(t_end);
    let tx = TimeX {
        t_end,
        scale,
        step,
        d: digits(step),
    };
    let shown_rows = rows.len().min(MAX_ROWS);
    let extra_row = rows.len() > MAX_ROWS;
    let n_rows = shown_rows + usize::from(extra_row);
    let h = TOP + ROW_H * n_rows.max(1) as f64 + AXIS_H;
    let w = LABEL_W + PLOT_W + 16.0;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" class="timeline" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica, Arial, sans-serif" font-size="11">"#
    );
    let bottom = TOP + ROW_H * n_rows.max(1) as f64;
    time_axis(&mut s, &tx, bottom);
    let spans_cut = draw_rows(&mut s, &tx, &rows[..shown_rows], marks);
    if extra_row || spans_cut > 0 {
        let y = TOP + ROW_H * shown_rows as f64;
        let _ = write!(
            s,
            r##"<text x="{}" y="{}" fill="#666">… {} more actions and {} more spans not drawn</text>"##,
            LABEL_W,
            y + ROW_H - 4.0,
            rows.len() - shown_rows,
            spans_cut
                + rows[shown_rows..]
                    .iter()
                    .map(|r| r.spans.len())
                    .sum::<usize>()
        );
    }
    for m in marks {
        let xm = tx.x(m.t);
        let _ = write!(
            s,
            r##"<g class="divergence"><title>{}</title><line x1="{xm:.2}" y1="{}" x2="{xm:.2}" y2="{bottom}" stroke="#d00000" stroke-width="1.5" stroke-dasharray="4 3"/><text x="{xm:.2}" y="{}" fill="#d00000" font-size="10">≠</text></g>"##,
            esc(&btfsm_core::sanitize::shown(&m.text)),
            TOP - 2.0,
            TOP + 6.0,
        );
    }
    let _ = write!(
        s,
        r##"<line id="{id}-cursor" class="cursor" x1="{LABEL_W}" y1="2" x2="{LABEL_W}" y2="{bottom}" stroke="#1f4fd0" stroke-width="2"/>"##
    );
    s.push_str("</svg>");
    (s, axis)
}

/// How a timeline places time: its span `0..t_end` s at `scale` px per
/// second, its tick `step` and the decimals `d` its ticks are shown with.
struct TimeX {
    t_end: f64,
    scale: f64,
    step: f64,
    d: usize,
}

impl TimeX {
    /// The x of time `t` (clamped to the span), px.
    fn x(&self, t: f64) -> f64 {
        LABEL_W + t.clamp(0.0, self.t_end) * self.scale
    }
}

/// The time axis under the rows (at `bottom`): its line, ticks with grid
/// lines, and title.
fn time_axis(s: &mut String, tx: &TimeX, bottom: f64) {
    let _ = write!(
        s,
        r##"<line x1="{LABEL_W}" y1="{bottom}" x2="{}" y2="{bottom}" stroke="#444"/>"##,
        LABEL_W + PLOT_W
    );
    let mut k = 0u32;
    while (k as f64) * tx.step <= tx.t_end + 1e-9 && k <= 20 {
        let t = k as f64 * tx.step;
        let xt = tx.x(t);
        let _ = write!(
            s,
            r##"<line x1="{xt}" y1="{TOP}" x2="{xt}" y2="{}" stroke="#ddd"/><text x="{xt}" y="{}" text-anchor="middle" fill="#444">{}</text>"##,
            bottom + 4.0,
            bottom + 15.0,
            num_with(t, tx.d)
        );
        k += 1;
    }
    let _ = write!(
        s,
        r##"<text x="{}" y="{}" text-anchor="end" fill="#444">time (s)</text>"##,
        LABEL_W - 6.0,
        bottom + 15.0
    );
}

/// The rows: each one's label and spans, at most [`MAX_SPANS`] spans in
/// all; how many spans were left out.
fn draw_rows(s: &mut String, tx: &TimeX, rows: &[Row], marks: &[Mark]) -> usize {
    let mut spans_left = MAX_SPANS;
    let mut spans_cut = 0usize;
    for (r, row) in rows.iter().enumerate() {
        let y = TOP + ROW_H * r as f64;
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
            LABEL_W - 6.0,
            y + ROW_H - 4.0,
            esc(&btfsm_core::sanitize::shown_max(&row.label, 32))
        );
        for sp in &row.spans {
            if spans_left == 0 {
                spans_cut += 1;
                continue;
            }
            spans_left -= 1;
            let marked = marks.iter().any(|m| m.index == sp.index);
            span_bar(s, tx, &row.label, sp, y, marked);
        }
    }
    spans_cut
}

/// One span of a row at `y`: a RUNNING bar (red-edged where the run
/// diverged: `marked`) and, if it ended, a mark in its outcome's colour.
fn span_bar(s: &mut String, tx: &TimeX, label: &str, sp: &Span, y: f64, marked: bool) {
    let num = |x: f64| num_with(x, tx.d + 2);
    let x0 = tx.x(sp.start);
    let x1 = tx.x(sp.end.unwrap_or(tx.t_end)).max(x0 + 1.5);
    let stroke = if marked { "#d00000" } else { "goldenrod" };
    let _ = write!(
        s,
        r#"<g class="span{}"><title>{} {}: {} s to {} s</title><rect x="{x0:.2}" y="{}" width="{:.2}" height="{}" fill="{}" stroke="{stroke}" stroke-width="{}"/>"#,
        if marked { " diverged" } else { "" },
        esc(&btfsm_core::sanitize::shown(label)),
        esc(&sp.outcome),
        num(sp.start),
        sp.end.map_or("the end".to_string(), num),
        y + 3.0,
        x1 - x0,
        ROW_H - 6.0,
        Status::Running.fill_color(),
        if marked { 2 } else { 1 },
    );
    if sp.end.is_some() {
        let _ = write!(
            s,
            r##"<rect x="{:.2}" y="{}" width="5" height="{}" fill="{}" stroke="#333" stroke-width="0.7"/>"##,
            x1 - 2.5,
            y + 1.0,
            ROW_H - 2.0,
            outcome_fill(&sp.outcome)
        );
    }
    s.push_str("</g>");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_numbers() {
        assert_eq!(tick_step(60.0), 10.0);
        assert_eq!(tick_step(7.0), 2.0);
        assert_eq!(tick_step(0.3), 0.05);
        assert_eq!(tick_step(0.0), 1.0);
        assert_eq!(tick_step(0.0046), 0.001);
        assert_eq!(digits(0.001), 3);
        assert_eq!(digits(10.0), 0);
        assert_eq!(num_with(0.0030, 3), "0.003");
        assert_eq!(num_with(20.0, 0), "20");
    }

    #[test]
    fn rows_spans_and_marks_are_drawn_and_bounded() {
        let span = |i: usize| Span {
            start: i as f64,
            end: Some(i as f64 + 0.5),
            outcome: if i.is_multiple_of(2) {
                "success"
            } else {
                "failure"
            }
            .into(),
            index: i,
        };
        let rows: Vec<Row> = (0..MAX_ROWS + 5)
            .map(|r| Row {
                label: format!("Skill{r}(<x>)"),
                spans: (0..3).map(|i| span(r * 3 + i)).collect(),
            })
            .collect();
        let marks = vec![Mark {
            t: 4.0,
            index: 4,
            text: "</svg><script>".into(),
        }];
        let (s, axis) = svg("p0", &rows, &marks, 200.0);
        assert_eq!(axis.x0, LABEL_W);
        assert_eq!(s.matches("<text x=\"184\"").count(), MAX_ROWS + 1);
        assert!(s.contains("… 5 more actions and 15 more spans"));
        assert_eq!(s.matches("class=\"span diverged\"").count(), 1);
        assert!(s.contains("Skill0(&lt;x&gt;)"));
        assert!(!s.contains("<script"));
        assert!(s.contains("id=\"p0-cursor\""));
    }
}
