//! The shared strings of an edit script (keys, names, labels): one table
//! per graph, entries cloned by reference count.

use std::sync::Arc;

/// An immutable shared string of an edit script (a key, a name, a label):
/// an entry of a table of one graph's strings, built once per graph.
/// Cloning it bumps the table's one reference count, so that writing a
/// script of 100k entries allocates nothing and touches no string.
/// Compared, ordered and serialized as the string it names.
#[derive(Clone)]
pub struct Text {
    table: Arc<Vec<String>>,
    index: u32,
}

impl Text {
    /// Entry `index` of `table` (which must have it).
    pub(super) fn at(table: &Arc<Vec<String>>, index: usize) -> Text {
        debug_assert!(index < table.len());
        Text {
            table: Arc::clone(table),
            index: index as u32,
        }
    }

    pub fn as_str(&self) -> &str {
        self.table
            .get(self.index as usize)
            .map_or("", String::as_str)
    }
}

impl PartialEq for Text {
    fn eq(&self, other: &Text) -> bool {
        (Arc::ptr_eq(&self.table, &other.table) && self.index == other.index)
            || self.as_str() == other.as_str()
    }
}

impl Eq for Text {}

impl PartialOrd for Text {
    fn partial_cmp(&self, other: &Text) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Text {
    fn cmp(&self, other: &Text) -> std::cmp::Ordering {
        self.as_str().cmp(other.as_str())
    }
}

impl std::hash::Hash for Text {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.as_str().hash(h);
    }
}

impl std::fmt::Debug for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(self.as_str(), f)
    }
}

impl std::ops::Deref for Text {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl From<&str> for Text {
    fn from(s: &str) -> Text {
        Text::at(&Arc::new(vec![s.to_string()]), 0)
    }
}

impl PartialEq<str> for Text {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Text {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl std::fmt::Display for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl serde::Serialize for Text {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}
