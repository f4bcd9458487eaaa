//! What a TOML document may cost before it is parsed (issue 33).
//!
//! The `toml` crate (1.x, `toml::de::DeTable::parse`, which `toml::from_str`
//! uses too) lexes the whole document into a vector of tokens, then a vector
//! of parse events at least as long, then builds the tables: measured on
//! 8 MB documents of `=` lines, `a=1` lines, `[a]` headers, one array of
//! 4 million integers, 2.7 million `{}` and 8 million dots, 70-112 bytes of
//! memory per token (release build, peak RSS). Any count limit of a
//! document (nodes, states, stations, rules) is checked only after that,
//! so a 60 MB file of `=` lines peaked at 4.45 GB before its first error.
//!
//! [`check`] counts the tokens first with the same lexer
//! (`toml_parser::Source::lex`, an iterator: constant memory, about 20 ms
//! per MB) and refuses a document with more than its reader allows, at the
//! first token beyond, before any of that is allocated: at most
//! [`TOKEN_COST`] × tokens bytes are then spent parsing, which
//! [`max_tokens`] keeps within 56 × the bytes read + 192 MiB (the project's
//! bound is 64 × the bytes read + 200 MB: docs/robustness.md).

use crate::diagnostic::{Diagnostic, SourceFile};
use std::sync::Arc;

/// Bytes of memory one token costs the `toml` crate's parser, at most (the
/// worst measured is 112, a document of dots).
pub const TOKEN_COST: u64 = 128;

/// Tokens a reader allows by default for a document of fixed counts (a
/// scenario, a domain, a tick script, `btfsm.toml`): 50 per node of the
/// default `--max-nodes` (150,000), the same as a policy at that limit.
pub const DEFAULT_MAX_TOKENS: u64 = 50 * 150_000;

/// Tokens per node a policy may spend: a BT node written in full (a
/// condition with a label, a skill and two arguments) is about 25, an FSM
/// state with three transitions about 50.
pub const TOKENS_PER_NODE: u64 = 50;

/// The tokens a document of `bytes` bytes may hold: `limit` (its reader's
/// count limit), and at most one per two bytes read plus 1.5 million, so
/// that parsing costs at most [`TOKEN_COST`] × that: 64 × bytes + 192 MiB.
/// Real documents hold one token per 3 to 5 bytes.
pub fn max_tokens(bytes: usize, limit: u64) -> u64 {
    limit.min(bytes as u64 / 2 + 1_500_000)
}

/// Refuses `file` when its TOML holds more than [`max_tokens`] tokens
/// (keys, values, punctuation, whitespace runs, comments), positioned at
/// the first token beyond; `hint` says how to raise the limit.
pub fn check(file: &Arc<SourceFile>, limit: u64, hint: &str) -> Result<(), Diagnostic> {
    let max = max_tokens(file.text.len(), limit);
    let source = toml_parser::Source::new(&file.text);
    let mut tokens = (source.lex()).filter(|t| t.kind() != toml_parser::lexer::TokenKind::Eof);
    let Some(beyond) = tokens.nth(usize::try_from(max).unwrap_or(usize::MAX)) else {
        return Ok(());
    };
    let span = beyond.span();
    Err(Diagnostic::error(format!(
        "more than {max} TOML tokens (keys, values, punctuation, blanks): this document would cost more memory to parse than its reader allows"
    ))
    .at(file, span.start()..span.end().max(span.start() + 1).min(file.text.len()))
    .hint(format!(
        "at most {limit} tokens, and one per two bytes of the file past 1.5 million; {hint}"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_past_the_limit_are_refused_at_the_first_one_beyond() {
        let f = SourceFile::new("t.toml", "a = 1\nb = 2\n".to_string());
        // `a`, ` `, `=`, ` `, `1`, `\n`: six tokens a line.
        assert!(check(&f, 12, "").is_ok());
        let d = check(&f, 11, "raise --max-nodes").unwrap_err();
        assert!(
            d.message.contains("more than 11 TOML tokens"),
            "{}",
            d.message
        );
        assert_eq!(d.span, Some(11..12));
        assert!(d.hint.as_deref().unwrap_or("").contains("--max-nodes"));
        // One token a byte: past 1.5 million plus half the bytes.
        let dots = SourceFile::new("d.toml", ".".repeat(4_000_000));
        let d = check(&dots, DEFAULT_MAX_TOKENS, "").unwrap_err();
        assert!(d.message.contains("more than 3500000"), "{}", d.message);
        assert_eq!(max_tokens(10, 5), 5);
    }
}
