//! Reading a scenario's `[rates]` and `[[disturbances]]` (one trigger and
//! one effect each).

use super::*;

impl Reader {
    pub(super) fn skill_name(&mut self, v: &Val<'_>) -> Option<String> {
        let s = self.string(v, "the skill")?;
        if SKILLS.iter().any(|(n, _, _)| *n == s) {
            Some(s)
        } else {
            let h = suggest(&s, SKILLS.iter().map(|(n, _, _)| *n));
            self.err(v.span(), format!("unknown skill `{s}`"), h);
            None
        }
    }

    pub(super) fn rates(&mut self, v: &Val<'_>) -> Option<BTreeMap<String, f64>> {
        let t = self.table(v, "`rates`")?;
        let mut out = BTreeMap::new();
        for (k, v) in t.iter() {
            let name = k.get_ref().to_string();
            if !SKILLS.iter().any(|(n, _, _)| *n == name) {
                let h = suggest(&name, SKILLS.iter().map(|(n, _, _)| *n));
                self.err(k.span(), format!("unknown skill `{name}`"), h);
                continue;
            }
            if let Some(p) = self.number(v, &format!("the failure rate of `{name}`"), 0.0, 1.0) {
                out.insert(name, p);
            }
        }
        Some(out)
    }

    /// A `[[disturbances]]` entry: one trigger and one effect.
    pub(super) fn disturbance(&mut self, v: &Val<'_>, world: &World) -> Option<Disturbance> {
        let t = self.table(v, "a disturbance")?;
        self.keys(
            t,
            &[
                "at",
                "after_done",
                "when",
                "battery",
                "move",
                "to",
                "drop",
                "fail",
                "times",
                "block",
                "emergency",
            ],
            "field of a disturbance",
        );
        let when = self.trigger(v, t, world)?;
        let (effect, text) = self.effect(v, t, world)?;
        Some(Disturbance { when, effect, text })
    }

    /// A disturbance's trigger: exactly one of `at`, `after_done`, `when`.
    fn trigger(&mut self, v: &Val<'_>, t: &DeTable<'_>, world: &World) -> Option<When> {
        let whens: Vec<&str> = ["at", "after_done", "when"]
            .into_iter()
            .filter(|k| t.contains_key(*k))
            .collect();
        if whens.len() != 1 {
            self.err(
                v.span(),
                "a disturbance needs exactly one trigger: `at`, `after_done` or `when`",
                "write `at = 12.0` (seconds), `after_done = 2.0` or `when = [{ if = \"In-Hand\", args = { object = \"cube2\" } }]`",
            );
            return None;
        }
        Some(match whens[0] {
            "at" => When::At(self.number(t.get("at").expect("checked above"), "`at`", 0.0, 1e9)?),
            "after_done" => When::AfterDone(self.number(
                t.get("after_done").expect("checked above"),
                "`after_done`",
                0.0,
                1e9,
            )?),
            _ => When::Holds(self.terms(t.get("when").expect("checked above"), world)?),
        })
    }

    /// A disturbance's effect, exactly one, and its text for events and
    /// the report.
    fn effect(&mut self, v: &Val<'_>, t: &DeTable<'_>, world: &World) -> Option<(Effect, String)> {
        let effects: Vec<&str> = ["battery", "move", "drop", "fail", "block", "emergency"]
            .into_iter()
            .filter(|k| t.contains_key(*k))
            .collect();
        if effects.len() != 1 {
            self.err(
                v.span(),
                "a disturbance needs exactly one effect: `battery`, `move`, `drop`, `fail`, `block` or `emergency`",
                "write e.g. `battery = 15` or `move = \"cube2\", to = \"east-table\"`",
            );
            return None;
        }
        match effects[0] {
            "battery" => {
                let b = self.number(
                    t.get("battery").expect("checked above"),
                    "`battery`",
                    0.0,
                    100.0,
                )?;
                Some((Effect::Battery(b), format!("battery set to {b}%")))
            }
            "move" => self.move_effect(v, t, world),
            "drop" => {
                let o = self.object_of(t, "drop", world)?;
                Some((
                    Effect::Drop { object: o },
                    format!("{} dropped", world.objects[o].name),
                ))
            }
            "fail" => self.fail_effect(t),
            "block" => self.block_effect(t, world),
            _ => match t.get("emergency").expect("checked above").get_ref() {
                DeValue::Boolean(b) => Some((
                    Effect::Emergency(*b),
                    if *b {
                        "emergency".into()
                    } else {
                        "emergency over".into()
                    },
                )),
                _ => {
                    self.err(
                        t.get("emergency").expect("checked above").span(),
                        "`emergency` must be true or false",
                        "",
                    );
                    None
                }
            },
        }
    }

    /// The object a disturbance's `key` names.
    fn object_of(&mut self, t: &DeTable<'_>, key: &str, world: &World) -> Option<usize> {
        let v = &t[key];
        let name = self.string(v, &format!("`{key}`"))?;
        match world.object_index(&name) {
            Some(i) => Some(i),
            None => {
                let h = suggest(&name, world.objects.iter().map(|o| o.name.as_str()));
                self.err(v.span(), format!("unknown object `{name}`"), h);
                None
            }
        }
    }

    /// `move = "object"` with `to`: a free pose.
    fn move_effect(
        &mut self,
        v: &Val<'_>,
        t: &DeTable<'_>,
        world: &World,
    ) -> Option<(Effect, String)> {
        let o = self.object_of(t, "move", world)?;
        let Some(to) = t.get("to") else {
            self.err(
                v.span(),
                "`move` needs `to`",
                "write `to = \"east-table\"` or `to = [1.7, 0.0]`",
            );
            return None;
        };
        let p = self.pose(
            to,
            "the new place",
            &world.layout,
            world.params.robot_radius,
        )?;
        Some((
            Effect::Move { object: o, to: p },
            format!("{} moved to ({}, {})", world.objects[o].name, p.0, p.1),
        ))
    }

    /// `fail = "Skill"`, the next `times` times (default once).
    fn fail_effect(&mut self, t: &DeTable<'_>) -> Option<(Effect, String)> {
        let s = self.skill_name(t.get("fail").expect("checked above"))?;
        let n = match t.get("times") {
            Some(n) => self.integer(n, "`times`", 1, 1_000_000)? as u32,
            None => 1,
        };
        Some((
            Effect::Fail {
                skill: s.clone(),
                times: n,
            },
            format!(
                "{s} fails the next {n} time{}",
                if n == 1 { "" } else { "s" }
            ),
        ))
    }

    /// `block = { name, rect }`: an obstacle over no station and not on the
    /// robot's start.
    fn block_effect(&mut self, t: &DeTable<'_>, world: &World) -> Option<(Effect, String)> {
        let bv = t.get("block").expect("checked above");
        let r = self.rect(bv)?;
        if !self.covers_no_station(
            bv.span(),
            &r,
            &world.layout.stations,
            world.params.robot_radius,
            "`block`",
        ) {
            return None;
        }
        if r.distance(world.robot) < world.params.robot_radius {
            self.err(
                bv.span(),
                format!("`block` `{}` covers the robot's start ({}, {})", r.name, show(world.robot.0), show(world.robot.1)),
                "a box cannot land on the robot; move it (a block that would cover the robot during a run is refused, with an event)",
            );
            return None;
        }
        let text = format!("path blocked by {}", r.name);
        Some((Effect::Block(r), text))
    }
}
