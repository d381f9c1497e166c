//! Local frames (TUM and ASL references, `--tum-out`): a local ENU position lands where the
//! Earth model's own NED displacement puts it, positions round-trip, a TUM trajectory's velocity
//! is its positions' difference turned into NED, and its attitude body → ENU becomes body → NED.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;

use ins_errors::earth::{Geodetic, displace_by_ned_m, pos_err_ned_m};
use ins_sim::logs::{self, LocalAxes, LocalFrame};
use nalgebra::{UnitQuaternion, Vector3};

fn origin() -> Geodetic {
    Geodetic::from_deg(-23.2, -45.87, 600.0)
}

#[test]
fn a_local_enu_position_is_the_earth_models_ned_displacement() {
    let enu = LocalFrame {
        origin: origin(),
        axes: LocalAxes::Enu,
    };
    let ned = LocalFrame {
        axes: LocalAxes::Ned,
        ..enu
    };
    let p_enu = Vector3::new(300.0, 400.0, 10.0);
    let g = enu.to_geodetic(&p_enu);
    let want = displace_by_ned_m(&origin(), &Vector3::new(400.0, 300.0, -10.0));
    let miss = pos_err_ned_m(&g, &want).norm();
    assert!(miss < 1e-3, "{miss} m");
    assert!((enu.to_local_m(&g) - p_enu).norm() < 1e-8);
    assert!((ned.to_local_m(&g) - Vector3::new(400.0, 300.0, -10.0)).norm() < 1e-8);
    assert!(LocalFrame::from_text("91,0,0", LocalAxes::Enu).is_err());
    assert!(LocalFrame::from_text("40,-105", LocalAxes::Enu).is_err());
}

#[test]
fn a_tum_trajectory_gives_differenced_ned_velocity_and_body_to_ned_attitude() {
    let dir = std::env::temp_dir().join(format!("ins-layouts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("walk.tum");
    // 2 m/s east, 1 m/s north, 0.5 m/s up in ENU; body → ENU: 180° about (1, 1, 0)/√2, i.e.
    // body = NED axes.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mut text = String::from("# t x y z qx qy qz qw\n");
    for k in 0..=50 {
        let t = k as f64 * 0.1;
        writeln!(text, "{t} {} {} {} {h} {h} 0 0", 2.0 * t, t, 0.5 * t).unwrap();
    }
    std::fs::write(&path, text).unwrap();
    let frame = LocalFrame {
        origin: origin(),
        axes: LocalAxes::Enu,
    };
    let rows = logs::read_reference_in(&path, Some(&frame), None).unwrap();
    assert_eq!(rows.len(), 51);
    for r in [&rows[0], &rows[25], &rows[50]] {
        assert!(
            (r.vel_ned_mps - Vector3::new(1.0, 2.0, -0.5)).norm() < 1e-5,
            "{:?}",
            r.vel_ned_mps
        );
        let q = r.att_b_to_n.unwrap();
        assert!(q.angle_to(&UnitQuaternion::identity()) < 1e-5, "{q:?}");
    }
    // Without the frame: an error naming the first pose's line.
    let e = logs::read_reference_in(&path, None, None).unwrap_err();
    assert!(
        e.to_string()
            .starts_with(&format!("{}:2:1:", path.display())),
        "{e}"
    );
}

/// `--tum-out` writes what the TUM reader reads: positions and attitudes come back.
#[test]
fn a_written_tum_trajectory_reads_back_to_the_same_poses() {
    let dir = std::env::temp_dir().join(format!("ins-layouts-rt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("out.tum");
    let frame = LocalFrame {
        origin: origin(),
        axes: LocalAxes::Enu,
    };
    let poses: Vec<(f64, Geodetic, UnitQuaternion<f64>)> = (0..20)
        .map(|k| {
            let t = k as f64 * 0.5;
            let g = frame.to_geodetic(&Vector3::new(40.0 * t, -25.0 * t, 3.0 * t));
            let q = UnitQuaternion::from_euler_angles(0.1 * t, -0.05 * t, 0.3 * t);
            (t, g, q)
        })
        .collect();
    let mut file = std::fs::File::create(&path).unwrap();
    let n = logs::write_tum(&mut file, &path, &frame, "test", poses.iter().copied()).unwrap();
    assert_eq!(n, 20);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("# test: TUM poses `t x y z qx qy qz qw`") && text.contains("local ENU"),
        "{text}"
    );
    let rows = logs::read_reference_in(&path, Some(&frame), None).unwrap();
    for ((t, g, q), r) in poses.iter().zip(&rows) {
        assert_eq!(*t, r.t_s);
        assert!(pos_err_ned_m(&r.pos, g).norm() < 1e-6);
        assert!(r.att_b_to_n.unwrap().angle_to(q) < 1e-9);
    }
}
