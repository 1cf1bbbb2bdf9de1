//! What a file offers to choose from (its scenes and material variants) and what it holds besides
//! (its animations), as [`crate::SceneInfo`] lists them, and how a user names a scene.

use std::convert::Infallible;
use std::fmt;
use std::str::FromStr;

/// A scene or an animation of a glTF file, chosen by position or by name
/// ([`crate::LoadOptions::scene`], [`crate::LoadOptions::animation`]).
///
/// Parsed from text by [`str::parse`], which never fails: text made only of the digits `0`–`9`
/// is an index, anything else a name. (One whose name is all digits is chosen by its index.)
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IndexOrName {
    /// The entry at this position of the file's list (from 0).
    Index(usize),
    /// The first entry with this `name`.
    Name(String),
}

/// Which of a glTF file's scenes to draw ([`crate::LoadOptions::scene`]).
pub type SceneChoice = IndexOrName;

/// Which of a glTF file's animations to pose by ([`crate::LoadOptions::animation`]).
pub type AnimationChoice = IndexOrName;

impl FromStr for IndexOrName {
    type Err = Infallible;

    fn from_str(text: &str) -> Result<Self, Infallible> {
        let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
        Ok(match text.parse::<usize>() {
            Ok(index) if digits => IndexOrName::Index(index),
            _ => IndexOrName::Name(text.to_string()),
        })
    }
}

impl fmt::Display for IndexOrName {
    /// `2` for an index, `'name'` for a name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IndexOrName::Index(i) => write!(f, "{i}"),
            IndexOrName::Name(n) => write!(f, "'{n}'"),
        }
    }
}

/// One scene of a glTF file ([`crate::SceneInfo::scenes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileScene {
    /// Its position in the file's `scenes` list.
    pub index: usize,
    /// Its `name`, when it has one.
    pub name: Option<String>,
    /// Whether it is drawn when no scene is chosen: the file's `scene`, else scene 0.
    pub is_default: bool,
    /// Whether it is the scene this load drew.
    pub loaded: bool,
}

/// One animation of a glTF file ([`crate::SceneInfo::animations`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FileAnimation {
    /// Its position in the file's `animations` list.
    pub index: usize,
    /// Its `name`, when it has one.
    pub name: Option<String>,
    /// Its length in seconds: the latest key time of its samplers (the largest `max` of their
    /// input accessors, or of their data where `max` is missing); 0 when no sampler's times
    /// could be read (a warning says why).
    pub duration_seconds: f32,
}

/// How many entries an error message lists before it says how many more there are.
const LISTED: usize = 16;

/// `items` (each one line) joined by `, `, at most [`LISTED`] of them, then `… (N more)`; `none` when empty.
pub(crate) fn listing(items: impl ExactSizeIterator<Item = String>, none: &str) -> String {
    let total = items.len();
    if total == 0 {
        return none.to_string();
    }
    let mut text = items.take(LISTED).collect::<Vec<_>>().join(", ");
    if total > LISTED {
        text.push_str(&format!(", … ({} more)", total - LISTED));
    }
    text
}

/// The error for a scene choice that no scene of `scenes` matches, listing them.
pub(crate) fn unknown_scene(choice: &SceneChoice, scenes: &[FileScene]) -> String {
    let list = listing(
        scenes.iter().map(|s| {
            let name = s
                .name
                .as_deref()
                .map_or(String::new(), |n| format!(" '{}'", crate::one_line(n)));
            let default = if s.is_default { " (default)" } else { "" };
            format!("{}{name}{default}", s.index)
        }),
        "none",
    );
    let choice = crate::one_line(&choice.to_string());
    format!("no scene {choice} in the file; its scenes: {list}")
}

/// The error for a material variant name that the file does not define, listing those it does.
pub(crate) fn unknown_variant(name: &str, variants: &[String]) -> String {
    let list = listing(
        variants.iter().map(|v| format!("'{}'", crate::one_line(v))),
        "none",
    );
    format!(
        "no material variant '{}' in the file; its variants: {list}",
        crate::one_line(name)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_are_an_index_and_anything_else_a_name() {
        let parse = |t: &str| t.parse::<SceneChoice>().unwrap();
        assert_eq!(parse("2"), SceneChoice::Index(2));
        assert_eq!(parse("007"), SceneChoice::Index(7));
        for name in ["+2", " 2", "", "scene 2", "99999999999999999999999"] {
            assert_eq!(parse(name), SceneChoice::Name(name.to_string()));
        }
        assert_eq!(SceneChoice::Index(3).to_string(), "3");
        assert_eq!(SceneChoice::Name("x".into()).to_string(), "'x'");
    }

    #[test]
    fn unknown_choices_list_what_the_file_has_on_one_line() {
        let scenes = [
            FileScene {
                index: 0,
                name: Some("day".into()),
                is_default: false,
                loaded: false,
            },
            FileScene {
                index: 1,
                name: None,
                is_default: true,
                loaded: false,
            },
        ];
        assert_eq!(
            unknown_scene(&SceneChoice::Index(5), &scenes),
            "no scene 5 in the file; its scenes: 0 'day', 1 (default)"
        );
        assert_eq!(
            unknown_scene(&SceneChoice::Name("x".into()), &[]),
            "no scene 'x' in the file; its scenes: none"
        );
        let many: Vec<String> = (0..20).map(|i| format!("v{i}")).collect();
        let message = unknown_variant("red", &many);
        assert!(message.starts_with("no material variant 'red' in the file; its variants: 'v0', "));
        assert!(message.ends_with("'v15', … (4 more)"), "{message}");
        assert!(!message.contains('\n'));
    }
}
