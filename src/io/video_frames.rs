//! How a frame taken from a recording is named (issue 36, recordings): the
//! one rule the CLI (`robocal detect cam_0.mp4`, `robocal rig`) and the web
//! app (through the wasm function `video_frame_name`) both follow, so a
//! frame keeps its name between the two and in every report.

/// The name of frame `index` (0 first) of the recording `video`:
/// `cam_0.mp4#frame0123` (four digits at least, more past frame 9999).
/// `video` is kept as given (a path in the CLI, a file name on the page).
pub fn video_frame_name(video: &str, index: usize) -> String {
    format!("{video}#frame{index:04}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn frames_are_named_after_the_video_with_four_digits_at_least() {
        assert_eq!(video_frame_name("cam_0.mp4", 0), "cam_0.mp4#frame0000");
        assert_eq!(
            video_frame_name("v/cam_0.mp4", 123),
            "v/cam_0.mp4#frame0123"
        );
        assert_eq!(video_frame_name("a.webm", 12345), "a.webm#frame12345");
    }
}
