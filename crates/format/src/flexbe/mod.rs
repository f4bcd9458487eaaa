//! FlexBE behaviors (`*_sm.py`, the Python code the FlexBE App generates
//! for a behavior; team-vigir/flexbe_behavior_engine) read statically into
//! the FSM/HFSM model: the file is parsed with a Python 3 parser
//! (`rustpython-parser`), never run.
//!
//! What is read, from the `create` method of the class that derives
//! `Behavior` (flexbe_core's `Behavior.create` builds and returns the state
//! machine):
//!
//! - `VAR = OperatableStateMachine(outcomes=[...])` defines a container;
//!   `ConcurrencyContainer(outcomes=[...], conditions=[...])` one whose
//!   states all run at once (a parallel region, as SCXML's `<parallel>` and
//!   yasmin's `Concurrence`: flexbe_core's `ConcurrencyContainer` executes
//!   every state it holds each tick and ends when one of its `conditions`
//!   holds); `PriorityContainer` a sequential one (it only pauses the
//!   states running beside it). The container `create` returns is the
//!   machine; the others are states of the container they are added to.
//! - `with VAR:` opens a container; each statement in it is
//!   `OperatableStateMachine.add('Label', STATE, transitions={...},
//!   autonomy={...}, remapping={...})` (flexbe_core's
//!   `OperatableStateMachine.add(label, state, transitions, autonomy,
//!   remapping)`): a state named `Label`. `STATE` is a container's
//!   variable (a nested machine) or any other expression (a task state:
//!   a state class instance, or `self.use_behavior(...)`, an embedded
//!   behavior, kept opaque). The first state added is the initial one
//!   (flexbe_core's `StateMachine.initial_state`).
//! - `transitions` maps each outcome to a target: a state added to the same
//!   container, else one of its outcomes (flexbe_core's
//!   `StateMachine._execute_current_state` looks the label up first, then
//!   returns the target as the container's outcome).
//! - `autonomy` (`Autonomy.Off`, `Low`, `High`, `Full`, `Inherit`) is kept
//!   in the state's label, e.g. `Decide [back:High done:Low]`; `remapping`
//!   and userdata are data flow, not read.
//!
//! Every other construct inside a `with` block, a container or `add` call
//! whose arguments are not literals, is an error at its position naming
//! what is valid; code outside `with` blocks (userdata, manual sections)
//! is ignored. Input is bounded before parsing: at most
//! [`MAX_FLEXBE_BYTES`] and at most [`MAX_PY_NESTING`] levels of brackets,
//! operators and blocks (a pre-scan of the tokens), so that the syntax tree is never
//! deep enough for its recursive drop to exhaust the stack.

mod build;
mod collect;

use super::{Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use rustpython_parser::{Mode, Tok, lexer::LexResult};
use std::path::Path;
use std::sync::Arc;

/// Largest FlexBE behavior read, in bytes: generated behaviors are tens of
/// kilobytes (the largest of team-vigir/vigir_behaviors is 40 KB).
pub const MAX_FLEXBE_BYTES: usize = 2 * 1024 * 1024;

/// Deepest nesting of brackets, operators and indented blocks accepted
/// (CPython refuses 200 nested parentheses), checked on the tokens before parsing.
pub const MAX_PY_NESTING: usize = 200;

/// Does a file look like a FlexBE behavior: a `.py` file that derives
/// `Behavior` and builds an `OperatableStateMachine`? (For a directory
/// walk; a `.py` file named on the command line is read as one whatever
/// it holds.)
pub fn looks_like_flexbe(path: &Path, text: &str) -> bool {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase();
    name.ends_with(".py") && text.contains("(Behavior)") && text.contains("OperatableStateMachine")
}

/// Reads a FlexBE behavior already read from `path`.
pub fn load_read(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let module = parse(&file)?;
    let mut diags = Vec::new();
    let behavior = collect::collect(&module, &file, &mut diags);
    drop(module);
    let policy = behavior.and_then(|b| build::build(b, &file, limits, &mut diags));
    super::finish(&file, policy, diags, "FlexBE behavior")
}

/// Reads a FlexBE behavior from text (tests, fuzzing).
pub fn parse_str(name: &str, text: &str, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load_read(SourceFile::new(name, text), limits)
}

/// The file's statements, once its size and nesting are within bounds and
/// it parses as Python 3.
fn parse(file: &Arc<SourceFile>) -> Result<Vec<rustpython_parser::ast::Stmt>, Vec<Diagnostic>> {
    let text = &file.text;
    if text.len() > MAX_FLEXBE_BYTES {
        return Err(vec![
            Diagnostic::error(format!(
                "this FlexBE behavior is {} bytes, more than the limit of {MAX_FLEXBE_BYTES} bytes",
                text.len()
            ))
            .in_file(file)
            .hint("FlexBE behaviors are generated files of tens of kilobytes; split this one"),
        ]);
    }
    let tokens = prescan(file)?;
    match rustpython_parser::parse_tokens(tokens, Mode::Module, &file.path) {
        Ok(rustpython_parser::ast::Mod::Module(m)) => Ok(m.body),
        Ok(_) => Err(vec![Diagnostic::error("not a Python module").in_file(file)]),
        Err(e) => {
            let at = (e.offset.to_usize()).min(text.len());
            Err(vec![syntax_error(file, at, &e.error.to_string())])
        }
    }
}

fn syntax_error(file: &Arc<SourceFile>, at: usize, what: &str) -> Diagnostic {
    let end = text_end(&file.text, at);
    Diagnostic::error(format!(
        "not valid Python 3: {}",
        btfsm_core::sanitize::shown(what)
    ))
    .at(file, at..end)
    .hint("a FlexBE behavior is read as Python 3 source (a Python 2 `print x` statement is not)")
}

/// The end of the character at `at` (a one-character span), or `at` at the
/// end of the text.
fn text_end(text: &str, at: usize) -> usize {
    text.get(at..)
        .and_then(|r| r.chars().next())
        .map_or(at, |c| at + c.len_utf8())
}

/// The tokens of the file, refused when they nest deeper than
/// [`MAX_PY_NESTING`]. The bound counts what makes the syntax tree deep:
/// indented blocks, open brackets, and at each bracket level the operators
/// since its last comma (`a + b + c` nests, `[a, b, c]` does not; an
/// f-string's punctuation counts too, as its expressions are parsed from
/// the string). The tree's depth is at most a small multiple of it.
fn prescan(file: &Arc<SourceFile>) -> Result<Vec<LexResult>, Vec<Diagnostic>> {
    let mut tokens = Vec::new();
    let mut blocks = 0usize;
    // Operators since the last comma, per open bracket (the first entry is
    // the statement's own level).
    let mut levels: Vec<usize> = vec![0];
    let mut depth = 0usize; // blocks + open brackets + the sum of `levels`
    for t in rustpython_parser::lexer::lex(&file.text, Mode::Module) {
        let (tok, range) = match &t {
            Ok((tok, range)) => (tok, range),
            Err(e) => {
                let at = e.location.to_usize().min(file.text.len());
                return Err(vec![syntax_error(file, at, &e.error.to_string())]);
            }
        };
        let mut extra = 0usize;
        match tok {
            Tok::Indent => blocks += 1,
            Tok::Dedent => blocks = blocks.saturating_sub(1),
            Tok::Lpar | Tok::Lsqb | Tok::Lbrace => levels.push(0),
            Tok::Rpar | Tok::Rsqb | Tok::Rbrace if levels.len() > 1 => {
                levels.pop();
            }
            Tok::Comma | Tok::Newline => {
                if let Some(l) = levels.last_mut() {
                    *l = 0;
                }
            }
            Tok::String { value, kind, .. } => {
                if matches!(
                    kind,
                    rustpython_parser::StringKind::FString
                        | rustpython_parser::StringKind::RawFString
                ) {
                    extra = value
                        .chars()
                        .filter(|c| c.is_ascii_punctuation() && *c != '_')
                        .count();
                }
            }
            t if nests(t) => {
                if let Some(l) = levels.last_mut() {
                    *l += 1;
                }
            }
            _ => {}
        }
        depth = depth.max(blocks + levels.len() + levels.iter().sum::<usize>() + extra);
        if depth > MAX_PY_NESTING {
            let at = range.start().to_usize();
            let end = range.end().to_usize().max(at);
            return Err(vec![
                Diagnostic::error(format!(
                    "this Python nests more than {MAX_PY_NESTING} levels deep (blocks, brackets and operators)"
                ))
                .at(file, at..end)
                .hint("a FlexBE behavior nests a few levels; split the expression or the block"),
            ]);
        }
        tokens.push(t);
    }
    Ok(tokens)
}

/// Does a token make the expression around it one level deeper (an
/// operator, a keyword operator, an attribute access)?
fn nests(t: &Tok) -> bool {
    use Tok::*;
    matches!(
        t,
        Plus | Minus
            | Star
            | Slash
            | Vbar
            | Amper
            | Less
            | Greater
            | Dot
            | Percent
            | EqEqual
            | NotEqual
            | LessEqual
            | GreaterEqual
            | Tilde
            | CircumFlex
            | LeftShift
            | RightShift
            | DoubleStar
            | DoubleSlash
            | ColonEqual
            | At
            | And
            | Or
            | Not
            | If
            | Else
            | Lambda
            | Await
            | Yield
            | In
            | Is
    )
}

#[cfg(test)]
mod tests;
