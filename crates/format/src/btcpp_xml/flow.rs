//! The dataflow record of one node as the tree is expanded: the ports its
//! type declares (a `<TreeNodesModel>` entry, or a BehaviorTree.CPP 4
//! built-in's, [`super::ports::builtin_ports`]), its attributes, and the
//! blackboard entries they read and write, resolved through the SubTree
//! remappings around it (BehaviorTree.CPP 4 "Remapping ports between Trees
//! and SubTrees"; a script's names are looked up the same way, as the
//! subtree's blackboard does).

use super::super::xml::XElem;
use super::expand::port_key;
use super::loader::Loader;
use super::ports::{Access, Key, KeyUse, NodeFlow, PortDir, PortUse, SCRIPT_ATTRS};
use super::{builtin, builtin_ports, v4_name};

impl Loader<'_> {
    /// The declared ports of node type `ty` read from document `d`, cached
    /// per type: a built-in's (not in a `BTCPP_format="3"` file, whose
    /// built-ins are BehaviorTree.CPP 3's), else its model entry's.
    fn decl_of(&mut self, d: usize, ty: &str) -> (Option<usize>, bool) {
        let is_builtin = builtin(ty).is_some();
        if is_builtin && self.format_3(d) {
            return (None, true);
        }
        if let Some(&x) = self.flow.types.get(ty) {
            return (x, is_builtin);
        }
        let ports = if is_builtin {
            builtin_ports(v4_name(ty))
        } else {
            self.models.get(ty).map(|m| m.ports.clone())
        };
        let x = ports.map(|p| {
            self.flow.decls.push(p);
            self.flow.decls.len() - 1
        });
        self.flow.types.insert(ty.to_string(), x);
        (x, is_builtin)
    }

    /// What node `node` (element `el` of document `d`) does with the
    /// blackboard; `key` resolves a `{key}` in its expansion.
    pub(super) fn node_flow(
        &mut self,
        d: usize,
        el: &XElem,
        node: usize,
        key: impl Fn(&str) -> Key,
    ) -> NodeFlow {
        let ty = match el.name.as_str() {
            "Action" | "Condition" | "Control" | "Decorator" => el.attr("ID").unwrap_or(""),
            t => t,
        }
        .to_string();
        let (decl, is_builtin) = self.decl_of(d, &ty);
        let ports = decl.map(|x| &self.flow.decls[x]);
        let mut uses = Vec::new();
        let mut keys = Vec::new();
        let script =
            |text: &str, span: &std::ops::Range<usize>, port: &str, keys: &mut Vec<KeyUse>| {
                for (name, access) in super::ports::script_keys(text) {
                    keys.push(KeyUse {
                        key: key(&name),
                        access,
                        port: port.to_string(),
                        ty: None,
                        span: span.clone(),
                    });
                }
            };
        for a in el.attrs.iter().filter(|a| a.ns.is_none()) {
            if a.name == "name" || a.name == "ID" {
                continue;
            }
            if a.name.starts_with('_') {
                if SCRIPT_ATTRS.contains(&a.name.as_str()) {
                    script(&a.value, &a.span, &a.name, &mut keys);
                }
                continue;
            }
            uses.push(PortUse {
                name: a.name.clone(),
                value: a.value.clone(),
                span: a.span.clone(),
            });
            let p = ports.and_then(|ps| ps.iter().find(|p| p.name == a.name));
            if p.is_some_and(|p| p.script) {
                script(&a.value, &a.span, &a.name, &mut keys);
                continue;
            }
            // The entry the value names: `{key}`, `{=}` (the port's name),
            // SetBlackboard's `output_key` by bare name.
            let named = match port_key(&a.value) {
                Some("=") => Some(a.name.as_str()),
                Some(k) => Some(k),
                None if a.value == "=" && p.is_some_and(|p| p.dir != PortDir::Input) => {
                    Some(a.name.as_str())
                }
                None if p.is_some_and(|p| p.key_name) && !a.value.is_empty() => {
                    Some(a.value.as_str())
                }
                None => None,
            };
            let Some(k) = named else { continue };
            let access = match p {
                Some(p) if p.key_name => Access::Write,
                Some(p) => match p.dir {
                    PortDir::Input => Access::Read,
                    PortDir::Output => Access::Write,
                    PortDir::InOut => Access::ReadWrite,
                },
                None => Access::Unknown,
            };
            keys.push(KeyUse {
                key: key(k),
                access,
                port: a.name.clone(),
                ty: p.and_then(|p| p.ty.clone()),
                span: a.span.clone(),
            });
        }
        NodeFlow {
            node,
            ty,
            doc: d,
            span: el.span.clone(),
            decl,
            builtin: is_builtin,
            ports: uses,
            keys,
        }
    }
}
