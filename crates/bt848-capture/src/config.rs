//! Capture configuration: input, video standard, frame size, pixel-format preference, buffering.

use serde::{Deserialize, Serialize};

use crate::{CaptureError, PixelFormat};

/// Which video input of the card to capture from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum InputSelect {
    /// Leave the driver's current input selected.
    #[default]
    Current,
    /// The input whose `VIDIOC_ENUMINPUT` name equals this (ASCII case-insensitive), e.g. bttv's
    /// `"Composite0"`, `"S-Video"`, `"Television"`; failing that, the only input named this plus
    /// a space and a suffix (vivid's `"S-Video 0"` answers to `"S-Video"`).
    Name(String),
    /// The input with this `VIDIOC_ENUMINPUT` index.
    Index(u32),
}

/// Analogue video standard (`v4l2_std_id` sets). Serialised in kebab-case (`"ntsc-m"`, `"pal"`);
/// `"ntsc"` is accepted for NTSC-M.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum VideoStd {
    /// NTSC-M (North America; the paper's camera). `V4L2_STD_NTSC_M`.
    #[default]
    #[serde(alias = "ntsc")]
    NtscM,
    /// NTSC-M Japan. `V4L2_STD_NTSC_M_JP`.
    NtscMJp,
    /// NTSC 4.43. `V4L2_STD_NTSC_443`.
    Ntsc443,
    /// Any 625-line PAL B/G/D/K/H/I. `V4L2_STD_PAL`.
    Pal,
    /// PAL-M (Brazil). `V4L2_STD_PAL_M`.
    PalM,
    /// PAL-N. `V4L2_STD_PAL_N`.
    PalN,
    /// PAL-Nc (Argentina). `V4L2_STD_PAL_Nc`.
    PalNc,
    /// PAL-60. `V4L2_STD_PAL_60`.
    Pal60,
    /// Any SECAM. `V4L2_STD_SECAM`.
    Secam,
}

impl VideoStd {
    /// Every standard, for listing in CLI help and errors.
    pub const ALL: [VideoStd; 9] = [
        VideoStd::NtscM,
        VideoStd::NtscMJp,
        VideoStd::Ntsc443,
        VideoStd::Pal,
        VideoStd::PalM,
        VideoStd::PalN,
        VideoStd::PalNc,
        VideoStd::Pal60,
        VideoStd::Secam,
    ];

    /// The `v4l2_std_id` bit set (values from `linux/videodev2.h`).
    pub const fn v4l2_std_id(self) -> u64 {
        match self {
            VideoStd::NtscM => 0x0000_1000,
            VideoStd::NtscMJp => 0x0000_2000,
            VideoStd::Ntsc443 => 0x0000_4000,
            VideoStd::Pal => 0x0000_00ff,
            VideoStd::PalM => 0x0000_0100,
            VideoStd::PalN => 0x0000_0200,
            VideoStd::PalNc => 0x0000_0400,
            VideoStd::Pal60 => 0x0000_0800,
            VideoStd::Secam => 0x00ff_0000,
        }
    }

    /// The kebab-case name used by serde and [`std::str::FromStr`].
    pub const fn name(self) -> &'static str {
        match self {
            VideoStd::NtscM => "ntsc-m",
            VideoStd::NtscMJp => "ntsc-m-jp",
            VideoStd::Ntsc443 => "ntsc443",
            VideoStd::Pal => "pal",
            VideoStd::PalM => "pal-m",
            VideoStd::PalN => "pal-n",
            VideoStd::PalNc => "pal-nc",
            VideoStd::Pal60 => "pal60",
            VideoStd::Secam => "secam",
        }
    }
}

impl std::fmt::Display for VideoStd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for VideoStd {
    type Err = CaptureError;

    /// Parse `ntsc` (= NTSC-M) or any [`VideoStd::name`], ASCII case-insensitively.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.to_ascii_lowercase();
        if lower == "ntsc" {
            return Ok(VideoStd::NtscM);
        }
        VideoStd::ALL
            .into_iter()
            .find(|v| v.name() == lower)
            .ok_or_else(|| CaptureError::Config {
                field: "std",
                reason: format!(
                    "unknown standard {s:?}; expected ntsc or one of {}",
                    VideoStd::ALL.map(VideoStd::name).join(", ")
                ),
            })
    }
}

/// Everything [`crate::Capture::open`] needs besides the device path.
///
/// Defaults: current input, NTSC-M, 320×240 (the paper's grabber setting), formats in
/// [`PixelFormat::ALL`] order, 4 buffers, 1000 ms timeout.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CaptureConfig {
    /// Video input to select before streaming.
    pub input: InputSelect,
    /// Video standard to set (bttv starts in PAL, so it must be set for an NTSC camera). Ignored
    /// for inputs that report no standards (`v4l2_input.std == 0`, e.g. webcams).
    pub std: VideoStd,
    /// Requested frame width, pixels. The driver may adjust it: the frame size used is the one the
    /// driver returns (see [`crate::Capture::width_px`]).
    pub width_px: u32,
    /// Requested frame height, pixels (≤ 240 on bttv gives single fields: no combing).
    pub height_px: u32,
    /// Pixel formats to try, most preferred first; non-empty, no repeats.
    pub pixel_formats: Vec<PixelFormat>,
    /// Number of mmap buffers to request; 4…=32. Fewer granted by the driver is an error.
    pub buffers: u32,
    /// How long to wait for a frame before [`CaptureError::Timeout`] and a stream restart,
    /// milliseconds; 1…=60 000.
    pub timeout_ms: u32,
}

impl Default for CaptureConfig {
    fn default() -> Self {
        Self {
            input: InputSelect::Current,
            std: VideoStd::NtscM,
            width_px: 320,
            height_px: 240,
            pixel_formats: PixelFormat::ALL.to_vec(),
            buffers: 4,
            timeout_ms: 1000,
        }
    }
}

/// Largest accepted frame side, pixels (well above any analogue capture).
pub const MAX_SIDE_PX: u32 = 8192;
/// Fewest mmap buffers accepted.
pub const MIN_BUFFERS: u32 = 4;
/// Most mmap buffers accepted (`VIDEO_MAX_FRAME`).
pub const MAX_BUFFERS: u32 = 32;

impl CaptureConfig {
    /// Check every field; the error names the first bad one.
    ///
    /// # Errors
    /// [`CaptureError::Config`] with the field name and the reason.
    pub fn validate(&self) -> Result<(), CaptureError> {
        let bad = |field: &'static str, reason: String| Err(CaptureError::Config { field, reason });
        if let InputSelect::Name(name) = &self.input
            && name.trim().is_empty()
        {
            return bad("input", "input name is empty".into());
        }
        if self.width_px == 0 || self.width_px > MAX_SIDE_PX {
            return bad(
                "width_px",
                format!("{} not in 1..={MAX_SIDE_PX}", self.width_px),
            );
        }
        if self.height_px == 0 || self.height_px > MAX_SIDE_PX {
            return bad(
                "height_px",
                format!("{} not in 1..={MAX_SIDE_PX}", self.height_px),
            );
        }
        if self.pixel_formats.is_empty() {
            return bad(
                "pixel_formats",
                "empty: at least one format is needed".into(),
            );
        }
        for (i, f) in self.pixel_formats.iter().enumerate() {
            if self.pixel_formats[..i].contains(f) {
                return bad("pixel_formats", format!("{f} listed twice"));
            }
        }
        if !(MIN_BUFFERS..=MAX_BUFFERS).contains(&self.buffers) {
            return bad(
                "buffers",
                format!("{} not in {MIN_BUFFERS}..={MAX_BUFFERS}", self.buffers),
            );
        }
        if !(1..=60_000).contains(&self.timeout_ms) {
            return bad(
                "timeout_ms",
                format!("{} not in 1..=60000", self.timeout_ms),
            );
        }
        Ok(())
    }
}

/// Parse a `WIDTHxHEIGHT` size such as `320x240` (for CLIs).
///
/// # Errors
/// [`CaptureError::Config`] naming field `size`.
pub fn parse_size(s: &str) -> Result<(u32, u32), CaptureError> {
    let err = || CaptureError::Config {
        field: "size",
        reason: format!("{s:?} is not WIDTHxHEIGHT (e.g. 320x240)"),
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(err)?;
    let w = w.trim().parse().map_err(|_| err())?;
    let h = h.trim().parse().map_err(|_| err())?;
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(cfg: &CaptureConfig) -> &'static str {
        match cfg.validate() {
            Err(CaptureError::Config { field, .. }) => field,
            other => panic!("expected a config error, got {other:?}"),
        }
    }

    #[test]
    fn default_is_valid_ntsc_320x240_with_four_buffers() {
        let cfg = CaptureConfig::default();
        cfg.validate().unwrap();
        assert_eq!((cfg.width_px, cfg.height_px, cfg.buffers), (320, 240, 4));
        assert_eq!(cfg.std, VideoStd::NtscM);
        assert_eq!(cfg.pixel_formats[0], PixelFormat::Grey);
    }

    #[test]
    fn validate_names_the_bad_field() {
        let base = CaptureConfig::default();
        assert_eq!(
            field_of(&CaptureConfig {
                buffers: 3,
                ..base.clone()
            }),
            "buffers"
        );
        assert_eq!(
            field_of(&CaptureConfig {
                buffers: 33,
                ..base.clone()
            }),
            "buffers"
        );
        assert_eq!(
            field_of(&CaptureConfig {
                width_px: 0,
                ..base.clone()
            }),
            "width_px"
        );
        assert_eq!(
            field_of(&CaptureConfig {
                height_px: 9000,
                ..base.clone()
            }),
            "height_px"
        );
        assert_eq!(
            field_of(&CaptureConfig {
                timeout_ms: 0,
                ..base.clone()
            }),
            "timeout_ms"
        );
        assert_eq!(
            field_of(&CaptureConfig {
                pixel_formats: vec![],
                ..base.clone()
            }),
            "pixel_formats"
        );
        let dup = vec![PixelFormat::Yuyv, PixelFormat::Grey, PixelFormat::Yuyv];
        assert_eq!(
            field_of(&CaptureConfig {
                pixel_formats: dup,
                ..base.clone()
            }),
            "pixel_formats"
        );
        let empty_name = InputSelect::Name(" ".into());
        assert_eq!(
            field_of(&CaptureConfig {
                input: empty_name,
                ..base
            }),
            "input"
        );
    }

    #[test]
    fn toml_round_trip_and_unknown_fields_rejected() {
        let text = r#"
            input = { name = "S-Video" }
            std = "ntsc"
            width_px = 640
            height_px = 480
            pixel_formats = ["YUYV", "GREY"]
            buffers = 6
            timeout_ms = 500
        "#;
        let cfg: CaptureConfig = toml::from_str(text).unwrap();
        assert_eq!(cfg.input, InputSelect::Name("S-Video".into()));
        assert_eq!(cfg.std, VideoStd::NtscM);
        assert_eq!(
            cfg.pixel_formats,
            vec![PixelFormat::Yuyv, PixelFormat::Grey]
        );
        let back: CaptureConfig = toml::from_str(&toml::to_string(&cfg).unwrap()).unwrap();
        assert_eq!(back, cfg);
        assert!(toml::from_str::<CaptureConfig>("buffer = 4").is_err());
        let idx: CaptureConfig = toml::from_str("input = { index = 1 }\nstd = \"pal\"").unwrap();
        assert_eq!((idx.input, idx.std), (InputSelect::Index(1), VideoStd::Pal));
    }

    #[test]
    fn std_parsing_accepts_ntsc_alias_and_rejects_unknown() {
        assert_eq!("NTSC".parse::<VideoStd>().unwrap(), VideoStd::NtscM);
        assert_eq!("pal-m".parse::<VideoStd>().unwrap(), VideoStd::PalM);
        for s in VideoStd::ALL {
            assert_eq!(s.name().parse::<VideoStd>().unwrap(), s);
        }
        assert!(matches!(
            "ntsc-x".parse::<VideoStd>(),
            Err(CaptureError::Config { field: "std", .. })
        ));
    }

    #[test]
    fn std_ids_match_videodev2_h() {
        // V4L2_STD_PAL = PAL_BG|PAL_DK|PAL_H|PAL_I = 0x07|0xe0|0x08|0x10.
        assert_eq!(VideoStd::Pal.v4l2_std_id(), 0x07 | 0xe0 | 0x08 | 0x10);
        // V4L2_STD_NTSC_M = 0x1000; NTSC_M must not overlap any PAL bit.
        assert_eq!(
            VideoStd::NtscM.v4l2_std_id() & VideoStd::Pal.v4l2_std_id(),
            0
        );
        // SECAM = B|D|G|H|K|K1|L|LC = 0x00010000 … 0x00800000.
        assert_eq!(
            VideoStd::Secam.v4l2_std_id(),
            (0..8).map(|i| 0x0001_0000u64 << i).sum()
        );
    }

    #[test]
    fn size_parsing() {
        assert_eq!(parse_size("320x240").unwrap(), (320, 240));
        assert_eq!(parse_size("640X480").unwrap(), (640, 480));
        assert!(matches!(
            parse_size("320"),
            Err(CaptureError::Config { field: "size", .. })
        ));
        assert!(parse_size("axb").is_err());
    }
}
