//! Pairing robot poses with images by the names a pose file gives them.
//!
//! # The rule
//!
//! When any pose names an image (the pose file's `image`/`name` column),
//! every pose must, and each name must match exactly one of the images
//! given. A name matches an image, best first:
//! 1. the same path (`\` read as `/`, a leading `./` dropped);
//! 2. one path ends with the other at a folder boundary
//!    (`images/0.png` matches `/home/me/cell/images/0.png` and the other
//!    way round);
//! 3. the same file name (`0.png`);
//! 4. the same file stem (`0` matches `0.png`, `pose_0.json`'s `0`).
//!
//! The best level with a match decides; two images at that level make the
//! name ambiguous. A name that matches no image, an ambiguous name, or two
//! poses naming one image is an error that names the rows. Images no pose
//! names are left out (the caller says so).
//!
//! When no pose names an image, pose `i` pairs with the `i`-th image in
//! **numeric order** of the file names ([`natural_cmp`]: `img2.png` before
//! `img10.png`, whatever order the shell listed them in); the counts must be
//! equal.
//!
//! Either way the pairing is then proven against the data: the hand-eye
//! checks compare it with [`alternatives`] (lexicographic order, the order
//! given, numeric order) through the rotation angles of the motions
//! ([`crate::handeye::quality::pairing`]).

use crate::error::{Error, Result};
use crate::handeye::quality::pairing::PairingRule;
use std::cmp::Ordering;

/// How [`pair_poses`] paired the poses with the images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PosesPairedBy {
    /// By the image names in the pose file.
    Name,
    /// Pose `i` with the `i`-th image in numeric order of the file names.
    NumericOrder,
}

impl PosesPairedBy {
    /// How the pairing is said in messages.
    pub fn describe(self) -> &'static str {
        match self {
            PosesPairedBy::Name => "by the image names in the pose file",
            PosesPairedBy::NumericOrder => "in numeric order of the file names",
        }
    }
}

/// The result of [`pair_poses`].
#[derive(Debug, Clone, PartialEq)]
pub struct PosePairing {
    /// Which rule applied.
    pub paired_by: PosesPairedBy,
    /// For each pose, the index of its image in the given list.
    pub image_of_pose: Vec<usize>,
    /// Images that no pose names (indices into the given list).
    pub unnamed_images: Vec<usize>,
}

/// A path as compared: `/` separators, no leading `./`.
fn normalized(path: &str) -> String {
    let p = path.trim().replace('\\', "/");
    let mut s = p.as_str();
    while let Some(rest) = s.strip_prefix("./") {
        s = rest;
    }
    s.to_string()
}

fn file_name(path: &str) -> &str {
    path.rsplit('/').next().unwrap_or(path)
}

fn stem(path: &str) -> &str {
    let name = file_name(path);
    match name.rfind('.') {
        Some(dot) if dot > 0 => &name[..dot],
        _ => name,
    }
}

/// `long` ends with `short` at a folder boundary.
fn ends_with_path(long: &str, short: &str) -> bool {
    long.len() > short.len()
        && long.ends_with(short)
        && long.as_bytes()[long.len() - short.len() - 1] == b'/'
}

/// How well `name` matches `image` (lower is better), or `None`.
fn match_level(name: &str, image: &str) -> Option<u8> {
    if name == image {
        Some(1)
    } else if ends_with_path(image, name) || ends_with_path(name, image) {
        Some(2)
    } else if file_name(name) == file_name(image) {
        Some(3)
    } else if stem(name) == stem(image) || file_name(name) == stem(image) {
        Some(4)
    } else {
        None
    }
}

/// Numeric-aware comparison of file names: runs of digits compare as
/// numbers (`img2` < `img10`), the rest byte by byte; whole paths break ties.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    fn chunks(s: &str) -> Vec<(bool, &str)> {
        let mut out = Vec::new();
        let mut start = 0;
        let bytes = s.as_bytes();
        for i in 1..=bytes.len() {
            if i == bytes.len() || bytes[i].is_ascii_digit() != bytes[start].is_ascii_digit() {
                out.push((bytes[start].is_ascii_digit(), &s[start..i]));
                start = i;
            }
        }
        out
    }
    let (na, nb) = (normalized(a), normalized(b));
    let (ca, cb) = (chunks(file_name(&na)), chunks(file_name(&nb)));
    for (x, y) in ca.iter().zip(&cb) {
        let ord = match (x, y) {
            ((true, dx), (true, dy)) => {
                let (tx, ty) = (dx.trim_start_matches('0'), dy.trim_start_matches('0'));
                tx.len()
                    .cmp(&ty.len())
                    .then_with(|| tx.cmp(ty))
                    .then_with(|| dx.len().cmp(&dy.len()))
            }
            ((_, sx), (_, sy)) => sx.cmp(sy),
        };
        if ord != Ordering::Equal {
            return ord;
        }
    }
    ca.len().cmp(&cb.len()).then_with(|| na.cmp(&nb))
}

/// The image indices in numeric order of their file names.
pub fn numeric_order(images: &[&str]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..images.len()).collect();
    order.sort_by(|&a, &b| natural_cmp(images[a], images[b]));
    order
}

/// At most five items of a list for a message, then "and N more".
fn listed(items: &[String]) -> String {
    let shown = items.iter().take(5).cloned().collect::<Vec<_>>().join(", ");
    if items.len() > 5 {
        format!("{shown} and {} more", items.len() - 5)
    } else {
        shown
    }
}

/// Pair poses with images by the rule of the module docs. `pose_names[i]`
/// is pose `i`'s image name (if the file gives one), `pose_rows[i]` its
/// line or element number for messages.
pub fn pair_poses(
    pose_names: &[Option<&str>],
    pose_rows: &[usize],
    images: &[&str],
) -> Result<PosePairing> {
    let row = |i: usize| pose_rows.get(i).copied().unwrap_or(i + 1);
    if pose_names.iter().all(Option::is_none) {
        if pose_names.len() != images.len() {
            return Err(Error::invalid(
                "pairing",
                format!(
                    "{} robot poses but {} images: give one image per pose (paired in numeric \
                     order of the file names), or add an image column to the pose file",
                    pose_names.len(),
                    images.len()
                ),
            ));
        }
        return Ok(PosePairing {
            paired_by: PosesPairedBy::NumericOrder,
            image_of_pose: numeric_order(images),
            unnamed_images: Vec::new(),
        });
    }
    let unnamed: Vec<String> = (0..pose_names.len())
        .filter(|&i| pose_names[i].is_none())
        .map(|i| format!("row {}", row(i)))
        .collect();
    if !unnamed.is_empty() {
        return Err(Error::invalid(
            "pairing",
            format!(
                "the pose file names images for some poses but not for {}: name an image on \
                 every row, or on none to pair by order",
                listed(&unnamed)
            ),
        ));
    }
    let paths: Vec<String> = images.iter().map(|p| normalized(p)).collect();
    let mut image_of_pose = Vec::with_capacity(pose_names.len());
    let (mut missing, mut ambiguous) = (Vec::new(), Vec::new());
    for (i, name) in pose_names.iter().enumerate() {
        let name = normalized(name.unwrap_or_default());
        let levels: Vec<Option<u8>> = paths.iter().map(|p| match_level(&name, p)).collect();
        let Some(best) = levels.iter().flatten().min().copied() else {
            missing.push(format!("row {} '{name}'", row(i)));
            image_of_pose.push(usize::MAX);
            continue;
        };
        let at_best: Vec<usize> = (0..paths.len())
            .filter(|&k| levels[k] == Some(best))
            .collect();
        if at_best.len() > 1 {
            ambiguous.push(format!(
                "row {} '{name}' matches {}",
                row(i),
                at_best
                    .iter()
                    .take(3)
                    .map(|&k| format!("'{}'", images[k]))
                    .collect::<Vec<_>>()
                    .join(" and ")
            ));
        }
        image_of_pose.push(at_best[0]);
    }
    if !missing.is_empty() {
        return Err(Error::invalid(
            "pairing",
            format!(
                "{} of {} poses name no image that was given: {}: give those images, or remove \
                 their rows from the pose file",
                missing.len(),
                pose_names.len(),
                listed(&missing)
            ),
        ));
    }
    if !ambiguous.is_empty() {
        return Err(Error::invalid(
            "pairing",
            format!(
                "image names in the pose file match more than one image: {}: name the images by \
                 a longer path",
                listed(&ambiguous)
            ),
        ));
    }
    let mut twice = Vec::new();
    for (k, image) in images.iter().enumerate() {
        let rows: Vec<String> = (0..image_of_pose.len())
            .filter(|&i| image_of_pose[i] == k)
            .map(|i| row(i).to_string())
            .collect();
        if rows.len() > 1 {
            twice.push(format!("rows {} all name '{}'", rows.join(", "), image));
        }
    }
    if !twice.is_empty() {
        return Err(Error::invalid(
            "pairing",
            format!(
                "two poses name the same image: {}: each image pairs with one robot pose; fix \
                 the image column",
                listed(&twice)
            ),
        ));
    }
    let unnamed_images = (0..images.len())
        .filter(|k| !image_of_pose.contains(k))
        .collect();
    Ok(PosePairing {
        paired_by: PosesPairedBy::Name,
        image_of_pose,
        unnamed_images,
    })
}

/// The other simple ways these poses could pair with these images, as
/// `(pose index, image index)` rules: pose `i` with the `i`-th image in
/// numeric order, in lexicographic order, and in the order given. Rules
/// equal to `given` or to each other are left out. Only for as many poses
/// as images.
pub fn alternatives(n_poses: usize, images: &[&str], given: &[(usize, usize)]) -> Vec<PairingRule> {
    if n_poses != images.len() {
        return Vec::new();
    }
    let mut lexicographic: Vec<usize> = (0..images.len()).collect();
    lexicographic.sort_by(|&a, &b| images[a].cmp(images[b]));
    let candidates = [
        (
            "robot pose i with the i-th image in numeric order of the file names",
            "the poses fit the images only when paired in numeric order of the file names",
            "pass --pair-by numeric",
            numeric_order(images),
        ),
        (
            "robot pose i with the i-th image in lexicographic order of the file names (as a \
             shell lists them: 0, 1, 10, 11, ..., 2)",
            "the poses fit the images only when paired in lexicographic order of the file names",
            "pass --pair-by lexicographic",
            lexicographic,
        ),
        (
            "robot pose i with the i-th image as given",
            "the poses fit the images only when paired in the order the images were given",
            "pass --pair-by given",
            (0..images.len()).collect(),
        ),
    ];
    let mut rules: Vec<PairingRule> = Vec::new();
    for (name, finding, fix, order) in candidates {
        let pairs: Vec<(usize, usize)> = order.into_iter().enumerate().collect();
        if pairs != given && !rules.iter().any(|r| r.pairs == pairs) {
            rules.push(PairingRule {
                name: name.to_string(),
                finding: finding.to_string(),
                fix: fix.to_string(),
                pairs,
            });
        }
    }
    rules
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn names(v: &[&'static str]) -> Vec<Option<&'static str>> {
        v.iter().map(|s| Some(*s)).collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn names_match_by_path_suffix_file_name_and_stem() {
        let images = [
            "/home/me/cell/images/0.png",
            "/home/me/cell/images/1.png",
            "/home/me/cell/images/10.png",
            "/home/me/cell/images/2.png",
        ];
        let rows = [2, 3, 4, 5];
        for pose_names in [
            names(&[
                "images/0.png",
                "images/1.png",
                "images/2.png",
                "images/10.png",
            ]),
            names(&["./images/0.png", "images\\1.png", "2.png", "10"]),
            names(&[
                "/data/robot/run3/images/0.png",
                "/home/me/cell/images/1.png",
                "2",
                "10.png",
            ]),
        ] {
            let p = pair_poses(&pose_names, &rows, &images).unwrap();
            assert_eq!(p.paired_by, PosesPairedBy::Name);
            assert_eq!(p.image_of_pose, vec![0, 1, 3, 2], "{pose_names:?}");
            assert!(p.unnamed_images.is_empty());
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn nameless_poses_pair_in_numeric_order() {
        let images = [
            "a/0.png", "a/1.png", "a/10.png", "a/11.png", "a/2.png", "a/3.png",
        ];
        let p = pair_poses(&[None; 6], &[1, 2, 3, 4, 5, 6], &images).unwrap();
        assert_eq!(p.paired_by, PosesPairedBy::NumericOrder);
        assert_eq!(p.image_of_pose, vec![0, 1, 4, 5, 2, 3]);
        assert_eq!(
            pair_poses(&[None; 5], &[1, 2, 3, 4, 5], &images)
                .unwrap_err()
                .to_string(),
            "pairing: 5 robot poses but 6 images: give one image per pose (paired in numeric \
             order of the file names), or add an image column to the pose file"
        );
        assert_eq!(natural_cmp("img007.png", "img7.png"), Ordering::Greater);
        assert_eq!(natural_cmp("img7.png", "img10.png"), Ordering::Less);
        assert_eq!(natural_cmp("b/img1.png", "a/img2.png"), Ordering::Less);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn missing_twice_and_partly_named_rows_are_errors_naming_them() {
        let images = ["x/0.png", "x/1.png", "x/2.png"];
        let rows = [2, 3, 4];
        assert_eq!(
            pair_poses(&names(&["0.png", "1.png", "7.png"]), &rows, &images)
                .unwrap_err()
                .to_string(),
            "pairing: 1 of 3 poses name no image that was given: row 4 '7.png': give those \
             images, or remove their rows from the pose file"
        );
        assert_eq!(
            pair_poses(&names(&["0.png", "1.png", "x/1.png"]), &rows, &images)
                .unwrap_err()
                .to_string(),
            "pairing: two poses name the same image: rows 3, 4 all name 'x/1.png': each image \
             pairs with one robot pose; fix the image column"
        );
        assert_eq!(
            pair_poses(&[Some("0.png"), None, Some("2.png")], &rows, &images)
                .unwrap_err()
                .to_string(),
            "pairing: the pose file names images for some poses but not for row 3: name an \
             image on every row, or on none to pair by order"
        );
        assert_eq!(
            pair_poses(
                &names(&["0.png", "1.png"]),
                &rows,
                &["a/0.png", "b/0.png", "a/1.png"]
            )
            .unwrap_err()
            .to_string(),
            "pairing: image names in the pose file match more than one image: row 2 '0.png' \
             matches 'a/0.png' and 'b/0.png': name the images by a longer path"
        );
        // Fewer poses than images: the others are listed, not an error.
        let p = pair_poses(&names(&["2.png", "0.png"]), &[1, 2], &images).unwrap();
        assert_eq!(p.image_of_pose, vec![2, 0]);
        assert_eq!(p.unnamed_images, vec![1]);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn alternatives_leave_out_the_given_rule_and_repeats() {
        let images = ["0.png", "1.png", "10.png", "2.png"];
        let given: Vec<(usize, usize)> = vec![(0, 0), (1, 1), (2, 3), (3, 2)];
        let rules = alternatives(4, &images, &given);
        // Numeric is the given rule; lexicographic equals the order given.
        assert_eq!(rules.len(), 1);
        assert!(rules[0].name.contains("lexicographic"));
        assert_eq!(rules[0].pairs, vec![(0, 0), (1, 1), (2, 2), (3, 3)]);
        assert!(alternatives(3, &images, &given).is_empty());
    }
}
