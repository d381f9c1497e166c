//! Video files through ffmpeg: a lossless video decodes to exactly the frames it was made from,
//! an MP4 decodes with its frame rate, a file ffmpeg cannot decode is an error naming it, and the
//! child is reaped when the source is dropped early. Needs `ffmpeg` (the test command installs
//! it); outside CI a missing ffmpeg skips with a message.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};
use std::process::Command;

use lane_io::y4m::{Y4mChroma, Y4mWriter};
use lane_io::{FrameSource, GreyFrame, LaneIoError, sources, video};

fn have_ffmpeg() -> bool {
    let ok = Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "ffmpeg is missing under CI (cargo xtask test installs it)"
        );
        eprintln!("SKIPPED: ffmpeg is not installed");
    }
    ok
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ita-nav-video-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Ten 64×48 grey frames with a moving pattern, as y4m at 25 frames/s.
fn frames() -> Vec<Vec<u8>> {
    (0..10)
        .map(|k| {
            (0..64 * 48)
                .map(|i| {
                    let (x, y) = (i % 64, i / 64);
                    (((x + 3 * k) * 7 + y * 3) % 256) as u8
                })
                .collect()
        })
        .collect()
}

fn write_y4m(dir: &Path) -> PathBuf {
    let path = dir.join("in.y4m");
    let mut w = Y4mWriter::new(
        std::fs::File::create(&path).unwrap(),
        64,
        48,
        25.0,
        Y4mChroma::Mono,
    )
    .unwrap();
    for f in frames() {
        w.write_grey(&f).unwrap();
    }
    w.finish().unwrap();
    path
}

fn ffmpeg(args: &[&str]) {
    let out = Command::new("ffmpeg")
        .args(["-hide_banner", "-v", "error", "-y"])
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read_all(path: &Path) -> (Vec<Vec<u8>>, Vec<f64>, Option<f64>) {
    let mut src = sources::open_input(path, 0.0).unwrap();
    let rate = src.frame_rate_hz();
    let mut frame = GreyFrame::default();
    let (mut out, mut times) = (Vec::new(), Vec::new());
    while let Some(meta) = src.next_frame(&mut frame).unwrap() {
        out.push(frame.data().to_vec());
        times.push(meta.t_s);
    }
    (out, times, rate)
}

#[test]
fn a_lossless_video_decodes_to_the_frames_it_was_made_from() {
    if !have_ffmpeg() {
        return;
    }
    let dir = temp("lossless");
    let y4m = write_y4m(&dir);
    let mkv = dir.join("clip.mkv");
    ffmpeg(&[
        "-i",
        y4m.to_str().unwrap(),
        "-c:v",
        "ffv1",
        "-pix_fmt",
        "gray",
        mkv.to_str().unwrap(),
    ]);
    assert!(video::is_video(&mkv));
    let (got, times, rate) = read_all(&mkv);
    assert_eq!(got, frames());
    assert_eq!(rate, Some(25.0));
    assert_eq!(times[3], 3.0 / 25.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_mp4_decodes_with_its_frame_rate() {
    if !have_ffmpeg() {
        return;
    }
    let dir = temp("mp4");
    let y4m = write_y4m(&dir);
    let mp4 = dir.join("clip.MP4");
    ffmpeg(&[
        "-i",
        y4m.to_str().unwrap(),
        "-c:v",
        "mpeg4",
        "-q:v",
        "2",
        "-pix_fmt",
        "yuv420p",
        mp4.to_str().unwrap(),
    ]);
    let (got, _, rate) = read_all(&mp4);
    assert_eq!(got.len(), 10);
    assert_eq!(rate, Some(25.0));
    // Lossy, but close to the original.
    let err: f64 = got[5]
        .iter()
        .zip(&frames()[5])
        .map(|(a, b)| (f64::from(*a) - f64::from(*b)).abs())
        .sum::<f64>()
        / got[5].len() as f64;
    assert!(err < 12.0, "mean absolute error {err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_file_ffmpeg_cannot_decode_is_an_error_naming_it() {
    if !have_ffmpeg() {
        return;
    }
    let dir = temp("corrupt");
    let bad = dir.join("broken.mp4");
    std::fs::write(&bad, b"this is not a video at all").unwrap();
    let e = sources::open_input(&bad, 0.0).map(|_| ()).unwrap_err();
    assert!(matches!(e, LaneIoError::VideoDecode { .. }), "{e}");
    let shown = e.to_string();
    assert!(
        shown.contains("broken.mp4") && shown.contains("ffmpeg"),
        "{shown}"
    );
    // The reader's own finding is kept as the source: ffmpeg wrote no stream header.
    let LaneIoError::VideoDecode {
        source: Some(reader),
        ..
    } = &e
    else {
        panic!("no reader error kept as the source: {e:?}");
    };
    assert!(
        matches!(**reader, LaneIoError::Y4mHeader { .. }),
        "{reader}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_child_is_reaped_when_the_source_is_dropped_early() {
    if !have_ffmpeg() {
        return;
    }
    let dir = temp("reap");
    let y4m = write_y4m(&dir);
    let mkv = dir.join("clip.mkv");
    ffmpeg(&[
        "-i",
        y4m.to_str().unwrap(),
        "-c:v",
        "ffv1",
        "-pix_fmt",
        "gray",
        mkv.to_str().unwrap(),
    ]);
    let mut src = video::VideoSource::open(&mkv).unwrap();
    let pid = src.child_id();
    let mut frame = GreyFrame::default();
    assert!(src.next_frame(&mut frame).unwrap().is_some());
    assert!(Path::new(&format!("/proc/{pid}")).exists());
    drop(src); // as --max-frames 1 does
    // Killed and waited for: no process, not even a zombie, under that id.
    assert!(
        !Path::new(&format!("/proc/{pid}")).exists(),
        "ffmpeg {pid} was not reaped"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
