//! `robocal render` and `robocal detect` with the print options (issue 36):
//! a light-on-dark ChArUco rendered by `--target SPEC:light-on-dark` is
//! found without an option (each detection says "polarity":
//! "light_on_dark"); forcing the usual print names the option; the printable
//! sheet refuses a print it cannot draw.

use crate::support;

use support::{robocal, temp_dir};

const SPEC: &str = "charuco:5x7:30mm:22mm:DICT_4X4_50";

#[test]
fn an_inverted_render_is_found_without_an_option_and_a_forced_print_names_the_other() {
    let dir = temp_dir("polarity", "cli");
    let out = dir.to_str().unwrap();
    let (code, _, err) = robocal(&[
        "render",
        "--out",
        out,
        "--views",
        "2",
        "--seed",
        "3",
        "--target",
        &format!("{SPEC}:light-on-dark"),
    ]);
    assert_eq!(code, 0, "{err}");
    let image = dir.join("view_001.png");
    let image = image.to_str().unwrap();
    let (code, json, err) = robocal(&["detect", "--target", SPEC, image]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    let detection = &doc["images"][0]["detection"];
    assert_eq!(detection["polarity"], "light_on_dark", "{json}");
    assert_eq!(
        detection["points"].as_array().map(Vec::len),
        Some(24),
        "{json}"
    );
    let (code, _, err) = robocal(&[
        "detect",
        "--target",
        &format!("{SPEC}:light-on-dark"),
        image,
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, json, err) = robocal(&[
        "detect",
        "--target",
        &format!("{SPEC}:dark-on-light"),
        image,
    ]);
    assert_eq!(code, 1, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        doc["images"][0]["error"]["message"],
        "no DICT_4X4_50 markers found: is the board in view, sharp and lit, and the dictionary right?; \
         printed light-on-dark the board is in view: the target spec forces ':dark-on-light', \
         write ':light-on-dark' or leave the option out to find either print \
         (charuco:5x7:30mm:22mm:DICT_4X4_50)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_sheet_of_a_light_on_dark_spec_is_refused_where_it_cannot_be_drawn() {
    let (code, _, err) = robocal(&["target", &format!("{SPEC}:light-on-dark"), "--svg", "-"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the printable sheet of charuco:5x7:30mm:22mm:DICT_4X4_50 is drawn dark on light only; ':light-on-dark' is a detection option for it"),
        "{err}"
    );
    let (code, svg, err) = robocal(&["target", "circles:4x5:20mm:light-on-dark", "--svg", "-"]);
    assert_eq!(code, 0, "{err}");
    assert!(svg.contains("light on dark"), "{svg}");
}

#[test]
fn intrinsics_from_images_finds_either_print_and_keeps_a_forced_one() {
    let dir = temp_dir("polarity", "intrinsics");
    let out = dir.to_str().unwrap();
    let spec = "charuco:5x7:30mm:22mm:DICT_4X4_50";
    let (code, _, err) = robocal(&[
        "render",
        "--out",
        out,
        "--views",
        "4",
        "--seed",
        "11",
        "--target",
        &format!("{spec}:light-on-dark"),
    ]);
    assert_eq!(code, 0, "{err}");
    let images: Vec<String> = (1..=4)
        .map(|k| {
            dir.join(format!("view_{k:03}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let mut args = vec!["intrinsics", "--target", spec];
    args.extend(images.iter().map(String::as_str));
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 0, "{err}");
    let forced = format!("{spec}:dark-on-light");
    args[2] = &forced;
    let (code, _, err) = robocal(&args);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(
            "printed light-on-dark the board is in view: the target spec forces ':dark-on-light'"
        ),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
