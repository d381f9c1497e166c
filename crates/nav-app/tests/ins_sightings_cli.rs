//! `nav-app ins sightings --frame body|ned` (issue 54, item 4): the frame of the directions
//! written is chosen; the default is body with an attitude in the reference (as before); with
//! the same seed a NED direction is the body direction rotated by the reference attitude; body
//! directions from a reference without attitude are refused.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use std::fmt::Write as _;
use std::path::Path;

use ins_common::{nav_app, scratch, stderr};

/// The reference's attitude body FRD → NED (w, x, y, z): heading 30°, pitch 5°, roll −3°
/// (z-y-x Euler angles).
fn attitude_wxyz() -> [f64; 4] {
    let (r, p, y) = (
        (-3f64).to_radians() / 2.0,
        5f64.to_radians() / 2.0,
        30f64.to_radians() / 2.0,
    );
    let (cr, sr, cp, sp, cy, sy) = (r.cos(), r.sin(), p.cos(), p.sin(), y.cos(), y.sin());
    [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]
}

/// `q ⊗ v ⊗ q*` for a unit quaternion (w, x, y, z).
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let u = [x, y, z];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [0, 1, 2].map(|i| v[i] + w * t[i] + ut[i])
}

/// A 10 Hz reference at rest for 20 s, with the attitude above or without one.
fn write_reference(path: &Path, with_attitude: bool) {
    let mut text = String::from("t_s,lat_deg,lon_deg,alt_m,vn_mps,ve_mps,vd_mps,qw,qx,qy,qz\n");
    let [w, x, y, z] = attitude_wxyz();
    for k in 0..=200 {
        let q = if with_attitude {
            format!("{w:e},{x:e},{y:e},{z:e}")
        } else {
            ",,,".into()
        };
        writeln!(text, "{:.1},40,-105,1600,0,0,0,{q}", k as f64 * 0.1).unwrap();
    }
    std::fs::write(path, text).unwrap();
}

fn sightings(dir: &Path, out: &str, frame: Option<&str>) -> std::process::Output {
    let p = |n: &str| dir.join(n).display().to_string();
    let mut args = vec![
        "ins".to_string(),
        "sightings".into(),
        "--reference".into(),
        p("truth.csv"),
        "--landmarks".into(),
        p("lm.toml"),
        "--make-landmarks".into(),
        "8".into(),
        "--landmark-range-m".into(),
        "30".into(),
        "100".into(),
        "--seed".into(),
        "3".into(),
        "--out".into(),
        p(out),
    ];
    if let Some(f) = frame {
        args.extend(["--frame".into(), f.into()]);
    }
    nav_app(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// (t, id, frame, direction) per row.
fn rows(path: &Path) -> Vec<(String, String, String, [f64; 3])> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("t_s,landmark_id,frame,los_x,los_y,los_z")
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let v = [3, 4, 5].map(|i| f[i].parse::<f64>().unwrap());
            (f[0].into(), f[1].into(), f[2].into(), v)
        })
        .collect()
}

#[test]
fn ins_sightings_ned_directions_are_the_body_directions_rotated_by_the_reference_attitude() {
    let dir = scratch("frames");
    write_reference(&dir.join("truth.csv"), true);
    for (out, frame) in [
        ("default.csv", None),
        ("body.csv", Some("body")),
        ("ned.csv", Some("ned")),
    ] {
        let o = sightings(&dir, out, frame);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    // The default with an attitude: body directions, as before the option.
    assert_eq!(
        std::fs::read(dir.join("default.csv")).unwrap(),
        std::fs::read(dir.join("body.csv")).unwrap()
    );
    let (body, ned) = (rows(&dir.join("body.csv")), rows(&dir.join("ned.csv")));
    assert_eq!(body.len(), ned.len());
    assert!(body.len() > 20, "{} sightings", body.len());
    let q = attitude_wxyz();
    let mut largest_turn = 0f64;
    for (b, n) in body.iter().zip(&ned) {
        assert_eq!((&b.0, &b.1), (&n.0, &n.1), "the same epochs and landmarks");
        assert_eq!((b.2.as_str(), n.2.as_str()), ("body", "ned"));
        let rotated = rotate(q, b.3);
        for i in 0..3 {
            assert!(
                (rotated[i] - n.3[i]).abs() < 1e-12,
                "{b:?} → {rotated:?} vs {n:?}"
            );
            largest_turn = largest_turn.max((b.3[i] - n.3[i]).abs());
        }
    }
    assert!(largest_turn > 0.1, "the attitude turns the directions");
}

#[test]
fn ins_sightings_body_frame_without_a_reference_attitude_is_refused() {
    let dir = scratch("frames-no-att");
    write_reference(&dir.join("truth.csv"), false);
    let o = sightings(&dir, "body.csv", Some("body"));
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("body directions need the reference's attitude in every row"),
        "{e}"
    );
    let o = sightings(&dir, "default.csv", None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(rows(&dir.join("default.csv")).iter().all(|r| r.2 == "ned"));
}

/// Hamilton product of (w, x, y, z) quaternions.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// `--reference` takes a TUM trajectory in a local frame too (as `nav-app ins --truth`): the
/// same reference as CSV and as TUM (ENU) gives the same sightings to round-off.
#[test]
fn ins_sightings_from_a_tum_reference_equal_those_from_the_csv_reference() {
    let dir = scratch("frames-tum");
    write_reference(&dir.join("truth.csv"), true);
    // body → ENU = (NED → ENU) ⊗ (body → NED); NED → ENU: 180° about (1, 1, 0)/√2.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let [w, x, y, z] = mul([0.0, h, h, 0.0], attitude_wxyz());
    let mut tum = String::from("# t x y z qx qy qz qw\n");
    for k in 0..=200 {
        writeln!(tum, "{:.1} 0 0 0 {x:e} {y:e} {z:e} {w:e}", k as f64 * 0.1).unwrap();
    }
    std::fs::write(dir.join("truth.tum"), tum).unwrap();
    let o = sightings(&dir, "csv.csv", None);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = |n: &str| dir.join(n).display().to_string();
    let run_tum = |extra: &[&str]| {
        let mut args = vec![
            "ins",
            "sightings",
            "--reference",
            &p("truth.tum"),
            "--landmarks",
            &p("lm2.toml"),
            "--make-landmarks",
            "8",
            "--landmark-range-m",
            "30",
            "100",
            "--seed",
            "3",
            "--out",
            &p("tum.csv"),
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        args.extend(extra.iter().map(|s| s.to_string()));
        nav_app(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let o = run_tum(&[]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains(&format!(
            "{}:2:1: a TUM trajectory holds positions in a local frame",
            p("truth.tum")
        )),
        "{e}"
    );
    let o = run_tum(&["--tum-origin", "40,-105,1600", "--tum-frame", "enu"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (a, b) = (rows(&dir.join("csv.csv")), rows(&dir.join("tum.csv")));
    assert_eq!(a.len(), b.len());
    for (a, b) in a.iter().zip(&b) {
        assert_eq!((&a.0, &a.1, &a.2), (&b.0, &b.1, &b.2));
        for i in 0..3 {
            assert!((a.3[i] - b.3[i]).abs() < 1e-9, "{a:?} vs {b:?}");
        }
    }
}
