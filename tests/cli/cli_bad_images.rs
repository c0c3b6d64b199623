//! Strange image files through the real binary: each is answered with exit
//! code 1 and a message naming the format and the defect, never a crash
//! (exit 101) or an abort.

use crate::support;
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
    // Its tiles lie beyond the end of the file.
    assert!(
        out.contains("the TIFF file is truncated: it ends after 200 bytes"),
        "{out}"
    );
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

/// A 320 x 240 grey ramp, as JPEG (quality 90) and as PNG.
fn ramp_files() -> [(&'static str, &'static str, Vec<u8>); 2] {
    let (w, h) = (320u32, 240u32);
    let pixels: Vec<u8> = (0..w * h)
        .map(|i| ((i % w) * 3 + (i / w) * 5) as u8)
        .collect();
    let mut jpeg = Vec::new();
    jpeg_encoder::Encoder::new(&mut jpeg, 90)
        .encode(&pixels, w as u16, h as u16, jpeg_encoder::ColorType::Luma)
        .unwrap();
    let image = robocal::image::GrayImage::new(w, h, pixels).unwrap();
    let png = robocal::image::encode_png(&image).unwrap();
    [("JPEG", "jpg", jpeg), ("PNG", "png", png)]
}

fn truncated(format: &str, n: usize) -> String {
    format!(
        "the {format} file is truncated: it ends after {n} bytes, before the end of its image \
         data (an interrupted copy or download?): copy it again from the camera or its source"
    )
}

#[test]
fn files_cut_at_10_50_and_90_percent_are_named_truncated() {
    let dir = temp_dir("bad-images", "truncated");
    for (format, ext, bytes) in ramp_files() {
        for percent in [10, 50, 90] {
            let n = bytes.len() * percent / 100;
            let path = dir.join(format!("cut{percent}.{ext}"));
            std::fs::write(&path, &bytes[..n]).unwrap();
            let file = path.to_str().unwrap();
            let message = truncated(format, n);
            let (code, out, _) = robocal(&["info", file]);
            assert_eq!(code, 1, "{format} {percent} %");
            let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
            assert_eq!(
                line["error"],
                message.as_str(),
                "info, {format} {percent} %"
            );
            let (code, _, err) = robocal(&["detect", "--target", "chessboard:9x6:30mm", file]);
            assert_eq!(code, 1, "{format} {percent} %");
            assert_eq!(
                err.lines().next(),
                Some(format!("robocal detect: {file}: {message}").as_str()),
                "detect, {format} {percent} %"
            );
        }
    }
}

#[test]
fn only_regular_files_are_read() {
    let (code, out, _) = robocal(&["info", "/dev/zero"]);
    assert_eq!(code, 1);
    assert_eq!(
        out.trim(),
        r#"{"error":"'/dev/zero' is not a regular file (a character device): give an image file","file":"/dev/zero"}"#
    );
    let dir = temp_dir("bad-images", "fifo");
    let fifo = dir.join("camera.png");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        // No writer: reading would block for ever.
        let file = fifo.to_str().unwrap();
        let (code, _, err) = robocal(&["detect", "--target", "chessboard:9x6:30mm", file]);
        assert_eq!(code, 1);
        assert_eq!(
            err.lines().next(),
            Some(
                format!(
                    "robocal detect: {file}: '{file}' is not a regular file (a FIFO): give an image file"
                )
                .as_str()
            )
        );
    }
}

#[test]
fn large_files_are_judged_before_they_are_read() {
    let dir = temp_dir("bad-images", "large");
    // 3 GB of zeros named .png (a sparse file: no disk used): refused from
    // its first bytes.
    let junk = dir.join("junk.png");
    std::fs::File::create(&junk)
        .unwrap()
        .set_len(3_000_000_000)
        .unwrap();
    let (code, out, _) = robocal(&["info", junk.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(
        out.contains(r#""error":"not an image: the bytes match none of PNG, JPEG, TIFF, BMP, PGM/PPM, GIF, WebP""#),
        "{out}"
    );
    // A PNG signature followed by 1 GiB: over the cap, refused unread.
    let big = dir.join("big.png");
    {
        use std::io::Write;
        let mut f = std::fs::File::create(&big).unwrap();
        f.write_all(b"\x89PNG\r\n\x1a\n").unwrap();
        f.set_len((1 << 30) + 1).unwrap();
    }
    let file = big.to_str().unwrap();
    let (code, out, _) = robocal(&["info", file]);
    assert_eq!(code, 1);
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(
        line["error"],
        format!(
            "'{file}' is 1073741825 bytes, more than any image the decoder accepts (at most \
             1073741824 bytes, its memory limit): downscale or compress the image, or raise the \
             limit with --max-pixels (10 bytes a pixel)"
        )
    );
    let _ = std::fs::remove_file(&junk);
    let _ = std::fs::remove_file(&big);
}

#[test]
fn an_iccp_profile_that_inflates_to_gigabytes_is_not_inflated() {
    // 1.25 GiB of zeros as the colour profile of a 64 x 48 PNG.
    let mut data = b"bomb\0\0".to_vec();
    let mut z = fdeflate::Compressor::new(Vec::new()).unwrap();
    let block = vec![0u8; 1 << 20];
    for _ in 0..1280 {
        z.write_data(&block).unwrap();
    }
    data.extend_from_slice(&z.finish().unwrap());
    let mut chunk = (data.len() as u32).to_be_bytes().to_vec();
    chunk.extend_from_slice(b"iCCP");
    chunk.extend_from_slice(&data);
    let mut crc = crc32fast::Hasher::new();
    crc.update(b"iCCP");
    crc.update(&data);
    chunk.extend_from_slice(&crc.finalize().to_be_bytes());
    let image = robocal::image::GrayImage::new(64, 48, vec![90; 64 * 48]).unwrap();
    let png = robocal::image::encode_png(&image).unwrap();
    let bomb = [&png[..33], &chunk, &png[33..]].concat();
    let dir = temp_dir("bad-images", "iccp");
    let path = dir.join("profile.png");
    std::fs::write(&path, bomb).unwrap();
    let (code, out, err) = robocal(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{out} {err}");
    assert!(out.contains(r#""format":"png","height":48"#), "{out}");
}

#[test]
fn the_exif_orientation_is_reported_by_info_and_detect() {
    let (w, h) = (64u16, 48u16);
    let mut jpeg = Vec::new();
    let mut enc = jpeg_encoder::Encoder::new(&mut jpeg, 90);
    // Orientation 6 (rotate 90 degrees clockwise to display).
    enc.add_exif_metadata(
        b"II*\x00\x08\x00\x00\x00\x01\x00\x12\x01\x03\x00\x01\x00\x00\x00\x06\x00\x00\x00\x00\x00\x00\x00",
    )
    .unwrap();
    enc.encode(
        &vec![128u8; w as usize * h as usize],
        w,
        h,
        jpeg_encoder::ColorType::Luma,
    )
    .unwrap();
    let dir = temp_dir("bad-images", "exif");
    let path = dir.join("portrait.jpg");
    std::fs::write(&path, jpeg).unwrap();
    let file = path.to_str().unwrap();
    let (code, out, _) = robocal(&["info", file]);
    assert_eq!(code, 0);
    let line: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(
        (line["width"].as_u64(), line["height"].as_u64()),
        (Some(48), Some(64))
    );
    assert_eq!(line["exif_orientation"], 6);
    let (_, out, _) = robocal(&["detect", "--target", "chessboard:9x6:30mm", file]);
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["images"][0]["exif_orientation"], 6, "{out}");
}
