//! TOML `subtree` includes: another BT file read in place of a node, with
//! its `with` parameters substituted, confined to the root and bounded.

use super::*;

impl Loader {
    /// Reads an included subtree file.
    pub(super) fn include(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        t: &DeTable<'_>,
        tval: &Val<'_>,
    ) -> Option<Bt> {
        let Some(rel) = tval.get_ref().as_str() else {
            self.err(
                cx,
                tval.span(),
                format!("`subtree` of node `{id}` must be a file path"),
            );
            return None;
        };
        let path = match crate::source::resolve(self.root.as_deref(), cx.base, rel) {
            Ok(p) => p,
            Err(r) => {
                self.err(
                    cx,
                    tval.span(),
                    format!("subtree of node `{id}`: {}", r.message),
                )
                .hint = Some(r.hint);
                return None;
            }
        };
        let canon = canonical(&path);
        if let Some(pos) = self.stack.iter().position(|p| *p == canon) {
            let chain: Vec<String> = self.stack[pos..]
                .iter()
                .chain(std::iter::once(&canon))
                .map(|p| {
                    p.file_name()
                        .map_or_else(|| p.display().to_string(), |f| f.to_string_lossy().into())
                })
                .collect();
            self.err(
                cx,
                tval.span(),
                format!("cyclic subtree include: {}", chain.join(" -> ")),
            )
            .set_code("subtree-recursion")
            .hint = Some("a subtree must not include itself, directly or through others".into());
            return None;
        }
        if self.stack.len() > self.limits.max_include_depth {
            self.err(
                cx,
                tval.span(),
                format!(
                    "subtree includes nested deeper than {}",
                    self.limits.max_include_depth
                ),
            );
            return None;
        }
        let with: Vec<(String, String)> = match t.get("with").map(|w| w.get_ref()) {
            Some(DeValue::Table(wt)) => wt
                .iter()
                .map(|(k, v)| (k.get_ref().to_string(), cx.subst(&scalar_text(v.get_ref()))))
                .collect(),
            Some(other) => vec![(String::new(), type_name(other).to_string())],
            None => Vec::new(),
        };
        let key = (canon.clone(), with);
        if let Some(done) = self.includes.get(&key) {
            // Read before: its problems are reported already.
            let size = done.as_ref()?.nodes.len();
            if size > self.node_budget || !self.limits.expansion_budget.charge(size as u64) {
                self.err(
                    cx,
                    tval.span(),
                    format!(
                        "more than {} nodes with the subtrees expanded (in this policy, or copied by this command in all)",
                        self.limits.max_nodes
                    ),
                )
                .hint = Some("raise the limit with --max-nodes".into());
                return None;
            }
            self.node_budget -= size;
            return done.clone();
        }
        let bt = self.read_include(cx, id, t, rel, &path, canon);
        if self.subst.overflow.replace(false) {
            self.err(
                cx,
                tval.span(),
                format!(
                    "substituting the parameters of subtree `{rel}` makes a string longer than {} bytes, or more than {} bytes in all",
                    self.limits.max_name_bytes, self.limits.max_file_bytes
                ),
            )
            .hint = Some("shorten the `with` values, or raise --max-name-bytes / --max-file-bytes".into());
            self.includes.insert(key, None);
            return None;
        }
        self.includes.insert(key, bt.clone());
        bt
    }

    /// Reads an included subtree file the first time (see [`Self::include`]).
    pub(super) fn read_include(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        t: &DeTable<'_>,
        rel: &str,
        path: &Path,
        canon: PathBuf,
    ) -> Option<Bt> {
        let tval = t.get("subtree").expect("a subtree node");
        let file = self.included_file(cx, id, tval, path)?;
        let doc = self.parse_doc(&file)?;
        let sub_table = doc.get_ref();
        let sub_cx0 = Ctx {
            file: &file,
            base: path.parent().unwrap_or(Path::new("")),
            params: BTreeMap::new(),
            subst: self.subst.clone(),
        };
        match self.kind(&sub_cx0, sub_table, doc.span()) {
            Some("bt") => {}
            Some(k) => {
                self.err(
                    cx,
                    tval.span(),
                    format!("subtree `{rel}` of node `{id}` is a `{k}`, not a `bt`"),
                );
                return None;
            }
            None => return None,
        }
        self.check_keys(
            &sub_cx0,
            sub_table,
            &["kind", "name", "description", "root", "nodes", "params"],
            "top-level key",
        );
        // Parameters: declared defaults in the subtree file, overridden by `with`.
        let mut params = self.declared_params(&sub_cx0, sub_table);
        self.with_params(cx, id, t, rel, &mut params);
        let sub_cx = Ctx {
            file: &file,
            base: sub_cx0.base,
            params,
            subst: self.subst.clone(),
        };
        self.stack.push(canon);
        let bt = self.bt(&sub_cx, sub_table, doc.span(), Some(""));
        self.stack.pop();
        bt
    }

    /// Reads the file a `subtree` names (`tval`), charging its bytes to
    /// what includes may still read.
    fn included_file(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        tval: &Val<'_>,
        path: &Path,
    ) -> Option<Arc<SourceFile>> {
        let shown = path.display().to_string();
        let file = match read_included(path, &shown, &self.limits, crate::source::Named::TomlPolicy)
        {
            Ok(f) => f,
            Err(mut ds) => {
                let d = ds.remove(0);
                self.err(
                    cx,
                    tval.span(),
                    format!("subtree of node `{id}`: {}", d.message),
                )
                .hint = d.hint;
                return None;
            }
        };
        let len = file.text.len() as u64;
        if len > self.include_bytes {
            self.err(
                cx,
                tval.span(),
                format!(
                    "subtree includes read more than {} bytes in total",
                    self.limits.max_file_bytes
                ),
            )
            .hint = Some("raise the limit with --max-file-bytes".into());
            return None;
        }
        self.include_bytes -= len;
        Some(file)
    }

    /// The parameters a subtree file declares (`[params]`), with their
    /// default values as text.
    fn declared_params(
        &mut self,
        sub_cx: &Ctx<'_>,
        sub_table: &DeTable<'_>,
    ) -> BTreeMap<String, String> {
        let mut params = BTreeMap::new();
        if let Some(pv) = sub_table.get("params") {
            match pv.get_ref() {
                DeValue::Table(pt) => {
                    for (k, v) in pt.iter() {
                        params.insert(k.get_ref().to_string(), scalar_text(v.get_ref()));
                    }
                }
                other => {
                    self.err(
                        sub_cx,
                        pv.span(),
                        format!("`params` must be a table, found {}", type_name(other)),
                    );
                }
            }
        }
        params
    }

    /// Overrides declared parameters with the including node's `with`
    /// values (substituted in the including file's parameters).
    fn with_params(
        &mut self,
        cx: &Ctx<'_>,
        id: &str,
        t: &DeTable<'_>,
        rel: &str,
        params: &mut BTreeMap<String, String>,
    ) {
        let Some(wv) = t.get("with") else {
            return;
        };
        match wv.get_ref() {
            DeValue::Table(wt) => {
                for (k, v) in wt.iter() {
                    if !params.contains_key(k.get_ref().as_ref()) {
                        let declared: Vec<&str> = params.keys().map(String::as_str).collect();
                        let h = if declared.is_empty() {
                            format!("`{rel}` declares no `[params]`")
                        } else {
                            self.suggest(k.get_ref(), declared)
                        };
                        self.err(
                            cx,
                            k.span(),
                            format!("subtree `{rel}` has no parameter `{}`", k.get_ref()),
                        )
                        .hint = Some(h);
                        continue;
                    }
                    params.insert(k.get_ref().to_string(), cx.subst(&scalar_text(v.get_ref())));
                }
            }
            other => {
                self.err(
                    cx,
                    wv.span(),
                    format!(
                        "`with` of node `{id}` must be a table, found {}",
                        type_name(other)
                    ),
                );
            }
        }
    }

    // ---------------------------------------------------------------- FSM
}
