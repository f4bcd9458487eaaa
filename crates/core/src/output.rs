//! One output-format abstraction for every command, after hyperfine's
//! exporters: [`Format`] names every format a btfsm report is written in,
//! and a [`Report`] says which of them it is written in and writes itself
//! in each. A command's `--format` accepts exactly its report's formats.

/// Every format btfsm writes a report in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Format {
    /// Aligned plain-text tables.
    Table,
    /// Positioned messages with snippets (`lint`).
    Text,
    /// Pretty-printed JSON, a documented contract per command.
    Json,
    /// Comma-separated values, one row per item, formulas defused.
    Csv,
    /// GitHub-flavoured Markdown, for a pull-request comment.
    Markdown,
    /// SARIF 2.1.0, for code scanning (`lint`).
    Sarif,
    /// JUnit XML, the test report CI systems read (`lint`).
    Junit,
}

impl Format {
    /// Every format, in the order `--help` lists them.
    pub const ALL: [Format; 7] = [
        Format::Table,
        Format::Text,
        Format::Json,
        Format::Csv,
        Format::Markdown,
        Format::Sarif,
        Format::Junit,
    ];

    /// The name `--format` takes.
    pub const fn name(self) -> &'static str {
        match self {
            Format::Table => "table",
            Format::Text => "text",
            Format::Json => "json",
            Format::Csv => "csv",
            Format::Markdown => "markdown",
            Format::Sarif => "sarif",
            Format::Junit => "junit",
        }
    }

    /// The format of a name `--format` takes.
    pub fn from_name(name: &str) -> Option<Format> {
        Format::ALL.into_iter().find(|f| f.name() == name)
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A report a command prints.
pub trait Report {
    /// The formats it is written in, its default first.
    const FORMATS: &'static [Format];

    /// The report in `format`, one of [`Report::FORMATS`]; any other
    /// format writes the default.
    fn write(&self, format: Format) -> String;

    /// `format` if the report is written in it, else the default.
    fn supported(format: Format) -> Format {
        if Self::FORMATS.contains(&format) {
            format
        } else {
            Self::FORMATS[0]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_has_one_name_that_reads_back() {
        for f in Format::ALL {
            assert_eq!(Format::from_name(f.name()), Some(f));
        }
        assert_eq!(Format::from_name("yaml"), None);
    }

    struct Two;
    impl Report for Two {
        const FORMATS: &'static [Format] = &[Format::Table, Format::Json];
        fn write(&self, format: Format) -> String {
            Self::supported(format).to_string()
        }
    }

    #[test]
    fn a_format_a_report_is_not_written_in_writes_its_default() {
        assert_eq!(Two.write(Format::Json), "json");
        assert_eq!(Two.write(Format::Sarif), "table");
    }
}
