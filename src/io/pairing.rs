//! Pairing the images of two cameras (stereo left and right) by file name.
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

/// The default grouping of a rig's images (`robocal rig` without
/// `--group-by`, the web app's rig step): by number unless no file name has
/// one.
pub fn default_grouping<'a>(mut names: impl Iterator<Item = &'a str>) -> PairedBy {
    if names.any(|n| number_in_name(n).is_some()) {
        PairedBy::Number
    } else {
        PairedBy::Order
    }
}

/// The frame key of every image of one camera of a rig (`robocal rig`):
/// with [`PairedBy::Number`] the number in its name (every name must have
/// one, unique within the camera; keys compare across cameras, so
/// `front07.png` and `side7.jpg` are one frame), with [`PairedBy::Order`]
/// its position (`"0"`, `"1"`, ...). `camera` names the camera in errors.
pub fn frame_keys(names: &[&str], by: PairedBy, camera: &str) -> Result<Vec<String>> {
    if by == PairedBy::Order {
        return Ok((0..names.len()).map(|i| i.to_string()).collect());
    }
    let numbers: Vec<Option<String>> = names
        .iter()
        .map(|n| number_in_name(n).map(str::to_string))
        .collect();
    let without: Vec<&str> = names
        .iter()
        .zip(&numbers)
        .filter(|(_, n)| n.is_none())
        .map(|(name, _)| *name)
        .collect();
    if !without.is_empty() {
        return Err(Error::invalid(
            "images",
            format!(
                "frames are grouped by the last number in the file names, but camera {camera} \
                 has names without one: {} (number every file, or group by order)",
                without.join(", ")
            ),
        ));
    }
    index_by_number(names, &numbers, &format!("camera {camera}")).map_err(|e| match e {
        Error::Invalid { message, .. } => Error::invalid(
            "images",
            message.replace("images are paired", "frames are grouped"),
        ),
        other => other,
    })?;
    Ok(numbers.into_iter().flatten().collect())
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
            frame_keys(&names, PairedBy::Number, "front").unwrap(),
            ["7", "1"]
        );
        assert_eq!(
            frame_keys(&names, PairedBy::Order, "front").unwrap(),
            ["0", "1"]
        );
        assert_eq!(
            frame_keys(&["a1.png", "b.png"], PairedBy::Number, "top")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the last number in the file names, but camera top has \
             names without one: b.png (number every file, or group by order)"
        );
        assert_eq!(
            frame_keys(&["a1.png", "a01.png"], PairedBy::Number, "top")
                .unwrap_err()
                .to_string(),
            "images: frames are grouped by the last number in their file names, but number 1 is \
             in two camera top images: a1.png, a01.png"
        );
    }

    #[test]
    fn rigs_group_by_number_unless_no_name_has_one() {
        assert_eq!(
            default_grouping(["a.png", "cam/b7.png"].into_iter()),
            PairedBy::Number
        );
        assert_eq!(
            default_grouping(["a.png", "cam7/b.png"].into_iter()),
            PairedBy::Order
        );
        assert_eq!(default_grouping(std::iter::empty()), PairedBy::Order);
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
