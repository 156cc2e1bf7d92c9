//! Keys that were renamed because their old names did not say what they do: a file that still
//! uses one is refused with the new name and the line, instead of an unknown-key error that
//! lists every field.

use toml::de::{DeTable, DeValue};

/// A renamed key: in every table at `section` (`*` matches any one key), `old` is now `new`.
struct Renaming {
    section: &'static [&'static str],
    old: &'static str,
    new: &'static str,
    why: &'static str,
}

/// Every renamed key.
const RENAMINGS: &[Renaming] = &[
    Renaming {
        section: &["classes", "*"],
        old: "gate_m",
        new: "paper_gate_m",
        why: "it gates the `paper` association cost only; the `likelihood` cost is gated by \
              association.likelihood_gate_chi2",
    },
    Renaming {
        section: &["classes", "*"],
        old: "radial_velocity_std_mps",
        new: "initial_radial_speed_std_mps",
        why: "it is the spread of a new track's velocity along the line of sight, beside \
              initial_tangential_speed_std_mps",
    },
    Renaming {
        section: &["classes", "*"],
        old: "radial_velocity_residual_std_mps",
        new: "likelihood_radial_velocity_std_mps",
        why: "it scores the radial-velocity difference in the `likelihood` association cost only",
    },
];

/// A key of the file that was renamed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: configuration key `{old_key}` is now `{new_key}` ({why})")]
pub struct RenamedKey {
    /// The old key's dotted path, as the file has it.
    pub old_key: String,
    /// The key to use instead.
    pub new_key: String,
    /// Why it was renamed.
    pub why: &'static str,
    /// The line of the file where the old key is (from 1).
    pub line: usize,
}

/// The first renamed key in `file`, whose text is `text`.
pub(crate) fn renamed_key_in(file: &DeTable<'_>, text: &str) -> Option<RenamedKey> {
    RENAMINGS.iter().find_map(|renaming| find(file, renaming.section, &mut Vec::new(), renaming, text))
}

/// Looks for `renaming.old` in the tables of `table` at the rest of the section path `rest`.
fn find(
    table: &DeTable<'_>,
    rest: &[&str],
    path: &mut Vec<String>,
    renaming: &Renaming,
    text: &str,
) -> Option<RenamedKey> {
    let Some((first, rest)) = rest.split_first() else {
        let (key, _) = table.iter().find(|(key, _)| key.get_ref().as_ref() == renaming.old)?;
        let section = path.join(".");
        return Some(RenamedKey {
            old_key: format!("{section}.{}", renaming.old),
            new_key: format!("{section}.{}", renaming.new),
            why: renaming.why,
            line: line_of(text, key.span().start),
        });
    };
    for (key, value) in table.iter() {
        let name: &str = key.get_ref().as_ref();
        let DeValue::Table(inner) = value.get_ref() else { continue };
        if *first == "*" || *first == name {
            path.push(name.to_string());
            let found = find(inner, rest, path, renaming, text);
            path.pop();
            if found.is_some() {
                return found;
            }
        }
    }
    None
}

/// The line (from 1) of byte `offset` of `text`.
pub(crate) fn line_of(text: &str, offset: usize) -> usize {
    text.get(..offset).unwrap_or(text).matches('\n').count() + 1
}
