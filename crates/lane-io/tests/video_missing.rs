//! A video input without ffmpeg: a clear error naming the file and what to do. (Its own test
//! binary: it sets `ITA_NAV_FFMPEG` for the whole process.)
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_io::{LaneIoError, sources, video};

#[test]
fn a_missing_ffmpeg_is_a_clear_error_naming_the_file() {
    // SAFETY: this test binary has one test, so no other thread reads the environment.
    unsafe { std::env::set_var(video::FFMPEG_ENV, "/nonexistent/ffmpeg") };
    let path = std::env::temp_dir().join(format!("ita-nav-missing-{}.mp4", std::process::id()));
    std::fs::write(&path, b"whatever").unwrap();
    let e = sources::open_input(&path, 0.0).map(|_| ()).unwrap_err();
    let _ = std::fs::remove_file(&path);
    assert!(matches!(e, LaneIoError::FfmpegMissing { .. }), "{e}");
    let shown = e.to_string();
    assert!(shown.contains(&path.display().to_string()), "{shown}");
    assert!(shown.contains("install ffmpeg"), "{shown}");
}
