//! The diff drawing of the paper's Figs. 7 and 8: b with what an edit
//! script added highlighted, and a's removed elements as dashed grey ghosts
//! beside the vertices they were attached to.

use super::{Pair, Script, VertexRef};
use crate::render::dot::{DotOptions, Highlight};
use std::collections::{BTreeMap, BTreeSet};

impl Pair<'_> {
    pub fn dot_options(&self, script: &Script) -> DotOptions {
        let mut opts = DotOptions::default();
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
        for arc in &script.arcs_removed {
            let end = |k: &str| drawn.get(k).cloned().unwrap_or_else(|| k.to_string());
            for _ in 0..arc.count {
                opts.ghost_arcs
                    .push((end(&arc.from), end(&arc.to), arc.label.to_string()));
            }
        }
        opts
    }
}
