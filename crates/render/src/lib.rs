//! Drawing policies: DOT text in the paper's visual language ([`dot::policy_dot`])
//! and rendering it to SVG or PNG with Graphviz ([`dot::render`]).

pub mod dot;
pub mod mermaid;

pub use dot::{
    DotOptions, Highlight, RenderError, RenderFormat, Status, policy_dot, render, render_with,
};
