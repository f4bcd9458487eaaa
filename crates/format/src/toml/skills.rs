//! Skill bindings of TOML leaves and states: `skill` and `args` checked
//! against the shared skill library (src/model/skill.rs).

use super::*;

impl Loader {
    /// Reads `skill = "..."` and `args = {...}` of a leaf or state.
    #[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
    pub(super) fn skill_call(
        &mut self,
        cx: &Ctx<'_>,
        t: &DeTable<'_>,
        owner: &str,
        want: Option<SkillKind>,
    ) -> Option<SkillCall> {
        let (_, sv) = t.get_key_value("skill")?;
        let Some(name) = sv.get_ref().as_str() else {
            self.err(
                cx,
                sv.span(),
                format!(
                    "`skill` of {owner} must be a string, found {}",
                    type_name(sv.get_ref())
                ),
            );
            return None;
        };
        let name = cx.subst(name);
        let args = match t.get("args") {
            None => BTreeMap::new(),
            Some(a) => self.args(cx, a, owner)?,
        };
        // A skill of an action domain (`domain:Name`, docs/guide/plan.md "Action
        // domains"): its arguments are the domain's to check (symbolic
        // simulation checks them against the domain when it binds them).
        if let Some((dom, own)) = name.split_once(':') {
            let named = |x: &str| {
                !x.is_empty()
                    && x.len() <= 128
                    && x.chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            };
            if named(dom) && named(own) {
                return Some(SkillCall { skill: name, args });
            }
            self.err(cx, sv.span(), format!("`{name}` is not a skill name"))
                .hint =
                Some("a domain's own skill is `domain:Name`: letters, digits, `-` and `_`".into());
            return None;
        }
        match skill::skill_kind(&name) {
            None => {
                let cands: Vec<&str> = match want {
                    Some(k) => skill::skill_names(k),
                    None => skill::SKILLS.iter().map(|s| s.0).collect(),
                };
                let h = self.suggest(&name, cands.iter().copied());
                self.err(cx, sv.span(), format!("unknown skill `{name}` in {owner}"))
                    .hint = Some(h);
                return None;
            }
            Some(k) if want.is_some_and(|w| w != k) => {
                let w = want.expect("checked");
                let h = format!(
                    "{} skills are {}",
                    kind_word(w),
                    skill::skill_names(w)
                        .iter()
                        .map(|s| format!("`{s}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                self.err(
                    cx,
                    sv.span(),
                    format!(
                        "{owner} is {} but `{name}` is {} skill",
                        article_kind(w),
                        article_kind(k)
                    ),
                )
                .hint = Some(h);
                return None;
            }
            Some(_) => {}
        }
        let params = skill::skill_params(&name).unwrap_or(&[]);
        let mut ok = true;
        for (p, required) in params {
            if *required && !args.contains_key(*p) {
                let span = t.get("args").map_or(sv.span(), |a| a.span());
                self.err(
                    cx,
                    span,
                    format!("skill `{name}` of {owner} needs argument `{p}`"),
                )
                .hint = Some(format!(
                    "write `args = {{ {} }}`",
                    params
                        .iter()
                        .map(|(p, _)| format!("{p} = ..."))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                ok = false;
            }
        }
        if let Some(DeValue::Table(at)) = t.get("args").map(|a| a.get_ref()) {
            for (k, _) in at.iter() {
                if !params.iter().any(|(p, _)| *p == k.get_ref().as_ref()) {
                    let h = if params.is_empty() {
                        format!("`{name}` takes no arguments")
                    } else {
                        self.suggest(k.get_ref(), params.iter().map(|p| p.0))
                    };
                    self.err(
                        cx,
                        k.span(),
                        format!("skill `{name}` has no argument `{}`", k.get_ref()),
                    )
                    .hint = Some(h);
                    ok = false;
                }
            }
        }
        ok.then_some(SkillCall { skill: name, args })
    }

    pub(super) fn args(
        &mut self,
        cx: &Ctx<'_>,
        a: &Val<'_>,
        owner: &str,
    ) -> Option<BTreeMap<String, ArgValue>> {
        let DeValue::Table(t) = a.get_ref() else {
            self.err(
                cx,
                a.span(),
                format!(
                    "`args` of {owner} must be a table, found {}",
                    type_name(a.get_ref())
                ),
            )
            .hint = Some("write `args = { target = \"cube2\" }`".into());
            return None;
        };
        let mut out = BTreeMap::new();
        for (k, v) in t.iter() {
            let val = match v.get_ref() {
                DeValue::String(s) => ArgValue::Str(cx.subst(s)),
                DeValue::Boolean(b) => ArgValue::Bool(*b),
                DeValue::Integer(_) => match int_of(v.get_ref()) {
                    Some(i) => ArgValue::Int(i),
                    None => {
                        self.err(cx, v.span(), "integer out of range");
                        return None;
                    }
                },
                DeValue::Float(_) => ArgValue::Float(float_of(v.get_ref()).unwrap_or(f64::NAN)),
                other => {
                    self.err(
                        cx,
                        v.span(),
                        format!(
                            "argument `{}` of {owner} must be a string, number or boolean, found {}",
                            k.get_ref(),
                            type_name(other)
                        ),
                    );
                    return None;
                }
            };
            out.insert(k.get_ref().to_string(), val);
        }
        Some(out)
    }

    // ---------------------------------------------------------------- BT
}
