//! Pairing the images of two cameras (stereo left and right) by file name,
//! and grouping a rig's images into frames ([`FrameGrouping`]).
//!
//! # The rule
//!
//! Each file's *number* is the last run of ASCII digits in its stem: the
//! file name without folders (`/` or `\`) and without its last extension
//! (`cam2/left07.png` -> `07`, `img_3_b.jpg` -> `3`, `left.png` -> none).
//! Numbers compare as integers (`left7` pairs with `right007`).
//!
//! 1. When no file on either side has a number, the images pair by order
//!    (the first left with the first right, ...), and [`Pairing::paired_by`]
//!    says so: the counts must be equal.
//! 2. Otherwise every file must have a number, unique on its side, and every
//!    number must be on both sides: left `n` pairs with right `n`. A name
//!    without a number, a number twice on one side, or a file without a
//!    partner is an error that names the files.
//!
//! The pairs come in the order of the left list.

use crate::error::{Error, Result};
use serde::Serialize;
use std::collections::BTreeMap;

/// How [`pair_by_number`] paired the two lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PairedBy {
    /// By the last number in the file stems.
    Number,
    /// By position: no file name had a number.
    Order,
}

/// The result of [`pair_by_number`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Pairing {
    /// Which rule applied.
    pub paired_by: PairedBy,
    /// `(left index, right index)` into the given lists, in left order.
    pub pairs: Vec<(usize, usize)>,
}

/// The stem of `name`: no folders, no last extension.
fn stem(name: &str) -> &str {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    match base.rfind('.') {
        Some(dot) => &base[..dot],
        None => base,
    }
}

/// The file's number (the last run of digits in its stem) without leading
/// zeros (`"0"` for a run of zeros), or `None` when the stem has no digit.
pub fn number_in_name(name: &str) -> Option<&str> {
    let stem = stem(name);
    let end = stem.rfind(|c: char| c.is_ascii_digit())? + 1;
    let start = stem[..end]
        .char_indices()
        .rev()
        .find(|(_, c)| !c.is_ascii_digit())
        .map_or(0, |(i, c)| i + c.len_utf8());
    let digits = stem[start..end].trim_start_matches('0');
    Some(if digits.is_empty() {
        &stem[end - 1..end]
    } else {
        digits
    })
}

/// Pair `left` with `right` file names by the rule of the module docs.
pub fn pair_by_number(left: &[&str], right: &[&str]) -> Result<Pairing> {
    let numbers = |list: &[&str]| -> Vec<Option<String>> {
        list.iter()
            .map(|n| number_in_name(n).map(str::to_string))
            .collect()
    };
    let (nl, nr) = (numbers(left), numbers(right));
    if nl.iter().chain(&nr).all(Option::is_none) {
        return by_order(left.len(), right.len());
    }
    let without: Vec<&str> = left
        .iter()
        .zip(&nl)
        .chain(right.iter().zip(&nr))
        .filter(|(_, n)| n.is_none())
        .map(|(name, _)| *name)
        .collect();
    if !without.is_empty() {
        return Err(invalid(format!(
            "images are paired by the last number in their file names, but {} no number: {} \
             (number every file, e.g. left01.png with right01.png, or none to pair by order)",
            if without.len() == 1 {
                "this name has"
            } else {
                "these names have"
            },
            without.join(", ")
        )));
    }
    let index_l = index_by_number(left, &nl, "left")?;
    let index_r = index_by_number(right, &nr, "right")?;
    let mut unpaired: Vec<String> = Vec::new();
    for (side, mine, other, names) in [
        ("left", &index_l, &index_r, left),
        ("right", &index_r, &index_l, right),
    ] {
        for (number, &i) in mine {
            if !other.contains_key(number) {
                unpaired.push(format!("{} ({side}, number {number})", names[i]));
            }
        }
    }
    if !unpaired.is_empty() {
        return Err(invalid(format!(
            "images are paired by the last number in their file names; no partner for: {}",
            unpaired.join(", ")
        )));
    }
    let pairs = nl
        .iter()
        .enumerate()
        .filter_map(|(i, n)| n.as_ref().and_then(|n| index_r.get(n)).map(|&j| (i, j)))
        .collect();
    Ok(Pairing {
        paired_by: PairedBy::Number,
        pairs,
    })
}

/// How a rig's images form frames (`robocal rig --group-by`, the page's
/// rig step): each image gets a frame key from its file name (without
/// folders), and images of different cameras with the same key are one
/// frame. Keys are numbers without leading zeros (`sync036` and `sync36`
/// are one frame).
///
/// | rule       | key                                                       |
/// |------------|-----------------------------------------------------------|
/// | `number`   | the last run of digits in the stem (the default)          |
/// | `last`     | the same                                                  |
/// | `first`    | the first run of digits in the stem                       |
/// | `order`    | the position in the camera's list (`0`, `1`, ...)         |
/// | a pattern  | the digits of its one `(\d+)`, e.g. `sync(\d+)`           |
///
/// A pattern is literal text with one `(\d+)` (no other regular-expression
/// syntax): it matches the file name without folders, extension included,
/// at the first place where the text before `(\d+)` is followed by one or
/// more digits (all of them are taken) and then by the text after it.
/// `sync(\d+)` takes `036` from `sync036_cam0.jpg` and from
/// `cam1_sync036.png`; `left_(\d+).png` takes `12` from `0001_left_12.png`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameGrouping {
    /// `number`: the last run of digits in the stem.
    Number,
    /// `last`: the last run of digits in the stem (as `number`).
    Last,
    /// `first`: the first run of digits in the stem.
    First,
    /// `order`: the position in each camera's list.
    Order,
    /// A pattern: the digits between `before` and `after`.
    Pattern {
        /// Literal text before the digits.
        before: String,
        /// Literal text after the digits.
        after: String,
    },
}

/// The rules, for errors that name them.
pub const GROUPING_RULES: &str = "number or last (the last number in the name, the default), first (the first number), order (the position in each camera's list), or a pattern with one (\\d+) such as sync(\\d+)";

const CAPTURE: &str = "(\\d+)";

impl FrameGrouping {
    /// The grouping of a rule name or pattern (see the type's docs).
    pub fn from_rule(rule: &str) -> Result<FrameGrouping> {
        match rule {
            "number" => return Ok(FrameGrouping::Number),
            "last" => return Ok(FrameGrouping::Last),
            "first" => return Ok(FrameGrouping::First),
            "order" => return Ok(FrameGrouping::Order),
            _ => {}
        }
        let refuse = |why: String| {
            Error::invalid(
                "group_by",
                format!("takes {GROUPING_RULES}; got '{}': {why}", shown(rule)),
            )
        };
        let Some((before, after)) = rule.split_once(CAPTURE) else {
            return Err(refuse("not a rule name, and no (\\d+) in it".into()));
        };
        if after.contains(CAPTURE) {
            return Err(refuse("a pattern has one (\\d+)".into()));
        }
        let special = |c: char| "\\()[]{}*+?|^$".contains(c) || c == '/' || c.is_control();
        if let Some(c) = before.chars().chain(after.chars()).find(|&c| special(c)) {
            return Err(refuse(format!(
                "'{}' is not literal text: besides its (\\d+), a pattern is plain text (no other regular-expression syntax, no folders)",
                shown(&c.to_string())
            )));
        }
        Ok(FrameGrouping::Pattern {
            before: before.to_string(),
            after: after.to_string(),
        })
    }

    /// The rule as written (`number`, ..., or the pattern).
    pub fn rule(&self) -> String {
        match self {
            FrameGrouping::Number => "number".into(),
            FrameGrouping::Last => "last".into(),
            FrameGrouping::First => "first".into(),
            FrameGrouping::Order => "order".into(),
            FrameGrouping::Pattern { before, after } => format!("{before}{CAPTURE}{after}"),
        }
    }

    /// What the keys are, for messages.
    fn describe(&self) -> String {
        match self {
            FrameGrouping::Number | FrameGrouping::Last => {
                "the last number in the file names".into()
            }
            FrameGrouping::First => "the first number in the file names".into(),
            FrameGrouping::Order => "order".into(),
            FrameGrouping::Pattern { .. } => {
                format!(
                    "the number of the pattern {} in the file names",
                    self.rule()
                )
            }
        }
    }

    /// The frame key of one file name (`None`: the name has none); not
    /// for [`FrameGrouping::Order`], whose keys are positions.
    pub fn key(&self, name: &str) -> Option<String> {
        let digits = match self {
            FrameGrouping::Number | FrameGrouping::Last => {
                return number_in_name(name).map(str::to_string)
            }
            FrameGrouping::Order => return None,
            FrameGrouping::First => first_digits(stem(name)),
            FrameGrouping::Pattern { before, after } => pattern_digits(base(name), before, after),
        }?;
        let trimmed = digits.trim_start_matches('0');
        Some(if trimmed.is_empty() { "0" } else { trimmed }.to_string())
    }
}

/// `text` with its control characters escaped, so a message stays one line.
fn shown(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// The file name without folders.
fn base(name: &str) -> &str {
    name.rsplit(['/', '\\']).next().unwrap_or(name)
}

fn first_digits(text: &str) -> Option<&str> {
    let start = text.find(|c: char| c.is_ascii_digit())?;
    let rest = &text[start..];
    let end = rest
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(rest.len());
    Some(&rest[..end])
}

fn pattern_digits<'a>(text: &'a str, before: &str, after: &str) -> Option<&'a str> {
    text.match_indices(before).find_map(|(i, _)| {
        let rest = &text[i + before.len()..];
        let end = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        (end > 0 && rest[end..].starts_with(after)).then(|| &rest[..end])
    })
}

/// The default grouping of a rig's images (`robocal rig` without
/// `--group-by`, the web app's rig step): by number unless no file name has
/// one.
pub fn default_grouping<'a>(mut names: impl Iterator<Item = &'a str>) -> FrameGrouping {
    if names.any(|n| number_in_name(n).is_some()) {
        FrameGrouping::Number
    } else {
        FrameGrouping::Order
    }
}

/// The frame key of every image of one camera of a rig (`robocal rig`),
/// by `by` (see [`FrameGrouping`]): every name must have a key, unique
/// within the camera; keys compare across cameras, so `front07.png` and
/// `side7.jpg` are one frame. `camera` names the camera in errors, which
/// list the rules.
pub fn frame_keys(names: &[&str], by: &FrameGrouping, camera: &str) -> Result<Vec<String>> {
    if *by == FrameGrouping::Order {
        return Ok((0..names.len()).map(|i| i.to_string()).collect());
    }
    let keys: Vec<Option<String>> = names.iter().map(|n| by.key(n)).collect();
    let without: Vec<&str> = names
        .iter()
        .zip(&keys)
        .filter(|(_, k)| k.is_none())
        .map(|(name, _)| *name)
        .collect();
    if !without.is_empty() {
        return Err(Error::invalid(
            "images",
            format!(
                "frames are grouped by {}, but camera {camera} has names without one: {} (group by {GROUPING_RULES})",
                by.describe(),
                without.join(", ")
            ),
        ));
    }
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, k) in keys.iter().enumerate() {
        let Some(k) = k else { continue };
        if let Some(&first) = seen.get(k.as_str()) {
            return Err(Error::invalid(
                "images",
                format!(
                    "frames are grouped by {}, but number {k} is in two camera {camera} images: {}, {} (group by {GROUPING_RULES})",
                    by.describe(),
                    names[first],
                    names[i]
                ),
            ));
        }
        seen.insert(k, i);
    }
    Ok(keys.into_iter().flatten().collect())
}

fn by_order(n_left: usize, n_right: usize) -> Result<Pairing> {
    if n_left != n_right {
        return Err(invalid(format!(
            "images are paired by order: {n_left} left but {n_right} right"
        )));
    }
    Ok(Pairing {
        paired_by: PairedBy::Order,
        pairs: (0..n_left).map(|i| (i, i)).collect(),
    })
}

/// number -> index of the one file of `side` that has it.
fn index_by_number(
    names: &[&str],
    numbers: &[Option<String>],
    side: &str,
) -> Result<BTreeMap<String, usize>> {
    let mut index = BTreeMap::new();
    for (i, n) in numbers.iter().enumerate() {
        let Some(n) = n else { continue };
        if let Some(&first) = index.get(n) {
            return Err(invalid(format!(
                "images are paired by the last number in their file names, but number {n} is in \
                 two {side} images: {}, {}",
                names[first], names[i]
            )));
        }
        index.insert(n.clone(), i);
    }
    Ok(index)
}

fn invalid(message: String) -> Error {
    Error::invalid("images", message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_number_is_the_last_run_of_digits_in_the_stem() {
        assert_eq!(number_in_name("left07.png"), Some("7"));
        assert_eq!(
            number_in_name("cam2/left.png"),
            None,
            "folders do not count"
        );
        assert_eq!(number_in_name("C:\\cam2\\img_3_b.jpg"), Some("3"));
        assert_eq!(number_in_name("view12.v2"), Some("12"), "nor the extension");
        assert_eq!(number_in_name("shot_000.png"), Some("0"));
        assert_eq!(number_in_name("left"), None);
        assert_eq!(number_in_name("2024-05-01_14"), Some("14"));
        // A multi-byte character before the digits (found by fuzzing: the
        // start of the run was taken one byte after the character's start).
        assert_eq!(number_in_name("spy_px\u{bf}76acing_m"), Some("76"));
        assert_eq!(number_in_name("Bild_über_12.png"), Some("12"));
    }

    #[test]
    fn rig_frame_keys_are_the_numbers_or_the_positions() {
        let names = ["f/front07.png", "f/front1.png"];
        assert_eq!(
            frame_keys(&names, &FrameGrouping::Number, "front").unwrap(),
            ["7", "1"]
        );
        assert_eq!(
            frame_keys(&names, &FrameGrouping::Order, "front").unwrap(),
            ["0", "1"]
        );
        assert_eq!(
            frame_keys(&["a1.png", "b.png"], &FrameGrouping::Number, "top")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the last number in the file names, but camera top has \
             names without one: b.png (group by number or last (the last number in the name, the \
             default), first (the first number), order (the position in each camera's list), or a \
             pattern with one (\\d+) such as sync(\\d+))"
        );
        assert_eq!(
            frame_keys(&["a1.png", "a01.png"], &FrameGrouping::Number, "top")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the last number in the file names, but number 1 is \
             in two camera top images: a1.png, a01.png (group by number or last (the last number \
             in the name, the default), first (the first number), order (the position in each \
             camera's list), or a pattern with one (\\d+) such as sync(\\d+))"
        );
    }

    #[test]
    fn rig_frames_group_by_the_first_the_last_or_a_pattern() {
        let rule = |r: &str| FrameGrouping::from_rule(r).unwrap();
        let cam0 = [
            "rig/sync036_cam0.jpg",
            "rig/sync037_cam0.jpg",
            "rig/sync100_cam0.jpg",
        ];
        let cam1 = ["cam1_sync036.png", "cam1_sync37.png", "cam1_sync0100.png"];
        let left = ["0001_left_12.png", "0002_left_13.png"];
        // The last number of cam0's names is the camera's: two images have it.
        assert_eq!(
            frame_keys(&cam0, &rule("number"), "cam0")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the last number in the file names, but number 0 is \
             in two camera cam0 images: rig/sync036_cam0.jpg, rig/sync037_cam0.jpg (group by \
             number or last (the last number in the name, the default), first (the first \
             number), order (the position in each camera's list), or a pattern with one (\\d+) \
             such as sync(\\d+))"
        );
        assert_eq!(
            frame_keys(&cam0, &rule("first"), "cam0").unwrap(),
            ["36", "37", "100"]
        );
        assert_eq!(
            frame_keys(&cam1, &rule("last"), "cam1").unwrap(),
            ["36", "37", "100"]
        );
        let sync = rule("sync(\\d+)");
        assert_eq!(
            frame_keys(&cam0, &sync, "cam0").unwrap(),
            ["36", "37", "100"]
        );
        assert_eq!(
            frame_keys(&cam1, &sync, "cam1").unwrap(),
            ["36", "37", "100"]
        );
        assert_eq!(
            frame_keys(&left, &rule("first"), "left").unwrap(),
            ["1", "2"]
        );
        assert_eq!(
            frame_keys(&left, &rule("last"), "left").unwrap(),
            ["12", "13"]
        );
        assert_eq!(
            frame_keys(&left, &rule("left_(\\d+).png"), "left").unwrap(),
            ["12", "13"]
        );
        // Text after the digits must follow them; the first place that fits counts.
        assert_eq!(
            rule("_(\\d+)_").key("0001_left_12_x_7_.png"),
            Some("12".into())
        );
        assert_eq!(rule("(\\d+)").key("a/b0042c9.png"), Some("42".into()));
        assert_eq!(
            frame_keys(&["sync1_a.png", "b2.png"], &sync, "top")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the number of the pattern sync(\\d+) in the file \
             names, but camera top has names without one: b2.png (group by number or last (the \
             last number in the name, the default), first (the first number), order (the \
             position in each camera's list), or a pattern with one (\\d+) such as sync(\\d+))"
        );
        assert_eq!(rule("sync(\\d+)").rule(), "sync(\\d+)");
    }

    #[test]
    fn a_rule_that_is_neither_a_name_nor_a_pattern_lists_the_rules() {
        let err = |r: &str| FrameGrouping::from_rule(r).unwrap_err().to_string();
        let rules = "group_by: takes number or last (the last number in the name, the default), \
                     first (the first number), order (the position in each camera's list), or a \
                     pattern with one (\\d+) such as sync(\\d+)";
        assert_eq!(
            err("numbers"),
            format!("{rules}; got 'numbers': not a rule name, and no (\\d+) in it")
        );
        assert_eq!(
            err("a(\\d+)b(\\d+)"),
            format!("{rules}; got 'a(\\d+)b(\\d+)': a pattern has one (\\d+)")
        );
        assert_eq!(
            err("sync_(\\d+).*"),
            format!("{rules}; got 'sync_(\\d+).*': '*' is not literal text: besides its (\\d+), a pattern is plain text (no other regular-expression syntax, no folders)")
        );
    }

    #[test]
    fn pairs_by_number_whatever_the_order() {
        let left = ["l/left10.png", "l/left2.png", "l/left1.png"];
        let right = ["r/right01.png", "r/right02.png", "r/right10.png"];
        let p = pair_by_number(&left, &right).unwrap();
        assert_eq!(p.paired_by, PairedBy::Number);
        assert_eq!(p.pairs, vec![(0, 2), (1, 1), (2, 0)]);
    }

    #[test]
    fn names_without_numbers_pair_by_order_and_say_so() {
        let p = pair_by_number(&["a.png", "b.png"], &["c.png", "d.png"]).unwrap();
        assert_eq!(p.paired_by, PairedBy::Order);
        assert_eq!(p.pairs, vec![(0, 0), (1, 1)]);
        let e = pair_by_number(&["a.png", "b.png"], &["c.png"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "images: images are paired by order: 2 left but 1 right"
        );
        assert_eq!(pair_by_number(&[], &[]).unwrap().pairs, vec![]);
    }

    #[test]
    fn errors_name_the_files() {
        let e = pair_by_number(&["left1.png", "left2.png"], &["right1.png", "right3.png"])
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with("no partner for: left2.png (left, number 2), right3.png (right, number 3)"),
            "{e}"
        );
        let e = pair_by_number(&["left1.png"], &["right1.png", "blank.png"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("this name has no number: blank.png"), "{e}");
        let e = pair_by_number(&["a/left1.png", "b/left01.png"], &["right1.png"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("number 1 is in two left images: a/left1.png, b/left01.png"),
            "{e}"
        );
    }
}
