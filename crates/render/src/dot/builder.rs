//! The builder of a policy's DOT graph: BT nodes and edges, FSM states,
//! HFSM clusters with their outcome boxes, highlights, ghosts, the title and
//! the legend.

use super::*;
use btfsm_model::{Bt, Region, State, StateBody, StateMachine, Target, Transition, Trigger};
use graphviz_rust::dot_structures::{Stmt, Subgraph};
use std::collections::{HashMap, HashSet};

pub(super) struct Builder<'o> {
    pub(super) opts: &'o DotOptions,
    /// Top-level statements (nodes, clusters), before the edges.
    pub(super) root: Vec<Stmt>,
    pub(super) edges: Vec<Stmt>,
    /// DOT node ids in use.
    pub(super) used: HashSet<String>,
    /// Vertex key -> DOT node id, for arcs given by key (ghost arcs).
    pub(super) by_key: HashMap<String, String>,
    /// Container key -> container, for placing ghost vertices.
    pub(super) container_of_key: HashMap<String, usize>,
    /// Statements added to a cluster (`Some(container)`) or to the top level
    /// (`None`) besides its states: ghosts, clusters nested too deep.
    pub(super) extra: HashMap<Option<usize>, Vec<Stmt>>,
    /// Per state: its node, or for a container its cluster once assembled.
    pub(super) state_stmt: Vec<Option<Stmt>>,
    /// Per container: cluster attributes and entry node; outcome boxes.
    pub(super) header: Vec<Vec<Stmt>>,
    pub(super) footer: Vec<Vec<Stmt>>,
    /// Clusters to assemble, deepest first.
    pub(super) clusters: Vec<ClusterPlan>,
    /// Top-level states in order, and what follows them (outcomes).
    pub(super) top_states: Vec<usize>,
    pub(super) top_tail: Vec<Stmt>,
    /// `(position in edges, ghost arc)`: ghost arcs of a BT drawn among
    /// their tail's children, in edge order.
    pub(super) bt_ghost_slots: Vec<(usize, usize)>,
}

/// How one container's cluster is put together.
pub(super) struct ClusterPlan {
    container: usize,
    name: String,
    /// The states of its region, in file order.
    children: Vec<usize>,
    /// Where the cluster goes: inside its parent's cluster (`true`), or, when
    /// nested too deep, beside it in the cluster `slot`.
    in_parent: bool,
    slot: Option<usize>,
}

impl<'o> Builder<'o> {
    pub(super) fn new(opts: &'o DotOptions) -> Self {
        Builder {
            opts,
            root: Vec::new(),
            edges: Vec::new(),
            used: HashSet::new(),
            by_key: HashMap::new(),
            container_of_key: HashMap::new(),
            extra: HashMap::new(),
            state_stmt: Vec::new(),
            header: Vec::new(),
            footer: Vec::new(),
            clusters: Vec::new(),
            top_states: Vec::new(),
            top_tail: Vec::new(),
            bt_ghost_slots: Vec::new(),
        }
    }

    /// Puts the clusters together, deepest first, then the top level.
    pub(super) fn assemble(&mut self) {
        for plan in std::mem::take(&mut self.clusters) {
            let c = plan.container;
            let mut stmts = std::mem::take(&mut self.header[c]);
            for j in plan.children {
                stmts.extend(self.state_stmt[j].take());
            }
            stmts.extend(self.extra.remove(&Some(c)).unwrap_or_default());
            stmts.append(&mut self.footer[c]);
            let sub = Stmt::Subgraph(Subgraph {
                id: dot_id(&plan.name),
                stmts,
            });
            if plan.in_parent {
                self.state_stmt[c] = Some(sub);
            } else {
                self.extra.entry(plan.slot).or_default().push(sub);
            }
        }
        for j in std::mem::take(&mut self.top_states) {
            self.root.extend(self.state_stmt[j].take());
        }
        // States no region lists (none in a valid machine) are still drawn.
        for s in std::mem::take(&mut self.state_stmt) {
            self.root.extend(s);
        }
        self.root
            .extend(self.extra.remove(&None).unwrap_or_default());
        self.root.append(&mut self.top_tail);
    }

    /// A DOT node id not used yet, `base` if possible.
    pub(super) fn fresh(&mut self, base: &str) -> String {
        let mut id = base.to_string();
        while self.used.contains(&id) {
            id.push('\'');
        }
        self.used.insert(id.clone());
        id
    }

    /// Registers a vertex and returns its DOT node id.
    pub(super) fn vertex(&mut self, key: &str) -> String {
        let id = self.fresh(key);
        self.by_key.entry(key.to_string()).or_insert(id.clone());
        id
    }

    pub(super) fn vhl(&self, key: &str) -> Option<&'o Highlight> {
        self.opts.highlight.get(key)
    }

    pub(super) fn ahl(&self, from: &str, to: &str, label: &str) -> Option<&'o Highlight> {
        let (from, to) = (from.to_string(), to.to_string());
        if !self.opts.arc_label_highlight.is_empty() {
            let key = (from, to, label.to_string());
            if let Some(h) = self.opts.arc_label_highlight.get(&key) {
                return Some(h);
            }
            return self.opts.arc_highlight.get(&(key.0, key.1));
        }
        self.opts.arc_highlight.get(&(from, to))
    }

    // --- Behavior Trees -----------------------------------------------------

    pub(super) fn bt(&mut self, bt: &Bt, view: &super::bt::View) {
        let ids: Vec<String> = bt.nodes.iter().map(|n| self.vertex(&n.id)).collect();
        // In arena order (pre-order for a file read), hidden nodes left out.
        let drawn: Vec<usize> = (0..bt.nodes.len()).filter(|&i| view.shown[i]).collect();
        for &i in &drawn {
            let (n, id) = (&bt.nodes[i], &ids[i]);
            let mut a = super::bt::bt_node_attrs(n, view.folded[i], self.opts.ports);
            a.node_highlight(self.vhl(&n.id));
            a.changed(self.opts.changed.get(&n.id));
            self.root.push(node_stmt(id, a));
        }
        // Ghost arcs with a slot among a drawn node's children, by tail.
        let mut slotted: HashMap<&str, Vec<(usize, usize)>> = HashMap::new();
        for (&g, &slot) in &self.opts.ghost_slot {
            if let Some((from, _, _)) = self.opts.ghost_arcs.get(g) {
                slotted.entry(from.as_str()).or_default().push((slot, g));
            }
        }
        for &i in &drawn {
            if view.folded[i].is_some() {
                continue;
            }
            let (n, id) = (&bt.nodes[i], &ids[i]);
            let mut ghosts = slotted.remove(n.id.as_str()).unwrap_or_default();
            ghosts.sort_unstable();
            let mut ghosts = ghosts.into_iter().peekable();
            for (k, &c) in n.children.iter().enumerate() {
                while let Some((_, g)) = ghosts.next_if(|&(slot, _)| slot <= k) {
                    self.bt_ghost_slots.push((self.edges.len(), g));
                }
                let mut a = Attrs::default();
                a.edge_highlight(self.ahl(&n.id, &bt.nodes[c].id, ""));
                self.edges.push(edge_stmt(id, &ids[c], a));
            }
            for (_, g) in ghosts {
                self.bt_ghost_slots.push((self.edges.len(), g));
            }
        }
    }

    // --- FSMs and HFSMs -----------------------------------------------------

    /// An FSM or HFSM: vertex ids, state nodes, the top level's outcomes and
    /// start, the clusters' plans, then the edges.
    pub(super) fn machine(&mut self, m: &StateMachine) {
        let n = m.states.len();
        let ids = self.machine_ids(m);
        self.state_stmt = vec![None; n];
        self.header = vec![Vec::new(); n];
        self.footer = vec![Vec::new(); n];
        for i in 0..n {
            self.state_node(&ids, i);
        }
        self.top_level(&ids);
        self.plan_clusters(&ids);
        for i in 0..n {
            self.state_edges(&ids, i);
        }
    }

    /// Registers the machine's vertex ids: states, top outcomes, then the
    /// extra outcome boxes of the containers, so that every vertex keeps its
    /// key as its id.
    fn machine_ids<'m>(&mut self, m: &'m StateMachine) -> MachineIds<'m> {
        // Vertices are identified by the graph's keys (SPEC §3 identity),
        // so that highlights and ghosts given by key find them.
        let key: Vec<String> = m.keys();
        let state_id: Vec<String> = key.iter().map(|p| self.vertex(p)).collect();
        let top_outcome_id: Vec<String> = m.top.outcomes.iter().map(|o| self.vertex(o)).collect();
        let mut outcome_box: HashMap<(usize, &str), String> = HashMap::new();
        for (i, p) in key.iter().enumerate() {
            if let StateBody::Container(r) = &m.states[i].body {
                self.container_of_key.insert(p.clone(), i);
                for o in &r.outcomes {
                    let id = self.fresh(&format!("{p}/{o}"));
                    outcome_box.insert((i, o.as_str()), id);
                }
            }
        }
        MachineIds {
            m,
            key,
            state_id,
            top_outcome_id,
            outcome_box,
        }
    }

    /// The node of state `i`, or for a container its cluster's header and
    /// footer.
    fn state_node(&mut self, ids: &MachineIds<'_>, i: usize) {
        let (m, key) = (ids.m, &ids.key);
        let s = &m.states[i];
        if let StateBody::Container(r) = &s.body {
            // A region of a parallel state: a dashed box, as UML
            // separates orthogonal regions with dashed lines.
            let orthogonal = s.parent.is_some_and(
                |p| matches!(&m.states[p].body, StateBody::Container(pr) if pr.parallel),
            );
            self.container_nodes(i, &s.label, &key[i], r, orthogonal, &ids.outcome_box);
            return;
        }
        let mut a = state_attrs(s, &key[i]);
        if s.parent.is_none() && m.top.initial == Target::State(i) {
            a.set("penwidth", "2.2");
        }
        a.node_highlight(self.vhl(&key[i]));
        a.changed(self.opts.changed.get(&key[i]));
        self.state_stmt[i] = Some(node_stmt(&ids.state_id[i], a));
    }

    /// The top level's outcome nodes and states, and its initial state as
    /// UML marks it: a filled dot and an arrow (containers mark theirs with
    /// their own dot, a vertex). Neither is a vertex nor an arc of the graph.
    fn top_level(&mut self, ids: &MachineIds<'_>) {
        let m = ids.m;
        for (o, id) in m.top.outcomes.iter().zip(&ids.top_outcome_id) {
            let mut a = Attrs::default();
            a.set("label", o)
                .set("shape", "doublecircle")
                .set("fontsize", "9")
                .set("margin", "0.02");
            a.node_highlight(self.vhl(o));
            self.top_tail.push(node_stmt(id, a));
        }
        if !ids.top_outcome_id.is_empty() {
            self.top_tail.push(rank_group("sink", &ids.top_outcome_id));
        }
        self.top_states = m.top.states.clone();
        if let Target::State(j) = m.top.initial {
            let start = self.fresh(START);
            let mut a = Attrs::default();
            a.set("shape", "point")
                .set("width", "0.15")
                .set("tooltip", "initial state");
            self.top_tail.push(node_stmt(&start, a));
            let mut e = Attrs::default();
            if ids.region(j).is_some() {
                e.set("lhead", &ids.cluster_name(j));
            }
            e.set("class", "start");
            self.edges.push(edge_stmt(&start, &ids.state_id[j], e));
        }
    }

    /// The clusters' plans, deepest first; below `MAX_CLUSTER_NESTING` a
    /// cluster goes beside its parent's instead of inside it.
    fn plan_clusters(&mut self, ids: &MachineIds<'_>) {
        let m = ids.m;
        let n = m.states.len();
        // Nesting levels, parents before children, without recursion.
        let mut level = vec![0usize; n];
        for c in m.parents_first() {
            level[c] = m.states[c].parent.map_or(0, |p| level[p] + 1);
        }
        let mut by_level: Vec<usize> = (0..n).filter(|&i| ids.region(i).is_some()).collect();
        by_level.sort_by_key(|&i| (level[i], i));
        let mut slot: Vec<Option<usize>> = vec![None; n];
        for &i in &by_level {
            slot[i] = match m.states[i].parent {
                Some(p) if level[i] >= MAX_CLUSTER_NESTING => slot[p],
                parent => parent,
            };
        }
        for &i in by_level.iter().rev() {
            self.clusters.push(ClusterPlan {
                container: i,
                name: ids.cluster_name(i),
                children: ids.region(i).map(|r| r.states.clone()).unwrap_or_default(),
                in_parent: slot[i] == m.states[i].parent,
                slot: slot[i],
            });
        }
    }

    /// The edges of state `i`: into a container's initial states, then one
    /// per transition.
    fn state_edges(&mut self, ids: &MachineIds<'_>, i: usize) {
        let (m, key, state_id) = (ids.m, &ids.key, &ids.state_id);
        if let Some(r) = ids.region(i) {
            for j in r.entered(&m.states) {
                let mut a = Attrs::default();
                if ids.region(j).is_some() {
                    a.set("lhead", &ids.cluster_name(j));
                }
                a.edge_highlight(self.ahl(&key[i], &key[j], "initial"));
                self.edges.push(edge_stmt(&state_id[i], &state_id[j], a));
            }
        }
        for t in &m.states[i].transitions {
            self.transition_edge(ids, i, t);
        }
    }

    /// The edge of transition `t` of state `i`, coloured by its trigger,
    /// highlighted, and showing the old label of a changed arc.
    fn transition_edge(&mut self, ids: &MachineIds<'_>, i: usize, t: &Transition) {
        let (m, key, state_id) = (ids.m, &ids.key, &ids.state_id);
        let s = &m.states[i];
        let mut a = Attrs::default();
        // Tail: a container's outcome transitions leave from its
        // outcome box, anything else from the state's node.
        let tail = match &t.trigger {
            Trigger::Outcome(o) => ids.outcome_box.get(&(i, o.as_str())),
            Trigger::Guard(_) => None,
        }
        .unwrap_or(&state_id[i])
        .clone();
        let (head, to_key) = ids.head(i, t, &mut a);
        if ids.region(i).is_some() && tail == state_id[i] && head != state_id[i] {
            a.set("ltail", &ids.cluster_name(i));
        }
        if head == tail && matches!(s.body, StateBody::Decision) {
            // A decision state's arcs leave on every side; its
            // self-loop goes below it, clear of their labels.
            a.set("tailport", "s").set("headport", "s");
        }
        let color = match &t.trigger {
            Trigger::Outcome(o) => Status::from_outcome(o).map_or("black", Status::line_color),
            Trigger::Guard(_) => GUARD,
        };
        let label = t.trigger.label();
        a.set("label", &label)
            .set("color", color)
            .set("fontcolor", color);
        a.edge_highlight(self.ahl(&key[i], &to_key, &label));
        let was = (key[i].clone(), to_key, label);
        if let Some(old) = self.opts.changed_arcs.get(&was) {
            a.set("label", &format!("{}\n(was {old})", was.2))
                .set("color", CHANGED)
                .set("fontcolor", CHANGED);
        }
        self.edges.push(edge_stmt(&tail, &head, a));
    }

    /// A container's cluster header (attributes, its own vertex as a dot) and
    /// footer (its outcome boxes, side by side).
    pub(super) fn container_nodes(
        &mut self,
        i: usize,
        label: &str,
        key: &str,
        r: &btfsm_model::Region,
        orthogonal: bool,
        outcome_box: &HashMap<(usize, &str), String>,
    ) {
        let mut ca = Attrs::default();
        // A parallel state says so in its label (UML's regions).
        let shown_label = if r.parallel {
            format!("{label} ‖")
        } else {
            label.to_string()
        };
        ca.set("label", &shown_label)
            .set("fontname", FONT)
            .set("fontsize", "11")
            .set("labeljust", "l")
            .set("color", "grey40")
            .style(if orthogonal { "dashed" } else { "rounded" });
        match self.vhl(key) {
            Some(Highlight::Added) => {
                ca.set("color", ADDED)
                    .set("fontcolor", ADDED)
                    .set("penwidth", "2.5");
            }
            Some(Highlight::Removed) => {
                ca.style("dashed")
                    .set("color", REMOVED)
                    .set("fontcolor", REMOVED);
            }
            Some(Highlight::Status(st)) => {
                ca.style("filled").set("fillcolor", st.fill_color());
            }
            None => {}
        }
        ca.changed(self.opts.changed.get(key));
        if self.opts.svg_ids {
            ca.set("id", &svg_cluster_id(key));
        }
        let mut header: Vec<Stmt> = ca.into_vec().into_iter().map(Stmt::Attribute).collect();
        let mut ea = Attrs::default();
        ea.set("shape", "point")
            .set("width", "0.12")
            .set("tooltip", key);
        ea.node_highlight(self.vhl(key));
        let id = self.by_key.get(key).cloned().unwrap_or_else(|| key.into());
        header.push(node_stmt(&id, ea));
        self.header[i] = header;

        let boxes: Vec<String> = r
            .outcomes
            .iter()
            .map(|o| outcome_box[&(i, o.as_str())].clone())
            .collect();
        let footer = &mut self.footer[i];
        for (o, id) in r.outcomes.iter().zip(&boxes) {
            let mut oa = Attrs::default();
            let color = Status::from_outcome(o).map_or("black", Status::line_color);
            oa.set("label", o)
                .set("shape", "box")
                .set("fontsize", "8")
                .set("width", "0.3")
                .set("height", "0.2")
                .set("margin", "0.04,0.02")
                .set("color", color)
                .set("fontcolor", color)
                .set("tooltip", &format!("outcome {o} of {key}"))
                .style("rounded");
            footer.push(node_stmt(id, oa));
        }
        if !boxes.is_empty() {
            footer.push(rank_group("same", &boxes));
        }
    }

    // --- Ghosts (removed elements) --------------------------------------------

    pub(super) fn ghosts(&mut self) {
        let mut ghost_ids: HashMap<&str, String> = HashMap::new();
        let slotted: HashMap<usize, usize> =
            self.bt_ghost_slots.iter().map(|&(at, g)| (g, at)).collect();
        let mut placed: Vec<(usize, Stmt)> = Vec::with_capacity(slotted.len());
        for (key, label) in &self.opts.ghost_vertices {
            let id = self.fresh(key);
            let mut a = Attrs::default();
            a.set("label", label);
            a.node_highlight(Some(&Highlight::Removed));
            let stmt = node_stmt(&id, a);
            let cluster = self.ghost_cluster(key);
            self.extra.entry(cluster).or_default().push(stmt);
            ghost_ids.entry(key.as_str()).or_insert(id);
        }
        for (g, (from, to, label)) in self.opts.ghost_arcs.iter().enumerate() {
            let mut ends = Vec::with_capacity(2);
            for key in [from, to] {
                let id = match self.by_key.get(key).or(ghost_ids.get(key.as_str())) {
                    Some(id) => id.clone(),
                    None => {
                        let id = self.fresh(key);
                        let mut a = Attrs::default();
                        a.set("label", key);
                        a.node_highlight(Some(&Highlight::Removed));
                        self.extra.entry(None).or_default().push(node_stmt(&id, a));
                        ghost_ids.insert(key.as_str(), id.clone());
                        id
                    }
                };
                ends.push(id);
            }
            let mut a = Attrs::default();
            if !label.is_empty() {
                a.set("label", label);
            }
            a.edge_highlight(Some(&Highlight::Removed));
            match slotted.get(&g) {
                Some(&at) => placed.push((at, edge_stmt(&ends[0], &ends[1], a))),
                None => self.edges.push(edge_stmt(&ends[0], &ends[1], a)),
            }
        }
        // Slotted ghost arcs go before the edge they were placed at (one
        // merge: `placed` is in edge order).
        if !placed.is_empty() {
            placed.sort_by_key(|x| x.0);
            let edges = std::mem::take(&mut self.edges);
            let mut placed = placed.into_iter().peekable();
            for (i, e) in edges.into_iter().enumerate() {
                while let Some((_, p)) = placed.next_if(|x| x.0 <= i) {
                    self.edges.push(p);
                }
                self.edges.push(e);
            }
            self.edges.extend(placed.map(|x| x.1));
        }
    }

    /// The legend of a diff drawing: one sample node per highlight, side by
    /// side in a cluster of their own (ids not used by the policy).
    pub(super) fn legend(&mut self) -> Stmt {
        let mut ca = Attrs::default();
        ca.set("label", "legend")
            .set("fontname", FONT)
            .set("fontsize", "9")
            .set("color", "grey70")
            .style("rounded");
        let mut stmts: Vec<Stmt> = ca.into_vec().into_iter().map(Stmt::Attribute).collect();
        let samples = [
            ("legend: added", "added", Some(Highlight::Added)),
            ("legend: removed", "removed", Some(Highlight::Removed)),
            ("legend: changed", "changed\n(was: old value)", None),
        ];
        let mut ids = Vec::new();
        for (id, label, h) in samples {
            let id = self.fresh(id);
            let mut a = Attrs::default();
            a.set("label", label)
                .set("shape", "box")
                .set("fontsize", "9")
                .set("height", "0.3")
                .style("rounded");
            a.node_highlight(h.as_ref());
            if h.is_none() {
                a.set("color", CHANGED)
                    .set("fontcolor", CHANGED)
                    .set("penwidth", "2.5");
            }
            stmts.push(node_stmt(&id, a));
            ids.push(id);
        }
        stmts.push(rank_group("same", &ids));
        Stmt::Subgraph(Subgraph {
            id: dot_id("cluster legend"),
            stmts,
        })
    }

    /// The cluster a ghost vertex belongs in: the longest container key that
    /// prefixes its key.
    pub(super) fn ghost_cluster(&self, key: &str) -> Option<usize> {
        key.rmatch_indices('/')
            .find_map(|(at, _)| self.container_of_key.get(&key[..at]).copied())
    }
}

/// The vertex ids of a machine being drawn, which `Builder::machine`'s
/// phases share.
struct MachineIds<'m> {
    m: &'m StateMachine,
    /// Each state's key (SPEC §3 identity).
    key: Vec<String>,
    /// Each state's DOT node id.
    state_id: Vec<String>,
    /// The DOT node id of each outcome of the top level.
    top_outcome_id: Vec<String>,
    /// `(container, outcome)` -> DOT node id of the container's outcome box.
    outcome_box: HashMap<(usize, &'m str), String>,
}

impl<'m> MachineIds<'m> {
    /// The region of state `i`, if it is a container.
    fn region(&self, i: usize) -> Option<&'m Region> {
        match &self.m.states[i].body {
            StateBody::Container(r) => Some(r),
            _ => None,
        }
    }

    /// The DOT name of container `i`'s cluster.
    fn cluster_name(&self, i: usize) -> String {
        format!("cluster_{}", self.key[i])
    }

    /// The head of transition `t` of state `i` and the key it reaches (a
    /// state, or an outcome: its container's outcome box, or the top
    /// level's outcome node); sets `lhead` in `a` for a container.
    fn head(&self, i: usize, t: &Transition, a: &mut Attrs) -> (String, String) {
        let (m, key, state_id) = (self.m, &self.key, &self.state_id);
        match &t.target {
            &Target::State(j) => {
                if self.region(j).is_some() && j != i {
                    a.set("lhead", &self.cluster_name(j));
                }
                (state_id[j].clone(), key[j].clone())
            }
            Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => {
                let owner = match &t.target {
                    Target::OuterOutcome { owner, .. } => *owner,
                    _ => m.states[i].parent,
                };
                match owner {
                    Some(p) => {
                        let head = self
                            .outcome_box
                            .get(&(p, o.as_str()))
                            .unwrap_or(&state_id[p]);
                        (head.clone(), key[p].clone())
                    }
                    None => {
                        let head = m
                            .top
                            .outcomes
                            .iter()
                            .position(|x| x == o)
                            .map_or(o, |k| &self.top_outcome_id[k]);
                        (head.clone(), o.clone())
                    }
                }
            }
        }
    }
}

/// The attributes of a state drawn as a node: a history pseudo-state as a
/// small circle with H / H*, a decision as a diamond, a task as an ellipse
/// (white and oblique for a condition skill). Containers are clusters
/// (`Builder::container_nodes`) and get none.
fn state_attrs(s: &State, key: &str) -> Attrs {
    let condition = match &s.body {
        StateBody::Task(Some(c)) => {
            btfsm_model::skill::skill_kind(&c.skill) == Some(btfsm_model::SkillKind::Condition)
        }
        _ => false,
    };
    let mut a = Attrs::default();
    match &s.body {
        StateBody::Container(_) => {}
        // SCXML history pseudo-states as in UML: a small circle with H / H*.
        StateBody::Decision if s.pseudo.is_some() => {
            let h = match s.pseudo {
                Some(btfsm_model::Pseudo::DeepHistory) => "H*",
                _ => "H",
            };
            a.set("label", h)
                .set("shape", "circle")
                .set("fillcolor", "white")
                .set("fontsize", "10")
                .set("width", "0.3")
                .set("tooltip", key)
                .style("filled");
        }
        StateBody::Decision => {
            a.set("label", &s.label)
                .set("shape", "diamond")
                .set("fillcolor", DECISION_FILL)
                .set("fontsize", "10")
                .set("margin", "0.02,0.02")
                .set("tooltip", key)
                .style("filled");
        }
        StateBody::Task(call) => {
            a.set("label", &s.label).set("shape", "ellipse");
            if condition {
                a.set("fillcolor", "white")
                    .set("fontname", "Helvetica-Oblique");
            } else {
                a.set("fillcolor", ACTION_FILL);
            }
            let tip = match call {
                Some(c) => format!("{key}: {c}"),
                None => key.to_string(),
            };
            a.set("tooltip", &tip).style("filled");
        }
    }
    a
}
