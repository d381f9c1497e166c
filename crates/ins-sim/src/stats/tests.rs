use super::*;

fn file(modes: &[Mode]) -> StatsFile {
    StatsFile {
        format: FORMAT.to_string(),
        scenario_fingerprint: fingerprint("s"),
        scenario_source: "test".to_string(),
        assumptions: Vec::new(),
        sd_noise_sigma_m: None,
        duration_s: 2.0,
        seed: 1,
        runs_total: 10,
        run_ranges: vec![(5, 10), (0, 5)],
        shards: vec![ShardInfo { index: 1, count: 1 }],
        modes: modes.iter().map(|&m| ModeStats::new(m, 3)).collect(),
        exclusions: vec![
            Exclusion {
                mode: Mode::Kf,
                run_index: 4,
                t_s: None,
                reason: "x".to_string(),
            },
            Exclusion {
                mode: Mode::Standalone,
                run_index: 7,
                t_s: Some(1.0),
                reason: "y".to_string(),
            },
        ],
        runs: Vec::new(),
        wall_s: 0.0,
        core_s: 0.0,
    }
}

fn invalid_field(r: Result<Stats, SimError>) -> &'static str {
    match r {
        Err(e @ SimError::StatsInvalid { field, .. }) => {
            // The message names the field.
            assert!(
                e.to_string().starts_with(&format!("stats: {field}: ")),
                "{e}"
            );
            field
        }
        other => panic!("expected SimError::StatsInvalid, got {other:?}"),
    }
}

#[test]
fn loading_sorts_what_stats_documents_as_sorted() {
    let s = Stats::try_from(file(&[Mode::Standalone, Mode::Kf])).unwrap();
    assert_eq!(s.run_ranges(), &[(0, 5), (5, 10)]);
    let order: Vec<(Mode, u64)> = s
        .exclusions()
        .iter()
        .map(|e| (e.mode, e.run_index))
        .collect();
    assert_eq!(order, vec![(Mode::Standalone, 7), (Mode::Kf, 4)]);
    // And the JSON round trip goes through the same check.
    let text = serde_json::to_string(&s).unwrap();
    assert_eq!(serde_json::from_str::<Stats>(&text).unwrap(), s);
}

#[test]
fn modes_out_of_order_duplicated_or_of_other_lengths_are_refused() {
    let r = Stats::try_from(file(&[Mode::Kf, Mode::Standalone]));
    assert_eq!(invalid_field(r), "modes");
    let r = Stats::try_from(file(&[Mode::Kf, Mode::Kf]));
    assert_eq!(invalid_field(r), "modes");
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.modes[1].bins.pop();
    assert_eq!(invalid_field(Stats::try_from(f)), "modes");
    // No time bin at all (a truncated or hand-edited stats.json): refused, not read past.
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.modes.iter_mut().for_each(|m| m.bins.clear());
    assert_eq!(invalid_field(Stats::try_from(f)), "modes");
    // From stats.json: the serde error carries the reason.
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.modes.reverse();
    let e = serde_json::from_str::<Stats>(&serde_json::to_string(&f).unwrap()).unwrap_err();
    assert!(e.to_string().contains("modes"), "{e}");
}

#[test]
fn bad_run_ranges_and_foreign_modes_are_refused() {
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.run_ranges = vec![(0, 6), (5, 10)];
    let e = Stats::try_from(f).unwrap_err();
    assert!(matches!(e, SimError::StatsOverlap(0, 6, 5, 10)), "{e:?}");
    assert!(e.to_string().contains("0..6 and 5..10"), "{e}");
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.run_ranges = vec![(0, 11)];
    assert_eq!(invalid_field(Stats::try_from(f)), "run_ranges");
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.run_ranges = vec![(4, 2)];
    assert_eq!(invalid_field(Stats::try_from(f)), "run_ranges");
    // An exclusion of a mode that has no statistics.
    assert_eq!(
        invalid_field(Stats::try_from(file(&[Mode::Kf]))),
        "exclusions"
    );
    let mut f = file(&[Mode::Standalone, Mode::Kf]);
    f.format = "other/1".to_string();
    assert!(matches!(
        Stats::try_from(f),
        Err(SimError::StatsFormat { .. })
    ));
}

#[test]
fn the_paper_scenario_keeps_its_fingerprint() {
    // What stats.json and summary.json of `configs/paper.toml` have always recorded.
    assert_eq!(
        scenario_fingerprint(&crate::Scenario::paper_default()),
        "cb1cc3bbce788e42"
    );
}

#[test]
fn shard_range_refuses_shard_zero_and_count_zero() {
    for (index, count) in [(0, 3), (1, 0), (4, 3)] {
        let e = shard_range(10, index, count).unwrap_err();
        assert!(
            matches!(e, SimError::StatsShard { index: i, count: c } if (i, c) == (index, count)),
            "{e:?}"
        );
        // The message names the shard given.
        assert!(
            e.to_string()
                .starts_with(&format!("shard {index}/{count}:")),
            "{e}"
        );
    }
    assert_eq!(shard_range(10, 1, 3).unwrap(), (0, 3));
    assert_eq!(shard_range(10, 3, 3).unwrap(), (6, 10));
    // No overflow for huge run counts.
    assert_eq!(
        shard_range(u64::MAX, 2, 2).unwrap(),
        (u64::MAX / 2, u64::MAX)
    );
}
