//! `nav-app`'s capture options (with `--device`): the clap arguments and the
//! [`DeviceOptions`] they give, validated in one place (`DeviceOptions::validate`).

use anyhow::{Context, Result};
use lane_io::capture::{InputSelect, PixelFormat, VideoStd};
use lane_io::capture_source::{DeviceOptions, parse_control_spec};

/// Capture options (with `--device`).
#[derive(clap::Args, Debug)]
pub(crate) struct DeviceArgs {
    /// Capture input by name (bttv: Television, Composite0…, S-Video); a unique "NAME N" also matches.
    #[arg(
        long,
        value_name = "NAME",
        requires = "device",
        conflicts_with = "input_index"
    )]
    input_name: Option<String>,
    /// Capture input by index (VIDIOC_ENUMINPUT order). Default: the driver's current input.
    #[arg(long, value_name = "N", requires = "device")]
    input_index: Option<u32>,
    /// Video standard: ntsc (NTSC-M), ntsc-m-jp, ntsc443, pal, pal-m, pal-n, pal-nc, pal60, secam.
    #[arg(long, value_name = "STD", default_value = "ntsc", value_parser = parse_std)]
    std: VideoStd,
    /// Requested capture frame size, px (the driver may adjust it; its answer is used).
    #[arg(long, value_name = "WxH", default_value = "320x240", value_parser = parse_wh)]
    size: (u32, u32),
    /// Frame timeouts in a row (each restarts the stream) that end the run with exit code 4.
    #[arg(long, value_name = "N", default_value_t = 3)]
    max_timeouts: u32,
    /// Test hook: capture only this pixel format (fourcc, e.g. YUYV).
    #[arg(long, value_name = "FOURCC", hide = true)]
    format: Option<String>,
    /// Test hook: frame timeout, ms.
    #[arg(long, value_name = "MS", default_value_t = 1000, hide = true)]
    timeout_ms: u32,
    /// Test hook: set a V4L2 control once FRAME frames have been delivered.
    #[arg(long = "ctrl", value_name = "NAME=VALUE@FRAME", hide = true)]
    ctrl: Vec<String>,
    /// Test hook: set a V4L2 control at the first timeout.
    #[arg(long = "ctrl-on-timeout", value_name = "NAME=VALUE", hide = true)]
    ctrl_on_timeout: Vec<String>,
}

fn parse_std(s: &str) -> Result<VideoStd, String> {
    s.parse()
        .map_err(|e: lane_io::capture::CaptureError| e.to_string())
}

fn parse_wh(s: &str) -> Result<(u32, u32), String> {
    lane_io::capture::parse_size(s).map_err(|e| e.to_string())
}

pub(crate) fn device_options(d: &DeviceArgs) -> Result<DeviceOptions> {
    let mut opts = DeviceOptions::default();
    opts.capture.input = match (&d.input_name, d.input_index) {
        (Some(name), _) => InputSelect::Name(name.clone()),
        (None, Some(index)) => InputSelect::Index(index),
        (None, None) => InputSelect::Current,
    };
    opts.capture.std = d.std;
    (opts.capture.width_px, opts.capture.height_px) = d.size;
    opts.capture.timeout_ms = d.timeout_ms;
    if let Some(f) = &d.format {
        let fourcc = <[u8; 4]>::try_from(f.as_bytes())
            .ok()
            .and_then(PixelFormat::from_fourcc)
            .with_context(|| {
                format!(
                    "--format {f:?}: expected one of {}",
                    PixelFormat::ALL.map(|p| p.to_string()).join(", ")
                )
            })?;
        opts.capture.pixel_formats = vec![fourcc];
    }
    opts.max_consecutive_timeouts = d.max_timeouts;
    for spec in &d.ctrl {
        opts.controls_at_frame.push(parse_control_spec(spec)?);
    }
    for spec in &d.ctrl_on_timeout {
        opts.controls_on_timeout.push(parse_control_spec(spec)?);
    }
    opts.validate()?;
    Ok(opts)
}
