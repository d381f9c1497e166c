//! `nav-app ins --tum-out`, `--tum-truth-out` (issue 54, item 7): the solution and the
//! reference as TUM trajectories in a local frame stated in a header comment; the RMS of their
//! position differences over the rows with the same stamp is `nav-app`'s own position RMS (what
//! `evo_ape tum` computes without alignment).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod ins_common;

use std::collections::HashMap;
use std::path::Path;

use ins_common::{nav_app, scratch, stderr, write_imu, write_reference, write_sightings};

/// (header comment, stamp text → position) of a TUM file.
fn tum(path: &Path) -> (String, HashMap<String, [f64; 3]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            assert_eq!(f.len(), 8, "{l}");
            let q: f64 = f[4..8]
                .iter()
                .map(|x| x.parse::<f64>().unwrap().powi(2))
                .sum();
            assert!((q - 1.0).abs() < 1e-12, "{l}");
            (
                f[0].to_owned(),
                [1, 2, 3].map(|i| f[i].parse::<f64>().unwrap()),
            )
        })
        .collect();
    (header, rows)
}

#[test]
fn ins_tum_outputs_rms_over_the_same_stamps_is_the_printed_position_rms() {
    let dir = scratch("tum-out");
    let p = |n: &str| dir.join(n).display().to_string();
    let (imu, truth, out, m_json, sol_tum, ref_tum) = (
        p("imu.csv"),
        p("truth.csv"),
        p("o.csv"),
        p("m.json"),
        p("sol.tum"),
        p("ref.tum"),
    );
    write_imu(&dir.join("imu.csv"));
    write_reference(&dir.join("truth.csv"), 0.0, 0.0);
    let (s, lm) = write_sightings(&dir);
    for (filter, frame, origin) in [("kf", "enu", Some("40,-105,1600")), ("none", "ned", None)] {
        let mut args = vec![
            "ins",
            "--imu",
            &imu,
            "--truth",
            &truth,
            "--sightings",
            &s,
            "--landmarks",
            &lm,
            "--filter",
            filter,
            "--out",
            &out,
            "--metrics-json",
            &m_json,
            "--tum-out",
            &sol_tum,
            "--tum-truth-out",
            &ref_tum,
            "--tum-frame",
            frame,
        ];
        if let Some(o) = origin {
            args.extend(["--tum-origin", o]);
        }
        let o = nav_app(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let (sol_header, sol) = tum(&dir.join("sol.tum"));
        let (ref_header, reference) = tum(&dir.join("ref.tum"));
        for h in [&sol_header, &ref_header] {
            assert!(
                h.starts_with("# ")
                    && h.contains(&format!(
                        "local {} frame (m) with origin lat 40.000000000°, lon -105.000000000°, alt 1600.0000 m",
                        frame.to_uppercase()
                    )),
                "{h}"
            );
        }
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
        let compared = json["metrics"]["compared"].as_u64().unwrap() as usize;
        let printed_rms = json["metrics"]["position_m"]["rms"].as_f64().unwrap();
        assert_eq!(
            reference.len(),
            compared,
            "one reference row per compared time"
        );
        let mut sum2 = 0.0;
        for (t, r) in &reference {
            let s = sol
                .get(t)
                .unwrap_or_else(|| panic!("no solution row at t = {t}"));
            sum2 += (0..3).map(|i| (s[i] - r[i]).powi(2)).sum::<f64>();
        }
        let rms = (sum2 / compared as f64).sqrt();
        assert!(
            printed_rms > 1e-4,
            "{filter}: a non-trivial error, {printed_rms} m"
        );
        assert!(
            (rms - printed_rms).abs() < 1e-6,
            "{filter}: TUM RMS {rms} m vs printed {printed_rms} m"
        );
    }
}
