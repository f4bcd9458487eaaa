//! The diff drawing of the paper's Figs. 7 and 8: b with what an edit
//! script added highlighted (magenta, as Fig. 8, a colour no transition
//! label uses), a's removed elements as dashed grey ghosts beside the
//! vertices they were attached to (a removed BT child in its old place
//! among its siblings), kept elements that changed (relabels, reorders:
//! `changes.rs`) marked with their old value, a title naming both files and
//! a legend.

use super::changes::child_positions;
use super::changes_text::{changed_window, list_items};
use super::{Pair, Script, VertexRef};
use btfsm_core::sanitize::shown_max;
use btfsm_model::PolicyBody;
use btfsm_render::dot::{DotOptions, Highlight};
use std::collections::{BTreeMap, BTreeSet};

/// Longest line of a drawing's change note (the old value is cut after it).
const NOTE_CHARS: usize = 120;

impl Pair<'_> {
    /// `a → b`, each file escaped and cut as in a message.
    pub fn title(&self) -> String {
        format!(
            "{} → {}",
            shown_max(self.a.file, 80),
            shown_max(self.b.file, 80)
        )
    }

    /// What changed on each kept vertex of b (by key), one `was` line per
    /// relabel or reorder, as the drawings show it; the machine's own
    /// initial state under the key `""`.
    pub(super) fn change_notes(&self, script: &Script) -> BTreeMap<String, String> {
        let mut notes: BTreeMap<String, String> = BTreeMap::new();
        let mut add = |k: &str, line: String| {
            let e = notes.entry(k.to_string()).or_default();
            if !e.is_empty() {
                e.push('\n');
            }
            e.push_str(&line);
        };
        for r in &script.reordered {
            let (before, _) = changed_window(&r.before, &r.after);
            let list = list_items(before, |t| t.to_string());
            let what = if r.of == "guards" {
                "guard order"
            } else {
                "order"
            };
            let line = format!("{what} was: {list}");
            add(&r.key, shown_max(&line, NOTE_CHARS).into_owned());
        }
        for r in &script.relabelled {
            let line = match &r.to {
                Some(to) => format!("{} to {to} was: {}", r.what, r.before),
                None => format!("{} was: {}", r.what, r.before),
            };
            add(&r.key, shown_max(&line, NOTE_CHARS).into_owned());
        }
        notes
    }

    pub fn dot_options(&self, script: &Script) -> DotOptions {
        let mut opts = DotOptions {
            legend: true,
            ..DotOptions::default()
        };
        let mut notes = self.change_notes(script);
        let top = notes.remove("");
        opts.title = Some(match top {
            Some(t) => format!("{}\n{t}", self.title()),
            None => self.title(),
        });
        opts.changed = notes;
        for a in &script.arcs_kept {
            if let Some(old) = &a.label_in_a {
                opts.changed_arcs.insert(
                    (a.from.to_string(), a.to.to_string(), a.label.to_string()),
                    old.to_string(),
                );
            }
        }
        for v in &script.vertices_added {
            opts.highlight.insert(v.key.to_string(), Highlight::Added);
        }
        for arc in &script.arcs_added {
            opts.arc_label_highlight.insert(
                (
                    arc.from.to_string(),
                    arc.to.to_string(),
                    arc.label.to_string(),
                ),
                Highlight::Added,
            );
        }
        // a's keys as drawn in b: kept vertices under their image, removed
        // ones under a ghost key that cannot collide with a key of b.
        let mut taken: BTreeSet<String> = self.gb.g.node_weights().map(|v| v.key.clone()).collect();
        let mut drawn: BTreeMap<&str, String> = script
            .vertices_kept
            .iter()
            .map(|k| (k.a.as_str(), k.b.to_string()))
            .collect();
        // Containers before what they contain, so that a removed state is
        // drawn inside its container's cluster in b, or beside its ghost.
        let depth = |k: &str| {
            let mut d = 0usize;
            let mut cur = k;
            while let Some(p) = self.parent_a.get(cur) {
                d += 1;
                cur = p;
            }
            d
        };
        let mut removed: Vec<&VertexRef> = script.vertices_removed.iter().collect();
        removed.sort_by_cached_key(|v| depth(&v.key));
        for v in removed {
            let leaf = v.key.rsplit('/').next().unwrap_or(&v.key);
            let mut ghost = match self
                .parent_a
                .get(v.key.as_str())
                .and_then(|p| drawn.get(p.as_str()))
            {
                Some(parent) => format!("{parent}/{leaf}"),
                None => v.key.to_string(),
            };
            while taken.contains(&ghost) {
                ghost.push_str(" (removed)");
            }
            taken.insert(ghost.clone());
            opts.ghost_vertices
                .push((ghost.clone(), v.name.to_string()));
            drawn.insert(v.key.as_str(), ghost);
        }
        let order = self.bt_places(script, &drawn);
        for (i, &(k, _)) in order.iter().enumerate() {
            let arc = &script.arcs_removed[k];
            let end = |k: &str| drawn.get(k).cloned().unwrap_or_else(|| k.to_string());
            for _ in 0..arc.count {
                if let Some(slot) = order[i].1 {
                    opts.ghost_slot.insert(opts.ghost_arcs.len(), slot);
                }
                opts.ghost_arcs
                    .push((end(&arc.from), end(&arc.to), arc.label.to_string()));
            }
        }
        opts
    }

    /// The removed arcs of `script` in drawing order, each with its place
    /// among the children of its tail in b when that tail is drawn as a
    /// vertex of b. For a BT: by the tail's pre-order in a, then the child's
    /// place among its siblings in a; the place in b is just after the
    /// image of the nearest earlier sibling (in a) that is still a child of
    /// the tail's image (0 when none is). For a machine: script order, no
    /// place.
    fn bt_places(
        &self,
        script: &Script,
        drawn: &BTreeMap<&str, String>,
    ) -> Vec<(usize, Option<usize>)> {
        let plain = || (0..script.arcs_removed.len()).map(|k| (k, None)).collect();
        let (PolicyBody::Bt(a), PolicyBody::Bt(b)) = (&self.a.policy.body, &self.b.policy.body)
        else {
            return plain();
        };
        let mut rank = vec![0usize; a.nodes.len()];
        for (r, u) in a.preorder().into_iter().enumerate() {
            rank[u] = r;
        }
        let (pos_a, pos_b) = (child_positions(a), child_positions(b));
        let parent_b = b.parents();
        let image = |u: usize| {
            drawn
                .get(self.ia.key(u).as_str())
                .and_then(|k| self.ib.find(k))
        };
        let mut out: Vec<(usize, usize, usize, Option<usize>)> = Vec::new();
        for (k, arc) in script.arcs_removed.iter().enumerate() {
            let (Some(t), Some(h)) = (self.ia.find(&arc.from), self.ia.find(&arc.to)) else {
                return plain();
            };
            let (Some(node), Some(&p)) = (a.nodes.get(t), pos_a.get(h)) else {
                return plain();
            };
            // The tail drawn as b's vertex: the child's place among b's.
            let slot = image(t).map(|tb| {
                node.children[..p.min(node.children.len())]
                    .iter()
                    .rev()
                    .filter_map(|&s| image(s))
                    .find(|&s| parent_b.get(s).copied().flatten() == Some(tb))
                    .map_or(0, |s| pos_b[s] + 1)
            });
            out.push((rank[t], p, k, slot));
        }
        out.sort_unstable();
        out.into_iter().map(|x| (x.2, x.3)).collect()
    }
}
