//! The capture cases run in the guest: each a nav-app command line and what its output must show.

/// Common guest arguments: vivid's S-Video input, NTSC, 320×240.
pub(super) const BASE: &str =
    "--device /dev/video0 --input-name S-Video --std ntsc --size 320x240 --json";

/// nav-app's exit codes (see `crates/nav-app/src/bin/nav-app/lane.rs`).
pub(super) const EXIT_ERROR: i64 = 1;
pub(super) const EXIT_DEVICE_GONE: i64 = 3;
pub(super) const EXIT_TIMEOUTS: i64 = 4;

/// What a case requires of the guest's output.
#[derive(Clone, Copy)]
pub(super) enum Expect {
    /// `frames` frames of 320×240 in `fourcc`, strictly increasing timestamps, sequence numbers
    /// never going back (`judge::check_frames`: vivid may repeat one),
    /// NTSC-M set, exit 0. `optional`: a driver lacking the format skips instead of failing.
    Stream {
        fourcc: &'static str,
        frames: u64,
        optional: bool,
    },
    /// Exit 0 with `frames` frames and the given standard bits set.
    Std { mask: u64, frames: u64 },
    /// Exit 0 on input `index`.
    Input { index: u64 },
    /// A clean typed error mentioning `text`, exit 1.
    CleanError { text: &'static str },
    /// Injected `V4L2_BUF_FLAG_ERROR` buffers: errored_dropped ≥ 1, all frames delivered, exit 0.
    BufError { frames: u64 },
    /// Dropped buffers: sequence_gaps ≥ 1 equal to the sum of per-frame `missed`, exit 0.
    Dropped { frames: u64 },
    /// No signal: some frames flagged signal_lost, and the last ones not (restored), exit 0.
    NoSignal { frames: u64 },
    /// All buffers dropped → timeout → restart → frames again, exit 0.
    TimeoutRestart { frames: u64 },
    /// All buffers dropped and never restored → `timeouts` timeouts in a row → exit 4
    /// (`timeout`), at least `at_least` frames before, no panic.
    TimeoutLimit { at_least: u64, timeouts: u64 },
    /// Without `--json`: exit 0 and nav-app's stderr device line reporting `frames` frames,
    /// frames/s, errored and dropped frames.
    Human { frames: u64 },
    /// vivid Disconnect → device-gone, exit 3, fewer frames than asked, no panic.
    Disconnect { at_least: u64, max_frames: u64 },
}

pub(super) struct Case {
    pub(super) name: &'static str,
    pub(super) args: String,
    pub(super) expect: Expect,
}

pub(super) fn cases() -> Vec<Case> {
    let stream = |name, fourcc: &'static str, optional| Case {
        name,
        args: format!("{BASE} --format {fourcc} --max-frames 60"),
        expect: Expect::Stream {
            fourcc,
            frames: 60,
            optional,
        },
    };
    vec![
        // The command verbatim: no --format, no --size (GREY and 320×240 are defaults).
        Case {
            name: "nav-app-default",
            args: "--device /dev/video0 --input-name S-Video --std ntsc --max-frames 60 --json"
                .into(),
            expect: Expect::Stream {
                fourcc: "GREY",
                frames: 60,
                optional: false,
            },
        },
        stream("stream-grey", "GREY", false),
        stream("stream-yuyv", "YUYV", false),
        stream("stream-yu12", "YU12", false),
        stream("stream-uyvy", "UYVY", true),
        stream("stream-bgr24", "BGR3", true),
        stream("stream-rgb565", "RGBP", true),
        stream("stream-bgr32", "BGR4", true),
        Case {
            name: "std-pal",
            args: "--device /dev/video0 --input-name S-Video --std pal --size 320x240 --json --max-frames 10"
                .into(),
            expect: Expect::Std { mask: 0xff, frames: 10 },
        },
        Case {
            name: "input-index-0-tv",
            args: "--device /dev/video0 --input-index 0 --std ntsc --size 320x240 --json --max-frames 5"
                .into(),
            expect: Expect::Input { index: 0 },
        },
        Case {
            name: "bad-input-name",
            args: "--device /dev/video0 --input-name Composite7 --std ntsc --json --max-frames 5".into(),
            expect: Expect::CleanError { text: "no input named" },
        },
        Case {
            name: "fault-buf-error",
            args: format!(
                "{BASE} --max-frames 40 --ctrl 'Inject V4L2_BUF_FLAG_ERROR=1@10' \
                 --ctrl 'Inject V4L2_BUF_FLAG_ERROR=1@20'"
            ),
            expect: Expect::BufError { frames: 40 },
        },
        Case {
            name: "fault-dropped",
            args: format!(
                "{BASE} --max-frames 40 --ctrl 'Percentage of Dropped Buffers=50@5' \
                 --ctrl 'Percentage of Dropped Buffers=0@35'"
            ),
            expect: Expect::Dropped { frames: 40 },
        },
        Case {
            name: "fault-no-signal",
            args: format!(
                "{BASE} --max-frames 30 --ctrl 'Standard Signal Mode=1@5' \
                 --ctrl 'Standard Signal Mode=0@20'"
            ),
            expect: Expect::NoSignal { frames: 30 },
        },
        Case {
            name: "fault-timeout-restart",
            args: format!(
                "{BASE} --max-frames 20 --timeout-ms 1000 \
                 --ctrl 'Percentage of Dropped Buffers=100@5' \
                 --ctrl-on-timeout 'Percentage of Dropped Buffers=0'"
            ),
            expect: Expect::TimeoutRestart { frames: 20 },
        },
        Case {
            name: "human-stderr",
            args: "--device /dev/video0 --input-name S-Video --std ntsc --max-frames 10".into(),
            expect: Expect::Human { frames: 10 },
        },
        // Leaves vivid dropping every buffer: the next case restores it first.
        Case {
            name: "fault-timeout-limit",
            args: format!(
                "{BASE} --max-frames 40 --timeout-ms 500 --max-timeouts 2 \
                 --ctrl 'Percentage of Dropped Buffers=100@5'"
            ),
            expect: Expect::TimeoutLimit {
                at_least: 5,
                timeouts: 2,
            },
        },
        // Last: vivid stays disconnected until every handle is closed.
        Case {
            name: "fault-disconnect",
            args: format!(
                "{BASE} --max-frames 60 --ctrl 'Percentage of Dropped Buffers=0@0' \
                 --ctrl 'Disconnect=1@10'"
            ),
            expect: Expect::Disconnect { at_least: 10, max_frames: 60 },
        },
    ]
}
