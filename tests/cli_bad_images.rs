//! Strange image files through the real binary: each is answered with exit
//! code 1 and a message naming the format and the defect, never a crash
//! (exit 101) or an abort.

mod support;
use support::{robocal, temp_dir};

/// The 28-byte JPEG that crashed the old hand-written decoder (a DHT
/// segment whose code counts overrun its table).
fn jpeg_28_bytes() -> Vec<u8> {
    let mut b = vec![0xFF, 0xD8, 0xFF, 0xC4, 0x00, 0x16, 0x00, 0x02, 0x01];
    b.extend_from_slice(&[0; 14]);
    b.extend_from_slice(&[0x00, 0x01, 0x02, 0xFF, 0xD9]);
    b
}

/// A 200-byte TIFF of a 64 x 64 image whose tiles claim 2^30 x 2^30 pixels
/// (the old reader allocated from the tile size).
fn tiff_huge_tiles() -> Vec<u8> {
    let entries: [(u16, u16, u32); 10] = [
        (256, 3, 64),
        (257, 3, 64),
        (258, 3, 8),
        (259, 3, 1),
        (262, 3, 1),
        (277, 3, 1),
        (322, 4, 1 << 30),
        (323, 4, 1 << 30),
        (324, 4, 8),
        (325, 4, 16),
    ];
    let mut out = b"II*\x00".to_vec();
    out.extend_from_slice(&8u32.to_le_bytes());
    out.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for (tag, kind, value) in entries {
        out.extend_from_slice(&tag.to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&1u32.to_le_bytes());
        out.extend_from_slice(&value.to_le_bytes());
    }
    out.extend_from_slice(&0u32.to_le_bytes());
    out.resize(200, 0);
    out
}

#[test]
fn info_names_the_format_and_the_defect() {
    let dir = temp_dir("bad-images", "info");
    let jpeg = dir.join("bad28.jpg");
    std::fs::write(&jpeg, jpeg_28_bytes()).unwrap();
    let (code, out, err) = robocal(&["info", jpeg.to_str().unwrap()]);
    assert_eq!(code, 1, "stdout {out} stderr {err}");
    assert!(
        out.contains("corrupt or truncated JPEG file: Format error decoding Jpeg: Error decoding huffman values: Bad Huffman Table"),
        "{out}"
    );
    assert!(err.contains("1 of 1 files could not be decoded"), "{err}");

    let tiff = dir.join("tiles.tif");
    std::fs::write(&tiff, tiff_huge_tiles()).unwrap();
    let (code, out, err) = robocal(&["info", tiff.to_str().unwrap()]);
    assert_eq!(code, 1, "stdout {out} stderr {err}");
    assert!(out.contains("corrupt or truncated TIFF file"), "{out}");
}

#[test]
fn detect_reports_the_bad_file_and_keeps_going() {
    let dir = temp_dir("bad-images", "detect");
    let jpeg = dir.join("bad28.jpg");
    std::fs::write(&jpeg, jpeg_28_bytes()).unwrap();
    let out_json = dir.join("detections.json");
    let (code, out, err) = robocal(&[
        "detect",
        "--target",
        "chessboard:9x6:30mm",
        jpeg.to_str().unwrap(),
        "-o",
        out_json.to_str().unwrap(),
    ]);
    assert_ne!(code, 101, "crashed: {err}");
    assert!(!err.contains("crashed"), "{err}");
    let text = std::fs::read_to_string(&out_json).unwrap_or_default() + &out + &err;
    assert!(text.contains("corrupt or truncated JPEG file"), "{text}");
}

#[test]
fn max_pixels_lowers_and_raises_the_size_limit() {
    let dir = temp_dir("bad-images", "max-pixels");
    let png = dir.join("board.png");
    let image = robocal::image::GrayImage::new(400, 300, vec![128; 400 * 300]).unwrap();
    std::fs::write(&png, robocal::image::encode_png(&image).unwrap()).unwrap();
    let file = png.to_str().unwrap();
    let (code, out, err) = robocal(&["info", "--max-pixels", "100000", file]);
    assert_eq!(code, 1, "stdout {out} stderr {err}");
    assert!(
        out.contains("image is 400x300 = 120000 pixels, more than the limit of 100000 pixels: downscale it first, or raise the limit (--max-pixels in the CLI, \\\"max_pixels\\\" in the JSON options)"),
        "{out}"
    );
    let (code, out, _) = robocal(&["info", "--max-pixels", "1MP", file]);
    assert_eq!(code, 0);
    assert!(out.contains("\"height\":300,\"width\":400"), "{out}");
    // detect carries the limit to every image it decodes.
    let (code, out, _) = robocal(&[
        "detect",
        "--target",
        "chessboard:9x6:30mm",
        "--max-pixels",
        "1000",
        file,
    ]);
    assert_eq!(code, 1);
    assert!(out.contains("more than the limit of 1000 pixels"), "{out}");
    let (code, _, err) = robocal(&["info", "--max-pixels", "lots", file]);
    assert_eq!(code, 2);
    assert!(
        err.starts_with("error: invalid value 'lots' for '--max-pixels <N>': 'lots' is not a pixel count: give a whole number > 0, e.g. 150000000 or 150MP"),
        "{err}"
    );
}
