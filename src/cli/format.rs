//! `--format`: one enum for every command ([`Format`], from
//! `btfsm_core::output`), each command accepting exactly the formats its
//! report is written in, so that `--help` lists those and any other is a
//! usage error before anything runs.

use btfsm_core::output::Format;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

/// The help of the formats that need one on a command's `--help`.
pub(crate) type Help = &'static [(Format, &'static str)];

/// The value parser of a `--format` that takes `formats` (a command's
/// `Report::FORMATS` where it has one, so the two cannot disagree).
pub(crate) fn parser(
    formats: &'static [Format],
    help: Help,
) -> impl TypedValueParser<Value = Format> {
    PossibleValuesParser::new(formats.iter().map(|&f| {
        let v = PossibleValue::new(f.name());
        match help.iter().find(|(g, _)| *g == f) {
            Some((_, h)) => v.help(*h),
            None => v,
        }
    }))
    // The parser admits only these names, each the name of a format.
    .map(|name| Format::from_name(&name).unwrap_or(Format::Table))
}

/// Comparisons: `compare` and `log compare`.
pub(crate) const COMPARISON: &[Format] = &[Format::Table, Format::Json, Format::Markdown];

/// The help of markdown in a comparison.
pub(crate) const COMPARISON_HELP: Help = &[(
    Format::Markdown,
    "GitHub-flavoured markdown, for a pull-request comment",
)];

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Args {
        #[arg(long, value_parser = parser(COMPARISON, COMPARISON_HELP), default_value = "table")]
        format: Format,
    }

    #[test]
    fn a_command_takes_its_formats_and_refuses_the_others() {
        let f = |a: &[&str]| Args::try_parse_from(a).map(|a| a.format);
        assert_eq!(f(&["x"]).unwrap(), Format::Table);
        assert_eq!(f(&["x", "--format", "markdown"]).unwrap(), Format::Markdown);
        assert!(f(&["x", "--format", "csv"]).is_err());
    }
}
