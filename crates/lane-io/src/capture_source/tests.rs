use super::*;

#[test]
fn control_specs_parse_name_value_and_frame() {
    let c = parse_control_spec("Inject V4L2_BUF_FLAG_ERROR=1@20").unwrap();
    assert_eq!(
        c,
        ControlSet {
            name: "Inject V4L2_BUF_FLAG_ERROR".into(),
            value: 1,
            at_frame: 20
        }
    );
    let c = parse_control_spec("Percentage of Dropped Buffers=-5").unwrap();
    assert_eq!((c.value, c.at_frame), (-5, 0));
    // The last '=' splits, so a name may hold one.
    assert_eq!(parse_control_spec("a=b=3").unwrap().name, "a=b");
    for bad in [
        "Disconnect",
        "=1",
        "Disconnect=x",
        "Disconnect=1@-2",
        "D=1@",
    ] {
        let e = parse_control_spec(bad).unwrap_err();
        assert!(
            matches!(
                e,
                LaneIoError::ConfigField {
                    field: "control",
                    ..
                }
            ),
            "{bad}: {e}"
        );
        assert!(e.to_string().contains(bad), "{e}");
    }
}

#[test]
fn options_validation_names_the_field() {
    assert!(DeviceOptions::default().validate().is_ok());
    let mut o = DeviceOptions {
        max_consecutive_timeouts: 0,
        ..DeviceOptions::default()
    };
    assert!(matches!(
        o.validate(),
        Err(LaneIoError::ConfigField {
            field: "max_consecutive_timeouts",
            ..
        })
    ));
    o.max_consecutive_timeouts = 1;
    o.capture.buffers = 2;
    assert!(matches!(
        o.validate(),
        Err(LaneIoError::ConfigField {
            field: "capture.buffers",
            ..
        })
    ));
}

#[test]
fn timeline_index_skips_dropped_frames_and_time_is_relative_to_the_first() {
    let mut t = Timeline::default();
    let a = t.advance(5_000_000, 7); // a gap before the first frame is not a hole
    let b = t.advance(5_033_367, 0);
    let c = t.advance(5_133_467, 2);
    assert_eq!((a.index, b.index, c.index), (0, 1, 4));
    assert_eq!(a.t_s, 0.0);
    assert!((b.t_s - 0.033_367).abs() < 1e-12);
    assert!((c.t_s - 0.133_467).abs() < 1e-12);
}

#[test]
fn timeouts_are_non_fatal_until_the_limit_in_a_row() {
    let mut g = TimeoutGate::new(3);
    assert!(!g.timeout("/dev/video0", 1000, true).is_fatal());
    assert!(!g.timeout("/dev/video0", 1000, true).is_fatal());
    g.frame(); // a frame in between resets the count
    assert!(!g.timeout("/dev/video0", 1000, true).is_fatal());
    assert!(!g.timeout("/dev/video0", 1000, true).is_fatal());
    let last = g.timeout("/dev/video0", 1000, false);
    assert!(last.is_fatal());
    let text = last.to_string();
    assert!(
        text.contains("/dev/video0") && text.contains("1000 ms") && text.contains("3 of"),
        "{text}"
    );
    // A limit of 0 behaves as 1: the first timeout ends the run.
    assert!(TimeoutGate::new(0).timeout("d", 1, true).is_fatal());
}

#[test]
fn enodev_maps_to_device_gone_and_the_rest_to_capture_errors() {
    let gone = capture_error(
        "/dev/video0",
        CaptureError::DeviceGone {
            path: "/dev/video0".into(),
        },
    );
    assert!(matches!(gone, LaneIoError::DeviceGone { .. }) && gone.is_fatal());
    let other = capture_error(
        "/dev/video0",
        CaptureError::InputNotFound {
            name: "S-Video".into(),
            available: vec!["Television".into()],
        },
    );
    assert!(other.is_fatal());
    // The device, then the capture layer's error (its source), each once.
    assert_eq!(other.to_string(), "/dev/video0");
    let text = std::iter::successors(Some(&other as &dyn std::error::Error), |c| c.source())
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(": ");
    assert!(
        text.starts_with("/dev/video0: no input named \"S-Video\"") && text.contains("Television"),
        "{text}"
    );
    assert!(matches!(
        other,
        LaneIoError::Capture {
            error: CaptureError::InputNotFound { .. },
            ..
        }
    ));
}

#[test]
fn frame_rate_follows_the_line_standard() {
    let ntsc = std_frame_rate_hz(Some(0x1000)).unwrap();
    assert!((ntsc - 29.970_029_970_03).abs() < 1e-9);
    assert_eq!(std_frame_rate_hz(Some(0xff)), Some(25.0)); // PAL B/G/D/K/H/I
    assert_eq!(std_frame_rate_hz(Some(0x00ff_0000)), Some(25.0)); // SECAM
    assert_eq!(std_frame_rate_hz(Some(0x0100)), Some(30_000.0 / 1001.0)); // PAL-M
    assert_eq!(std_frame_rate_hz(None), None);
    assert_eq!(std_frame_rate_hz(Some(0)), None);
}

#[test]
fn the_monitor_is_empty_before_a_device_is_opened() {
    let m = CaptureMonitor::default();
    assert!(m.setup().is_none() && m.last_frame().is_none());
    assert_eq!(m.stats(), DeviceStats::default());
}

#[cfg(not(feature = "capture"))]
#[test]
fn without_the_feature_open_says_capture_is_not_built_in() {
    let err = open(Path::new("/dev/video0"), &DeviceOptions::default())
        .err()
        .unwrap();
    assert!(matches!(err, LaneIoError::CaptureUnavailable { .. }));
    assert!(err.to_string().contains("--features capture"), "{err}");
}
