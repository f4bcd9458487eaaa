//! Skill bindings of TOML leaves and states: `skill` and `args` checked
//! against the shared skill library (src/model/skill.rs).

use super::*;

impl Loader {
    /// Reads `skill = "..."` and `args = {...}` of a leaf or state.
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
            if is_domain_word(dom) && is_domain_word(own) {
                return Some(SkillCall { skill: name, args });
            }
            self.err(cx, sv.span(), format!("`{name}` is not a skill name"))
                .hint =
                Some("a domain's own skill is `domain:Name`: letters, digits, `-` and `_`".into());
            return None;
        }
        if !self.skill_of_kind(cx, sv.span(), &name, owner, want) {
            return None;
        }
        let args_v = t.get("args");
        let args_span = args_v.map_or(sv.span(), |a| a.span());
        let args_table = match args_v.map(|a| a.get_ref()) {
            Some(DeValue::Table(at)) => Some(at),
            _ => None,
        };
        let ok = self.skill_args_fit(cx, &name, owner, &args, args_span, args_table);
        ok.then_some(SkillCall { skill: name, args })
    }

    /// Whether `name` is a skill of the library, of the kind wanted (an
    /// error when not).
    fn skill_of_kind(
        &mut self,
        cx: &Ctx<'_>,
        span: Range<usize>,
        name: &str,
        owner: &str,
        want: Option<SkillKind>,
    ) -> bool {
        match skill::skill_kind(name) {
            None => {
                let cands: Vec<&str> = match want {
                    Some(k) => skill::skill_names(k),
                    None => skill::SKILLS.iter().map(|s| s.0).collect(),
                };
                let h = self.suggest(name, cands.iter().copied());
                self.err(cx, span, format!("unknown skill `{name}` in {owner}"))
                    .hint = Some(h);
                false
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
                    span,
                    format!(
                        "{owner} is {} but `{name}` is {} skill",
                        article_kind(w),
                        article_kind(k)
                    ),
                )
                .hint = Some(h);
                false
            }
            Some(_) => true,
        }
    }

    /// Checks a skill's arguments against its parameters: every required
    /// one given (an error at `args_span`), no unknown one in the `args`
    /// table. `false` when one is wrong.
    fn skill_args_fit(
        &mut self,
        cx: &Ctx<'_>,
        name: &str,
        owner: &str,
        args: &BTreeMap<String, ArgValue>,
        args_span: Range<usize>,
        args_table: Option<&DeTable<'_>>,
    ) -> bool {
        let params = skill::skill_params(name).unwrap_or(&[]);
        let mut ok = true;
        for (p, required) in params {
            if *required && !args.contains_key(*p) {
                self.err(
                    cx,
                    args_span.clone(),
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
        if let Some(at) = args_table {
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
        ok
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

/// Whether a part of `domain:Name` is a name: 1 to 128 letters, digits, `-`
/// and `_`.
fn is_domain_word(x: &str) -> bool {
    !x.is_empty()
        && x.len() <= 128
        && x.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}
