//! Label placement for the simulator plot: each label goes to the first of a
//! few candidate positions around its anchor (right, left, above, below) that
//! covers the least already drawn ink, the greedy point-feature labelling
//! that cartography uses (Christensen, Marks & Shieber, "An empirical study
//! of algorithms for point-feature label placement", ACM TOG 14(3), 1995,
//! the four- and eight-position models).
//!
//! Ink is counted on a sparse grid of [`CELL`]-pixel cells with a weight per
//! kind (a trajectory counts less than a marker or another label), so one
//! placement costs the area of its candidates, not the number of things
//! drawn: the plot stays linear in the number of stations, objects and
//! events.

use std::collections::HashMap;

/// Grid cell, px.
const CELL: f64 = 6.0;
/// Average advance of a Helvetica glyph, as a fraction of the font size.
const GLYPH: f64 = 0.56;

/// How much a covered cell costs a label placed over it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Ink {
    /// A trajectory passes.
    Path = 1,
    /// A wall or obstacle edge.
    Edge = 2,
    /// A marker, station cross, waypoint or object.
    Mark = 6,
    /// A label already placed.
    Text = 12,
}

/// A box in pixels: left, top, right, bottom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BBox {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl BBox {
    pub(super) fn around(x: f64, y: f64, r: f64) -> BBox {
        BBox {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        }
    }
}

/// Where a label goes: the text's anchor point and its SVG `text-anchor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Spot {
    pub x: f64,
    pub y: f64,
    pub anchor: &'static str,
    /// The weighted ink the label covers there (0: nothing under it).
    pub cost: u32,
}

/// The ink drawn so far, per grid cell.
#[derive(Debug, Default)]
pub(super) struct Placer {
    cells: HashMap<(i64, i64), u32>,
    /// Labels are kept inside this box (the drawing), when set.
    bounds: Option<BBox>,
}

fn cell(v: f64) -> i64 {
    (v / CELL).floor() as i64
}

impl Placer {
    pub(super) fn new(bounds: BBox) -> Self {
        Placer {
            cells: HashMap::new(),
            bounds: Some(bounds),
        }
    }

    /// Records ink over a box.
    pub(super) fn mark(&mut self, b: BBox, ink: Ink) {
        for i in cell(b.x0)..=cell(b.x1) {
            for j in cell(b.y0)..=cell(b.y1) {
                *self.cells.entry((i, j)).or_default() += ink as u32;
            }
        }
    }

    /// Records ink along a segment: sampled every half cell, so no cell it
    /// crosses lengthwise is skipped.
    pub(super) fn line(&mut self, a: (f64, f64), b: (f64, f64), ink: Ink) {
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let n = (2.0 * len / CELL).ceil().max(1.0) as usize;
        let mut last = None;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let c = (cell(a.0 + t * (b.0 - a.0)), cell(a.1 + t * (b.1 - a.1)));
            if last != Some(c) {
                *self.cells.entry(c).or_default() += ink as u32;
                last = Some(c);
            }
        }
    }

    fn cost(&self, b: BBox) -> u32 {
        let mut sum = 0u32;
        for i in cell(b.x0)..=cell(b.x1) {
            for j in cell(b.y0)..=cell(b.y1) {
                sum = sum.saturating_add(self.cells.get(&(i, j)).copied().unwrap_or(0));
            }
        }
        if let Some(f) = self.bounds
            && (b.x0 < f.x0 || b.y0 < f.y0 || b.x1 > f.x1 || b.y1 > f.y1)
        {
            sum = sum.saturating_add(1000);
        }
        sum
    }

    /// Places `text` of font size `size` next to a point feature of radius
    /// `r` at `(x, y)`: the cheapest of eight positions (ties go to the
    /// earlier: right above, right below, left above, left below, above,
    /// below, right, left), then records the label's ink.
    pub(super) fn place(&mut self, x: f64, y: f64, r: f64, text: &str, size: f64) -> Spot {
        let w = text.chars().count() as f64 * size * GLYPH;
        let h = size;
        let g = r + 2.0;
        // (text x, baseline y, anchor, box left offset from text x)
        let candidates: [(f64, f64, &'static str, f64); 8] = [
            (x + g, y - g, "start", 0.0),
            (x + g, y + g + h, "start", 0.0),
            (x - g, y - g, "end", -w),
            (x - g, y + g + h, "end", -w),
            (x, y - g - 1.0, "middle", -w / 2.0),
            (x, y + g + h + 1.0, "middle", -w / 2.0),
            (x + g + 1.0, y + h / 2.0 - 1.0, "start", 0.0),
            (x - g - 1.0, y + h / 2.0 - 1.0, "end", -w),
        ];
        let mut best: Option<(u32, Spot, BBox)> = None;
        for (tx, ty, anchor, dx) in candidates {
            let b = BBox {
                x0: tx + dx,
                y0: ty - h * 0.8,
                x1: tx + dx + w,
                y1: ty + h * 0.2,
            };
            let c = self.cost(b);
            if best.as_ref().is_none_or(|(bc, _, _)| c < *bc) {
                let spot = Spot {
                    x: tx,
                    y: ty,
                    anchor,
                    cost: c,
                };
                best = Some((c, spot, b));
                if c == 0 {
                    break;
                }
            }
        }
        let (_, spot, b) = best.expect("eight candidates");
        self.mark(b, Ink::Text);
        spot
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Placer {
        Placer::new(BBox {
            x0: 0.0,
            y0: 0.0,
            x1: 500.0,
            y1: 500.0,
        })
    }

    #[test]
    fn a_free_label_goes_right_above() {
        let mut p = frame();
        let s = p.place(100.0, 100.0, 4.0, "delivery", 11.0);
        assert_eq!((s.anchor, s.cost), ("start", 0));
        assert!(s.x > 100.0 && s.y < 100.0);
    }

    #[test]
    fn a_label_avoids_a_marker_on_its_first_choice() {
        let mut p = frame();
        // A marker right above the anchor where the label would go first.
        p.mark(BBox::around(120.0, 92.0, 7.0), Ink::Mark);
        let s = p.place(100.0, 100.0, 4.0, "start", 11.0);
        assert_eq!(s.cost, 0, "{s:?}");
        assert!(s.y > 100.0 || s.x < 100.0, "moved away: {s:?}");
    }

    #[test]
    fn two_labels_at_one_point_do_not_overlap() {
        let mut p = frame();
        let a = p.place(200.0, 200.0, 4.0, "cube1", 10.0);
        let b = p.place(200.0, 200.0, 4.0, "cube2", 10.0);
        assert_eq!((a.cost, b.cost), (0, 0));
        assert_ne!((a.x, a.y), (b.x, b.y));
    }

    #[test]
    fn labels_stay_inside_the_drawing() {
        let mut p = frame();
        let s = p.place(495.0, 5.0, 3.0, "a long station name", 11.0);
        assert_eq!(s.anchor, "end", "{s:?}");
        assert!(s.y > 5.0, "below the top edge: {s:?}");
    }

    #[test]
    fn a_long_segment_marks_cells_along_it_only() {
        let mut p = frame();
        p.line((0.0, 0.0), (600.0, 0.0), Ink::Path);
        assert_eq!(p.cells.len(), 101);
        assert!(p.cells.values().all(|&v| v == Ink::Path as u32));
    }
}
