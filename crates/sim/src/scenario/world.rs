//! Reading a scenario's `[world]` (room, stations, objects, obstacles,
//! parameters) and its condition terms (`goal`, `when`).

use super::*;

impl Reader {
    /// A condition term `{ if = "Skill", args = {...} }` or `unless`.
    pub(super) fn term(&mut self, v: &Val<'_>, world: &World) -> Option<(Call, bool)> {
        let t = self.table(v, "a condition")?;
        self.keys(t, &["if", "unless", "args"], "field of a condition");
        let (neg, c) = match (t.get("if"), t.get("unless")) {
            (Some(c), None) => (false, c),
            (None, Some(c)) => (true, c),
            _ => {
                self.err(
                    v.span(),
                    "a condition needs exactly one of `if` or `unless`",
                    "write `{ if = \"In-Hand\", args = { object = \"cube2\" } }`",
                );
                return None;
            }
        };
        let name = self.string(c, "the condition")?;
        let mut args = BTreeMap::new();
        if let Some(a) = t.get("args") {
            for (k, v) in self.table(a, "`args`")?.iter() {
                let val = match v.get_ref() {
                    DeValue::String(s) => btfsm_model::ArgValue::Str(s.to_string()),
                    other => match num(other) {
                        Some(x) if x.is_finite() => btfsm_model::ArgValue::Float(x),
                        _ => {
                            self.err(
                                v.span(),
                                "an argument must be a name or a finite number",
                                "",
                            );
                            return None;
                        }
                    },
                };
                args.insert(k.get_ref().to_string(), val);
            }
        }
        if skills::resolve(
            &SkillCall {
                skill: name.clone(),
                args: BTreeMap::new(),
            },
            world,
        )
        .is_err_and(|u| u.message.starts_with("unknown skill"))
        {
            let conds = btfsm_model::skill::skill_names(btfsm_model::SkillKind::Condition);
            self.err(
                c.span(),
                format!("unknown condition `{name}`"),
                suggest(&name, conds),
            );
            return None;
        }
        match skills::resolve(&SkillCall { skill: name, args }, world) {
            Ok(call) if !call.is_action() => Some((call, neg)),
            Ok(call) => {
                self.err(
                    c.span(),
                    format!("`{}` is an action, not a condition", call.name()),
                    "conditions: Robot-At, In-Hand, Object-At, Battery-Level, Arm-Tucked, Found, No-Emergency",
                );
                None
            }
            Err(u) => {
                self.unresolved(v.span(), u);
                None
            }
        }
    }

    pub(super) fn terms(&mut self, v: &Val<'_>, world: &World) -> Option<Vec<(Call, bool)>> {
        let a = self.array(v, "a list of conditions")?;
        self.terms += a.len();
        if !self.at_most(
            v.span(),
            self.terms,
            MAX_TERMS,
            "condition terms (`goal` and every `when` together)",
        ) {
            return None;
        }
        let mut out = Vec::new();
        for t in a {
            out.push(self.term(t, world)?);
        }
        Some(out)
    }

    /// `[world]`: the paper's room, with the parameters, obstacles,
    /// stations, battery, start and objects the scenario sets.
    pub(super) fn world(&mut self, v: Option<&Val<'_>>) -> Option<World> {
        let mut layout = Layout::paper_room();
        let mut params = Params::default();
        let mut robot = layout.station("start").expect("the paper room has a start");
        let mut objects = Vec::new();
        let mut battery = 100.0;
        let mut placed: Vec<(Range<usize>, usize)> = Vec::new();
        let Some(v) = v else {
            return Some(World::new(layout, params, robot, objects));
        };
        let t = self.table(v, "`world`")?;
        self.keys(
            t,
            &[
                "robot",
                "battery",
                "params",
                "obstacles",
                "stations",
                "objects",
            ],
            "field of `world`",
        );
        if let Some(p) = t.get("params") {
            self.world_params(p, &mut params)?;
        }
        if let Some(o) = t.get("obstacles") {
            self.obstacles(o, &mut layout, &mut placed)?;
        }
        if let Some(s) = t.get("stations") {
            self.stations(s, &mut layout, params.robot_radius)?;
        }
        self.obstacles_clear_of_kept_stations(t, &layout, placed, params.robot_radius);
        if let Some(b) = t.get("battery")
            && let Some(x) = self.number(b, "`battery`", 0.0, 100.0)
        {
            battery = x;
        }
        if let Some(rv) = t.get("robot")
            && let Some(p) = self.pose(rv, "the robot's start", &layout, params.robot_radius)
        {
            robot = p;
        }
        if let Some(ov) = t.get("objects") {
            objects = self.objects(ov, &layout, params.robot_radius)?;
        }
        let mut w = World::new(layout, params, robot, objects);
        w.battery = battery;
        Some(w)
    }

    /// `[world] params` into `params` (`None`: not a table).
    fn world_params(&mut self, p: &Val<'_>, params: &mut Params) -> Option<()> {
        let pt = self.table(p, "`world.params`")?;
        self.keys(
            pt,
            &(PARAMS.iter().map(|p| p.0))
                .chain(["follow_belief", "drop_sensed", "shut_down_latches"])
                .collect::<Vec<_>>(),
            "world parameter",
        );
        for (k, v) in pt.iter() {
            let flag = match k.get_ref().as_ref() {
                "follow_belief" => Some(&mut params.follow_belief),
                "drop_sensed" => Some(&mut params.drop_sensed),
                "shut_down_latches" => Some(&mut params.shut_down_latches),
                _ => None,
            };
            if let Some(flag) = flag {
                match v.get_ref() {
                    DeValue::Boolean(b) => *flag = *b,
                    _ => self.err(
                        v.span(),
                        format!("`{}` must be true or false", k.get_ref()),
                        format!("write `{} = true`", k.get_ref()),
                    ),
                }
                continue;
            }
            let Some(&(name, lo, hi)) = PARAMS.iter().find(|p| p.0 == k.get_ref().as_ref()) else {
                continue;
            };
            let Some(x) = self.number(v, &format!("`{name}`"), lo, hi) else {
                continue;
            };
            match name {
                "max_speed" => params.max_speed = x,
                "max_turn_rate" => params.max_turn_rate = x,
                "drain_per_m" => params.drain_per_m = x,
                "drain_per_s" => params.drain_per_s = x,
                "charge_per_s" => params.charge_per_s = x,
                "low_battery" => params.low_battery = x,
                "camera_range" => params.camera_range = x,
                "object_tolerance" => params.object_tolerance = x,
                "reach" => params.reach = x,
                "stall_s" => params.stall_s = x,
                "manipulation_s" => params.manipulation_s = x,
                "arm_s" => params.arm_s = x,
                _ => {}
            }
        }
        Some(())
    }

    /// `[world] obstacles` added to the layout, each noted in `placed` with
    /// its span (`None`: not an array, or too many).
    fn obstacles(
        &mut self,
        o: &Val<'_>,
        layout: &mut Layout,
        placed: &mut Vec<(Range<usize>, usize)>,
    ) -> Option<()> {
        let a = self.array(o, "`world.obstacles`")?;
        if !self.at_most(o.span(), a.len(), MAX_OBSTACLES, "obstacles") {
            return None;
        }
        for ob in a.iter() {
            if let Some(r) = self.rect(ob) {
                placed.push((ob.span(), layout.obstacles.len()));
                layout.obstacles.push(r);
            }
        }
        Some(())
    }

    /// `[world.stations]` set in the layout, each checked free once every
    /// one is placed (`None`: not a table, or too many).
    fn stations(&mut self, s: &Val<'_>, layout: &mut Layout, radius: f64) -> Option<()> {
        let st = self.table(s, "`world.stations`")?;
        // The paper room's stations count too (a scenario may move them).
        let new = st
            .iter()
            .filter(|(k, _)| layout.station(k.get_ref()).is_none());
        let n = layout.stations.len() + new.count();
        if !self.at_most(s.span(), n, MAX_STATIONS, "stations") {
            return None;
        }
        for (k, v) in st.iter() {
            if let Some(p) = self.point(v, "a station") {
                layout.set_station(k.get_ref(), p);
            }
        }
        // Checked after every obstacle is known.
        for (k, v) in self.table(s, "`world.stations`")?.iter() {
            let _ = self.pose(v, &format!("station `{}`", k.get_ref()), layout, radius);
        }
        Some(())
    }

    /// Refuses the obstacles (`placed`) over a station of the room that the
    /// scenario keeps where it is (those it sets were checked at their own
    /// position).
    fn obstacles_clear_of_kept_stations(
        &mut self,
        t: &DeTable<'_>,
        layout: &Layout,
        placed: Vec<(Range<usize>, usize)>,
        radius: f64,
    ) {
        let set: Vec<&str> = match t.get("stations").and_then(|s| s.get_ref().as_table()) {
            Some(st) => st.iter().map(|(k, _)| k.get_ref().as_ref()).collect(),
            None => Vec::new(),
        };
        let kept: Vec<(String, P2)> = (layout.stations.iter())
            .filter(|(n, _)| !set.contains(&n.as_str()))
            .cloned()
            .collect();
        for (span, i) in placed {
            let r = layout.obstacles[i].clone();
            self.covers_no_station(span, &r, &kept, radius, "obstacle");
        }
    }

    /// `[world.objects]` (`None`: not a table, or too many; an object with
    /// a problem is left out).
    fn objects(&mut self, ov: &Val<'_>, layout: &Layout, radius: f64) -> Option<Vec<Object>> {
        let ot = self.table(ov, "`world.objects`")?;
        if !self.at_most(ov.span(), ot.len(), MAX_OBJECTS, "objects") {
            return None;
        }
        let mut objects = Vec::new();
        for (k, v) in ot.iter() {
            if let Some(o) = self.object(k.get_ref(), v, layout, radius) {
                objects.push(o);
            }
        }
        Some(objects)
    }

    /// Object `name`: where it is (`at`, on the table in front of that pose
    /// or on the floor) and whether it was `found`.
    fn object(&mut self, name: &str, v: &Val<'_>, layout: &Layout, radius: f64) -> Option<Object> {
        let ot = self.table(v, &format!("object `{name}`"))?;
        self.keys(ot, &["at", "found"], "field of an object");
        let Some(at) = ot.get("at") else {
            self.err(
                v.span(),
                format!("object `{name}` needs `at`"),
                "write `at = \"east-table\"` or `at = [1.7, 0.0]`",
            );
            return None;
        };
        let p = self.pose(at, &format!("object `{name}`"), layout, radius)?;
        let found = match ot.get("found") {
            Some(f) => match f.get_ref() {
                DeValue::Boolean(b) => *b,
                _ => {
                    self.err(f.span(), "`found` must be true or false", "");
                    true
                }
            },
            None => true,
        };
        // On the table in front of its pose, or on the floor.
        let place = match layout.surface_near(p, radius) {
            Some(_) => Place::At(p),
            None => Place::Floor(p),
        };
        Some(Object::new(name, place, p, found))
    }

    /// Refuses an obstacle or a `block` over a station (or the robot's
    /// start): the robot must fit at every station. O(stations).
    pub(super) fn covers_no_station(
        &mut self,
        span: Range<usize>,
        r: &Rect,
        stations: &[(String, P2)],
        radius: f64,
        what: &str,
    ) -> bool {
        let hit = stations.iter().find(|(_, p)| r.distance(*p) < radius);
        if let Some((n, p)) = hit {
            self.err(
                span,
                format!(
                    "{what} `{}` covers station `{n}` ({}, {})",
                    r.name,
                    show(p.0),
                    show(p.1)
                ),
                format!(
                    "keep it at least the robot's radius ({radius} m) away from every station, or move the station"
                ),
            );
            return false;
        }
        true
    }

    pub(super) fn rect(&mut self, v: &Val<'_>) -> Option<Rect> {
        let t = self.table(v, "an obstacle")?;
        self.keys(t, &["name", "rect"], "field of an obstacle");
        let name = match t.get("name") {
            Some(n) => self.string(n, "`name`")?,
            None => "obstacle".into(),
        };
        let Some(rv) = t.get("rect") else {
            self.err(v.span(), "an obstacle needs `rect = [x0, y0, x1, y1]`", "");
            return None;
        };
        let nums: Vec<f64> = rv
            .get_ref()
            .as_array()
            .map(|a| {
                a.iter()
                    .take(5)
                    .filter_map(|x| num(x.get_ref()))
                    .filter(|x| x.is_finite())
                    .collect()
            })
            .unwrap_or_default();
        let len = rv.get_ref().as_array().map_or(0, |a| a.len());
        if len != 4 || nums.len() != 4 || nums[0] == nums[2] || nums[1] == nums[3] {
            self.err(
                rv.span(),
                "`rect` must be four finite numbers `[x0, y0, x1, y1]` with x0 != x1 and y0 != y1",
                "write e.g. `rect = [-0.5, 1.2, 0.5, 1.4]`",
            );
            return None;
        }
        Some(Rect::new(&name, nums[0], nums[1], nums[2], nums[3]))
    }
}
