//! Reading a whole scenario: its top-level keys and `[[policies]]` (each
//! policy file read, converted and checked against the world).

use super::*;

impl Reader {
    /// The whole scenario: its top-level keys, world, rates, goal,
    /// disturbances, Monte Carlo table, policies and expectations.
    pub(super) fn scenario(
        &mut self,
        t: &DeTable<'_>,
        base: &Path,
        limits: &Limits,
    ) -> Option<Scenario> {
        self.keys(t, TOP_KEYS, "top-level key");
        let name = match t.get("name") {
            Some(n) => self.string(n, "`name`")?,
            None => Path::new(&self.file.path)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
        };
        let description = match t.get("description") {
            Some(d) => self.string(d, "`description`"),
            None => None,
        };
        let run = self.settings(t);
        // The scenario's own settings for every policy (an entry may state
        // its own): read before the policies.
        let keep = |s: &mut Self, key: &str| match t.get(key) {
            Some(v) => s.afterwards(Some(v), key, false),
            None => None,
        };
        self.after = (keep(self, "after_success"), keep(self, "after_failure"));
        let world = self.world(t.get("world"))?;
        let rates = match t.get("rates") {
            Some(r) => self.rates(r)?,
            None => BTreeMap::new(),
        };
        let goal = match t.get("goal") {
            Some(g) => Some(self.terms(g, &world)?),
            None => None,
        };
        let disturbances = match t.get("disturbances") {
            Some(d) => self.disturbances(d, &world)?,
            None => Vec::new(),
        };
        let monte_carlo = match t.get("monte_carlo") {
            Some(m) => self.monte_carlo(m, &world)?,
            None => MonteCarlo::default(),
        };
        let policies = self.policies(t.get("policies"), base, limits, &world)?;
        let expect = match t.get("expect") {
            Some(e) => {
                let names: Vec<String> = policies.iter().map(|p| p.policy.name.clone()).collect();
                self.expect(e, &names, goal.is_some())
            }
            None => Vec::new(),
        };
        Some(Scenario {
            expect,
            warnings: Vec::new(),
            name,
            description,
            seed: run.seed,
            dt: run.dt,
            max_steps: run.max_steps,
            livelock_repeats: run.livelock_repeats,
            max_failures: run.max_failures,
            pose_tolerance_m: run.pose_tolerance_m,
            start_tolerance_s: run.start_tolerance_s,
            time_shift_s: run.time_shift_s,
            world,
            policies,
            rates,
            disturbances,
            goal,
            monte_carlo,
        })
    }

    /// The numbers of the runs (`seed`, `dt`, `max_steps`,
    /// `livelock_repeats`, `max_failures`), defaults for those missing or
    /// refused; a warning for the retired `chatter_switches`.
    fn settings(&mut self, t: &DeTable<'_>) -> Settings {
        let seed = t
            .get("seed")
            .and_then(|v| self.integer(v, "`seed`", 0, i64::MAX as u64))
            .unwrap_or(1);
        let dt = t
            .get("dt")
            .and_then(|v| self.number(v, "`dt`", 0.001, 10.0))
            .unwrap_or(0.1);
        let max_steps = t
            .get("max_steps")
            .and_then(|v| self.integer(v, "`max_steps`", 1, MAX_STEPS))
            .unwrap_or(20_000);
        if let Some(v) = t.get("chatter_switches")
            && self
                .integer(v, "`chatter_switches`", 2, 1_000_000)
                .is_some()
        {
            self.diags.push(
                Diagnostic::warning("`chatter_switches` is no longer used: a livelock is a recurring abstract state without progress toward the goal")
                    .at(&self.file, v.span())
                    .hint("remove it; `livelock_repeats` (default 3) sets how often a state may recur"),
            );
        }
        let livelock_repeats = t
            .get("livelock_repeats")
            .and_then(|v| self.integer(v, "`livelock_repeats`", 2, 1_000_000))
            .unwrap_or(3) as u32;
        let max_failures = t
            .get("max_failures")
            .and_then(|v| self.integer(v, "`max_failures`", 1, 1_000_000))
            .unwrap_or(50) as u32;
        // The verdicts' tolerances (docs/simulator-verdicts.md): how far
        // apart two robots may be at the same time, and two starts of the
        // same skill, for their behavior to match.
        let pose_tolerance_m = t
            .get("pose_tolerance_m")
            .and_then(|v| self.number(v, "`pose_tolerance_m`", 0.0, 100.0))
            .unwrap_or(POSE_TOLERANCE_M);
        let start_tolerance_s = t
            .get("start_tolerance_s")
            .and_then(|v| self.number(v, "`start_tolerance_s`", 0.0, 3600.0))
            .unwrap_or(dt);
        let time_shift_s = t
            .get("time_shift_s")
            .and_then(|v| self.number(v, "`time_shift_s`", 0.0, 60.0))
            .unwrap_or(start_tolerance_s.min(60.0));
        Settings {
            seed,
            dt,
            max_steps,
            livelock_repeats,
            max_failures,
            pose_tolerance_m,
            start_tolerance_s,
            time_shift_s,
        }
    }

    /// `[[disturbances]]` (`None`: not an array, or too many of them or of
    /// the obstacles they add; a disturbance with a problem is left out).
    fn disturbances(&mut self, d: &Val<'_>, world: &World) -> Option<Vec<Disturbance>> {
        let a = self.array(d, "`disturbances`")?;
        if !self.at_most(d.span(), a.len(), MAX_DISTURBANCES, "disturbances") {
            return None;
        }
        // Every `block` adds an obstacle.
        let blocks = (a.iter())
            .filter(|x| {
                x.get_ref()
                    .as_table()
                    .is_some_and(|t| t.contains_key("block"))
            })
            .count();
        let obstacles = world.layout.obstacles.len() + blocks;
        if !self.at_most(
            d.span(),
            obstacles,
            MAX_OBSTACLES,
            "obstacles (`block` disturbances included)",
        ) {
            return None;
        }
        let mut disturbances = Vec::new();
        for x in a {
            if let Some(d) = self.disturbance(x, world) {
                disturbances.push(d);
            }
        }
        Some(disturbances)
    }

    /// `[[policies]]`, at least one (`None`: not an array, or too many; a
    /// policy with a problem is left out).
    fn policies(
        &mut self,
        p: Option<&Val<'_>>,
        base: &Path,
        limits: &Limits,
        world: &World,
    ) -> Option<Vec<PolicyEntry>> {
        let mut policies = Vec::new();
        match p {
            None => self.err(
                0..0,
                "a scenario needs at least one policy",
                "add `[[policies]]` with `file = \"../paper/fig01-bt.toml\"`",
            ),
            Some(p) => {
                let a = self.array(p, "`policies`")?;
                if !self.at_most(p.span(), a.len(), MAX_POLICIES, "policies") {
                    return None;
                }
                let mut seen: BTreeMap<String, usize> = BTreeMap::new();
                for e in a {
                    if let Some(mut pe) = self.policy(e, base, limits, world) {
                        self.disambiguate(&mut pe, e, &mut seen);
                        policies.push(pe);
                    }
                }
            }
        }
        Some(policies)
    }

    /// A policy whose name (from its file) is an earlier one's is reported
    /// as `NAME#2` (`#3`, ...), with a warning saying so: two entries of
    /// one file (with different settings, say) would otherwise be
    /// indistinguishable in the verdicts and in `[expect]`. A generated
    /// name never takes an existing one; a `name` the entry states twice is
    /// an error.
    fn disambiguate(
        &mut self,
        pe: &mut PolicyEntry,
        e: &Val<'_>,
        seen: &mut BTreeMap<String, usize>,
    ) {
        let name = pe.policy.name.clone();
        let count = seen.entry(name.clone()).or_insert(0);
        *count += 1;
        if *count == 1 {
            return;
        }
        if let Some(n) = e.get_ref().as_table().and_then(|t| t.get("name")) {
            self.err(
                n.span(),
                format!("two policies are named `{name}`"),
                "names tell policies apart in reports and `[expect]`: give this entry another `name`",
            );
            return;
        }
        let renamed = numbered(&name, |n| seen.contains_key(n));
        seen.insert(renamed.clone(), 1);
        self.diags.push(
            Diagnostic::warning(format!(
                "two policies are named `{name}`: this one is reported as `{renamed}`"
            ))
            .at(&self.file, e.span())
            .hint("give each `[[policies]]` entry its own `name = \"...\"`"),
        );
        pe.policy.name = renamed;
    }

    /// `after_success` / `after_failure`: `"stop"` or `"keep-ticking"`.
    pub(super) fn afterwards(
        &mut self,
        v: Option<&Val<'_>>,
        key: &str,
        keep: bool,
    ) -> Option<Afterwards> {
        let Some(a) = v else {
            return Some(if keep {
                Afterwards::KeepTicking
            } else {
                Afterwards::Stop
            });
        };
        match a.get_ref().as_str() {
            Some("stop") => Some(Afterwards::Stop),
            Some("keep-ticking") => Some(Afterwards::KeepTicking),
            _ => {
                self.err(
                    a.span(),
                    format!("`{key}` must be \"stop\" or \"keep-ticking\""),
                    format!("write `{key} = \"keep-ticking\"` to tick the policy again (a BT's default), `\"stop\"` to end it (an FSM's and an HFSM's)"),
                );
                None
            }
        }
    }

    /// A `[[policies]]` entry: its file read (converted when asked),
    /// checked against the world, named, with what it does afterwards.
    pub(super) fn policy(
        &mut self,
        v: &Val<'_>,
        base: &Path,
        limits: &Limits,
        world: &World,
    ) -> Option<PolicyEntry> {
        let t = self.table(v, "a policy entry")?;
        self.keys(
            t,
            &["file", "convert", "name", "after_success", "after_failure"],
            "field of a policy entry",
        );
        let Some(f) = t.get("file") else {
            self.err(
                v.span(),
                "a policy entry needs `file`",
                "write `file = \"../paper/fig01-bt.toml\"` (relative to the scenario)",
            );
            return None;
        };
        let rel = self.string(f, "`file`")?;
        let path = self.policy_path(f, &rel, base, limits)?;
        let convert = self.convert(t)?;
        let loaded = match format::load_named(&path, limits) {
            Ok(l) => l,
            Err(d) => {
                self.diags.extend(d);
                return None;
            }
        };
        let mut policy = loaded.policy;
        if convert.is_some() {
            policy = self.converted(policy, f, &rel)?;
        }
        check_bindings(&policy, &loaded.path, limits, world, &mut self.diags);
        self.runs_one_state_at_a_time(&policy, f, &rel)?;
        if convert.is_none() {
            self.warn_forgetful(&policy, f, &rel);
        }
        if let Some(n) = t.get("name") {
            policy.name = self.string(n, "`name`")?;
        }
        // Defaults, unless the scenario states its own for every policy:
        // after FAILURE every policy is ticked (a BT) or started (a
        // machine) again, whatever its representation; after SUCCESS a BT
        // keeps ticking (its root is ticked every step) and a machine stops
        // (SMACH's final state). Reports print each run's settings.
        let bt = matches!(policy.body, PolicyBody::Bt(_));
        let after_success = match (t.get("after_success"), self.after.0) {
            (None, Some(a)) => a,
            (v, _) => self.afterwards(v, "after_success", bt)?,
        };
        let after_failure = match (t.get("after_failure"), self.after.1) {
            (None, Some(a)) => a,
            (v, _) => self.afterwards(v, "after_failure", true)?,
        };
        Some(PolicyEntry {
            file: path,
            convert,
            policy,
            after_success,
            after_failure,
            stated: [
                t.get("after_success").is_some(),
                t.get("after_failure").is_some(),
            ],
        })
    }

    /// The path of policy file `rel` (at `f`), resolved against the
    /// scenario's folder, inside its root.
    fn policy_path(
        &mut self,
        f: &Val<'_>,
        rel: &str,
        base: &Path,
        limits: &Limits,
    ) -> Option<PathBuf> {
        let root = format::source::root_for(limits, base);
        match format::source::resolve(root.as_deref(), base, rel) {
            Ok(p) => Some(p),
            Err(r) if r.message == "no such file" => {
                self.err(
                    f.span(),
                    format!("policy file `{rel}` not found"),
                    format!(
                        "paths are relative to the scenario's folder (`{}`)",
                        base.display()
                    ),
                );
                None
            }
            Err(r) => {
                self.err(
                    f.span(),
                    format!("policy file `{rel}`: {}", r.message),
                    r.hint,
                );
                None
            }
        }
    }

    /// A policy entry's `convert`: `Some(None)` without one, `None` when it
    /// is not `"hfsm"`.
    fn convert(&mut self, t: &DeTable<'_>) -> Option<Option<String>> {
        match t.get("convert") {
            None => Some(None),
            Some(c) => match c.get_ref().as_str() {
                Some("hfsm") => Some(Some("hfsm".to_string())),
                _ => {
                    self.err(c.span(), "`convert` must be \"hfsm\"", "write `convert = \"hfsm\"` to run the BT converted to an HFSM (Fig. 5 -> Fig. 6)");
                    None
                }
            },
        }
    }

    /// The HFSM of a BT (`convert = "hfsm"`): refused for a machine, a BT
    /// with memory, or one the construction does not convert.
    fn converted(&mut self, policy: Policy, f: &Val<'_>, rel: &str) -> Option<Policy> {
        if !matches!(policy.body, PolicyBody::Bt(_)) {
            self.err(
                f.span(),
                format!("`{rel}` is not a BT and cannot be converted"),
                "remove `convert`",
            );
            return None;
        }
        if let PolicyBody::Bt(bt) = &policy.body
            && let Some(&n) = btfsm_transform::bt_to_hfsm::memory_nodes(bt).first()
        {
            let node = &bt.nodes[n];
            self.err(
                f.span(),
                format!(
                    "the HFSM of `{rel}` would not behave as the BT: its `{}` node `{}` keeps memory, and the construction re-enters containers at their first state every tick",
                    node.kind.keyword(),
                    node.id
                ),
                "run the BT itself, or make the node reactive (sequence / fallback); `btfsm convert --to hfsm` still gives the HFSM to count",
            );
            return None;
        }
        match btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm(&policy) {
            Ok(p) => Some(p),
            Err(e) => {
                self.err(
                    f.span(),
                    e[0].to_string(),
                    "only sequence, fallback and simple decorators convert",
                );
                None
            }
        }
    }

    /// Refuses a machine the executor cannot run (it runs one state per
    /// region, from a state): parallel regions, or no state to start in.
    fn runs_one_state_at_a_time(&mut self, policy: &Policy, f: &Val<'_>, rel: &str) -> Option<()> {
        if let PolicyBody::Machine(m) = &policy.body {
            if m.has_parallel() {
                self.err(
                    f.span(),
                    format!("`{rel}` has parallel regions (SCXML `<parallel>`): the simulator runs one state at a time"),
                    "simulate each region as its own machine; `analyze`, `dot` and `compare` take the whole machine",
                );
                return None;
            }
            if m.top.initial_state().is_none() {
                self.err(
                    f.span(),
                    format!("`{rel}` starts in an outcome: it has no state to run"),
                    "give the machine a state to start in",
                );
                return None;
            }
        }
        Some(())
    }

    /// Warns about a tick-driven machine that looks converted from a BT
    /// with memory (its containers forget their running child).
    fn warn_forgetful(&mut self, policy: &Policy, f: &Val<'_>, rel: &str) {
        if let PolicyBody::Machine(m) = &policy.body
            && m.top.outcomes.iter().any(|o| o == "RUNNING")
            && let Some(st) = (m.states.iter()).find(|st| {
                matches!(st.body, StateBody::Container(_))
                    && (st.label == "Sequence*" || st.label == "Fallback*")
            })
        {
            self.diags.push(
                Diagnostic::warning(format!(
                    "`{rel}` looks converted from a BT with memory: its container `{}` ({}) is re-entered at its first state every tick, so it forgets the running child and does not behave as the BT",
                    st.name, st.label
                ))
                .at(&self.file, f.span())
                .hint("run the BT itself, or convert a BT whose composites are reactive (sequence / fallback)"),
            );
        }
    }
}

/// `NAME#2` (`#3`, ...): the first such name not `taken`, for a policy
/// named as an earlier one (planar and symbolic scenarios alike).
pub(crate) fn numbered(name: &str, taken: impl Fn(&str) -> bool) -> String {
    (2..)
        .map(|k| format!("{name}#{k}"))
        .find(|n| !taken(n))
        .expect("some number is free")
}

/// The numbers of a scenario's runs.
struct Settings {
    seed: u64,
    dt: f64,
    max_steps: u64,
    livelock_repeats: u32,
    max_failures: u32,
    pose_tolerance_m: f64,
    start_tolerance_s: f64,
    time_shift_s: f64,
}

/// The default of `pose_tolerance_m`: two robots within 0.2 m of each
/// other at every step move alike (a tenth of the room's smallest
/// clearance, twice a step's travel at top speed).
pub(super) const POSE_TOLERANCE_M: f64 = 0.2;
