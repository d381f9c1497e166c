//! What the benches over the real udacity clip share: the clip decoded into memory.

use lane_io::FrameSource;
use lane_io::y4m::Y4mSource;
use lane_tracker::GreyFrame;

/// The clip's frames, or `None` (said on stderr, naming `bench`) when it is missing under the
/// data root (`lane_bench::data`).
pub fn udacity_clip(bench: &str) -> Option<Vec<GreyFrame>> {
    let path = match lane_bench::data::data_file(lane_bench::data::UDACITY_CLIP) {
        Ok(path) => path,
        Err(e) => {
            eprintln!("SKIPPED: the {bench} bench needs the real udacity clip: {e}");
            return None;
        }
    };
    let file = std::fs::File::open(&path).expect("the clip opens");
    let mut src = Y4mSource::new(std::io::BufReader::new(file), path.display().to_string())
        .expect("a y4m stream");
    let mut frames = Vec::new();
    let mut frame = GreyFrame::default();
    while src.next_frame(&mut frame).expect("a frame").is_some() {
        frames.push(frame.clone());
    }
    Some(frames)
}
