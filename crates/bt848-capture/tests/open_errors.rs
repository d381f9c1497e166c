//! Opening things that are not capture devices gives typed errors, never a panic.
#![cfg(feature = "v4l")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use bt848_capture::{Capture, CaptureConfig, CaptureError};

#[test]
fn missing_device_is_an_open_error_naming_the_path() {
    let path = "/dev/this-video-device-does-not-exist";
    match Capture::open(path, &CaptureConfig::default()) {
        Err(CaptureError::Open { path: p, source }) => {
            assert_eq!(p, path);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        Err(other) => panic!("expected Open error, got {other:?}"),
        Ok(_) => panic!("opened a device that does not exist"),
    }
}

#[test]
fn non_v4l2_node_fails_at_querycap() {
    // /dev/null accepts open(O_RDWR) but no V4L2 ioctl (ENOTTY).
    match Capture::open("/dev/null", &CaptureConfig::default()) {
        Err(CaptureError::Ioctl { op, .. }) => assert_eq!(op, "VIDIOC_QUERYCAP"),
        Err(other) => panic!("expected an Ioctl error at QUERYCAP, got {other:?}"),
        Ok(_) => panic!("/dev/null opened as a capture device"),
    }
}

#[test]
fn invalid_config_is_rejected_before_touching_the_device() {
    let cfg = CaptureConfig {
        buffers: 2,
        ..CaptureConfig::default()
    };
    // The path does not exist: a Config error proves validation ran first.
    match Capture::open("/dev/this-video-device-does-not-exist", &cfg) {
        Err(CaptureError::Config { field, .. }) => assert_eq!(field, "buffers"),
        Err(other) => panic!("expected a Config error, got {other:?}"),
        Ok(_) => panic!("opened with 2 buffers"),
    }
}

#[test]
fn set_control_on_missing_device_is_an_open_error() {
    assert!(matches!(
        bt848_capture::set_control("/dev/this-video-device-does-not-exist", "Brightness", 1),
        Err(CaptureError::Open { .. })
    ));
}
