//! The protocol's text reports: `summary.md`'s tables and `frames.csv`'s rows.

use crate::labelled::{
    LabelFrame, LabelSet, LabelSide, LaneCensus, LaneRates, LaneTotals, NEAR_MISS_FRACTION,
    StageCensus,
};

use super::{DEFAULT_NAME, FULL_CEILING_NAME, FullSplitRates, SplitRates, Summary};
use crate::labelled::FullRates;

/// The census table (`--census`): per set and overall, development part, default configuration.
pub(super) fn render_census(censuses: &[(String, StageCensus)]) -> String {
    let mut md = String::from(
        "\n## Where the default loses the development part's ego lanes (`--census`)\n\n\
         Label lanes on frames with a joint initialisation, by the TuSimple rule \
         (`lane_eval::labelled::census_lanes`).\n\n\
         | set | label lanes | matched | … found by the refinement | no Hough candidate | \
         … no edge near the label | candidate not chosen | lost after the choice | \
         not classified |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut total = StageCensus::default();
    let row = |name: &str, c: &StageCensus| {
        format!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.label_lanes,
            c.matched,
            c.found_by_refinement,
            c.no_candidate,
            c.no_edge_near_label,
            c.not_chosen,
            c.lost_after_choice,
            c.not_classified
        )
    };
    for (name, c) in censuses {
        md += &row(name, c);
        total.add(c);
    }
    md += &row("**overall**", &total);
    md
}

/// Header of `frames.csv` (one row per scored ego side of every frame, default configuration).
pub const FRAMES_CSV_HEADER: &str = "set,file,split,side,label,predicted,tusimple_accuracy,\
tusimple_matched,aly_matched,false_positive,mean_abs_error_px,census_stage\n";

/// The `frames.csv` rows of one frame from its sides' scores `sides` (left, right;
/// [`crate::labelled::score_sides`]): one per ego side that the scorer scores (a label lane in
/// the scored rows, or a prediction on a side without one); empty fields where there is no label lane (accuracy, matches) or no
/// prediction (error); `false_positive` names the kind of an unmatched prediction
/// ([`crate::labelled::FalsePositives`]), empty otherwise; `census_stage` the stage where the
/// side's label lane is lost ([`crate::labelled::LaneStage`]) when `census` (the set's, with
/// `--census`: development part) classifies the frame at `position`, empty otherwise.
pub(super) fn side_rows(
    set: &LabelSet,
    f: &LabelFrame,
    position: usize,
    dev: bool,
    sides: &[LaneTotals; 2],
    census: &[LaneCensus],
) -> String {
    let mut rows = String::new();
    for (k, (side, name)) in [(LabelSide::Left, "left"), (LabelSide::Right, "right")]
        .into_iter()
        .enumerate()
    {
        let t = &sides[k];
        if t.label_lanes + t.predicted_lanes == 0 {
            continue;
        }
        let fp = &t.false_positives;
        let kind = [
            (fp.unlabelled_side, "unlabelled_side"),
            (fp.other_marking, "other_marking"),
            (fp.near, "near"),
            (fp.far, "far"),
        ]
        .into_iter()
        .find(|(n, _)| *n > 0)
        .map_or("", |(_, kind)| kind);
        let labelled = t.label_lanes > 0;
        let on_label = |v: String| if labelled { v } else { String::new() };
        let error = if t.abs_err_points > 0 {
            format!("{:.2}", t.abs_err_sum_px / t.abs_err_points as f64)
        } else {
            String::new()
        };
        let stage = census
            .iter()
            .find(|c| c.position == position && c.side == side)
            .map_or("", |c| c.stage.name());
        rows += &format!(
            "{},{},{},{name},{},{},{},{},{},{kind},{error},{stage}\n",
            csv_field(&set.set),
            csv_field(&f.file),
            if dev { "dev" } else { "hold-out" },
            u8::from(labelled),
            t.predicted_lanes,
            on_label(format!("{:.4}", t.tusimple_acc_sum)),
            on_label(t.tusimple_matched.to_string()),
            on_label(t.aly_matched.to_string()),
        );
    }
    rows
}

/// `v` as one CSV field (RFC 4180): quoted, with its quotes doubled, when it holds a comma, a
/// quote or a line break.
fn csv_field(v: &str) -> std::borrow::Cow<'_, str> {
    if v.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", v.replace('"', "\"\"")).into()
    } else {
        v.into()
    }
}

fn pct(x: f64) -> String {
    format!("{:.1}", 100.0 * x)
}

/// Which part of a set's figures a table row shows.
type Pick = fn(&SplitRates) -> &LaneRates;

pub(super) fn render_markdown(s: &Summary, dev_only: bool, command: &str) -> String {
    let mut md = String::new();
    md += &format!("# Lane tracker on real labelled frames (`{command}`)\n\n");
    md += &format!(
        "Ego lanes; label points below {:.0} % of the height. TuSimple: point within {} px at 1280 px \
         width (scaled, slope-corrected), lane matched at ≥ {:.0} % of its points; accuracy, FP and FN \
         in %. Aly: median nearest-point distance ≤ {} px at 640 px width; detection rate and false \
         detections per label lane in %. dev = first {:.0} % of each set's frames, hold-out = the rest \
         (never used for tuning).\n\n",
        100.0 * s.rules.eval_top_fraction,
        s.rules.tusimple_px_at_1280,
        100.0 * s.rules.tusimple_match_fraction,
        s.rules.aly_px_at_640,
        100.0 * s.dev_fraction
    );
    let splits: &[(&str, Pick)] = if dev_only {
        &[("dev", |r| &r.dev)]
    } else {
        &[
            ("all", |r| &r.all),
            ("dev", |r| &r.dev),
            ("hold-out", |r| &r.holdout),
        ]
    };
    md += "| set | kind | frames (longest clip) | config | split | lanes | TuSimple acc | FP | FN | Aly det. | Aly false/label | mean err px |\n";
    md += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let row = |md: &mut String,
               set: &str,
               kind: &str,
               frames: &str,
               cfg: &str,
               split: &str,
               r: &LaneRates| {
        *md += &format!(
            "| {set} | {kind} | {frames} | {cfg} | {split} | {} | {} | {} | {} | {} | {} | {:.2} |\n",
            r.label_lanes,
            pct(r.tusimple_accuracy),
            pct(r.tusimple_fp),
            pct(r.tusimple_fn),
            pct(r.aly_detection_rate),
            pct(r.aly_false_per_label),
            r.mean_abs_error_px
        );
    };
    for set in &s.sets {
        for (cfg, rates) in &set.results {
            for (split, pick) in splits {
                row(
                    &mut md,
                    &set.set,
                    &set.kind,
                    &format!("{} ({})", set.frames, set.longest_clip),
                    cfg,
                    split,
                    pick(rates),
                );
            }
        }
    }
    let frames: usize = s.sets.iter().map(|x| x.frames).sum();
    for (cfg, rates) in &s.overall {
        for (split, pick) in splits {
            row(
                &mut md,
                "**overall**",
                "",
                &frames.to_string(),
                cfg,
                split,
                pick(rates),
            );
        }
    }
    md += &render_false_positives(s, splits);
    md
}

/// The full rule's table ([`crate::labelled::full_rule`]): per set and overall, every
/// configuration it scores, hold-out and development parts (the development part alone with
/// `dev_only`), with the near band's accuracy of the same predictions beside it.
pub(super) fn render_full_rule(s: &Summary, dev_only: bool) -> String {
    type FullPick = fn(&FullSplitRates) -> &FullRates;
    let splits: &[(&str, FullPick, Pick)] = if dev_only {
        &[("dev", |r| &r.dev, |r| &r.dev)]
    } else {
        &[
            ("hold-out", |r| &r.holdout, |r| &r.holdout),
            ("dev", |r| &r.dev, |r| &r.dev),
        ]
    };
    let mut md = format!(
        "\n## The full rule (TuSimple's own: every labelled row)\n\n\
         Every labelled row of each ego lane is scored (not only the near band's); the point \
         tolerance is slope-corrected from the line fitted to the whole label; a labelled row \
         outside the prediction's row extent (± {} px of the working frame) is a wrong point; a \
         lane is matched at ≥ {:.0} % correct points. `near acc`: the near band's TuSimple \
         accuracy of the same predictions (above). `unreached`: of the label points of predicted \
         lanes, those on rows the prediction does not reach. Extents: the tracker's, the rows of \
         the points behind each estimate; a candidate's, the rows searched; the ceiling's, the \
         rows it was fitted on. `{FULL_CEILING_NAME}`: a parabola over each whole label lane \
         (the model's own bound); `ceiling`: the near band's, fitted on the ROI rows. The peer's \
         predictions carry no extent and are not scored here. In %.\n\n\
         | set | config | split | lanes | near acc | full acc | FP | FN | unreached |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        s.full_rule_reach_working_px,
        100.0 * s.rules.tusimple_match_fraction,
    );
    let named = s
        .sets
        .iter()
        .map(|set| (set.set.as_str(), &set.full_rule, &set.results))
        .chain([("**overall**", &s.overall_full_rule, &s.overall)]);
    for (name, full, near) in named {
        for (cfg, rates) in full {
            for (split, pick_full, pick_near) in splits {
                let r = pick_full(rates);
                let near_acc = near
                    .get(cfg)
                    .map_or_else(|| "—".to_owned(), |n| pct(pick_near(n).tusimple_accuracy));
                md += &format!(
                    "| {name} | {cfg} | {split} | {} | {near_acc} | {} | {} | {} | {} |\n",
                    r.label_lanes,
                    pct(r.tusimple_accuracy),
                    pct(r.tusimple_fp),
                    pct(r.tusimple_fn),
                    pct(r.unreached_fraction)
                );
            }
        }
    }
    md
}

/// The default's unmatched predictions by kind ([`crate::labelled::FalsePositives`]), per set
/// and overall, for each of `splits`.
fn render_false_positives(s: &Summary, splits: &[(&str, Pick)]) -> String {
    let mut md = format!(
        "\nFalse positives of the default (TuSimple: predictions not matched) by what they lie on: \
         a side with no label lane; another labelled marking (the other side's label or an unscored \
         one: a neighbour's mark, or the sides swapped); near (≥ {:.0} % of the label's points within \
         the tolerance); far (the rest).\n\n\
         | set | split | predictions | false positives | no label on the side | another marking | near | far |\n\
         |---|---|---|---|---|---|---|---|\n",
        100.0 * NEAR_MISS_FRACTION
    );
    let named = s
        .sets
        .iter()
        .filter_map(|set| Some((set.set.as_str(), set.results.get(DEFAULT_NAME)?)))
        .chain(s.overall.get(DEFAULT_NAME).map(|r| ("**overall**", r)));
    for (name, rates) in named {
        for (split, pick) in splits {
            let r = pick(rates);
            let k = r.false_positives;
            md += &format!(
                "| {name} | {split} | {} | {} | {} | {} | {} | {} |\n",
                r.predicted_lanes,
                k.total(),
                k.unlabelled_side,
                k.other_marking,
                k.near,
                k.far
            );
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use crate::labelled::{
        LabelFrame, LabelLane, LabelSet, LabelSide, LaneCensus, LaneStage, SceneKind, ScoringRules,
    };

    use crate::labelled::{EgoPrediction, PredictedLane, score_sides};

    use super::{FRAMES_CSV_HEADER, side_rows};

    /// `frames.csv`'s rows of frame `f` at `position` for prediction `p`, scored as `eval-lanes`
    /// scores it.
    fn rows(
        f: &LabelFrame,
        position: usize,
        dev: bool,
        p: &EgoPrediction,
        census: &[LaneCensus],
    ) -> String {
        let set = set();
        let sides = score_sides(f, set.width, set.height, p, &ScoringRules::default());
        side_rows(&set, f, position, dev, &sides, census)
    }

    fn set() -> LabelSet {
        LabelSet {
            schema: 1,
            set: "my,set".into(),
            kind: SceneKind::Road,
            source: String::new(),
            licence: String::new(),
            width: 320,
            height: 240,
            frames: Vec::new(),
        }
    }

    #[test]
    fn frame_rows_give_one_row_per_scored_side_with_its_outcome() {
        // Left label x = 100 on rows 150..240, right label only in the far field (not scored).
        let f = LabelFrame {
            index: 3,
            file: "frames/a\"b.png".into(),
            clip: "c".into(),
            lanes: vec![
                LabelLane {
                    side: LabelSide::Left,
                    points: (150..240).map(|y| [100.0, f64::from(y)]).collect(),
                },
                LabelLane {
                    side: LabelSide::Right,
                    points: (0..40).map(|y| [250.0, f64::from(y)]).collect(),
                },
            ],
        };
        let columns = FRAMES_CSV_HEADER.trim_end().split(',').count();
        // On the label: matched; the far-field right side gives no row.
        let got = rows(
            &f,
            3,
            true,
            &[
                Some(PredictedLane::without_extent([0.0, 0.0, 101.0])),
                Some(PredictedLane::without_extent([0.0, 0.0, 0.0])),
            ],
            &[],
        );
        assert_eq!(
            got,
            "\"my,set\",\"frames/a\"\"b.png\",dev,left,1,1,1.0000,1,1,,1.00,\n"
        );
        // The census's stage of this frame's side, not of another frame's or side's.
        let census = |position, side, stage| LaneCensus {
            position,
            side,
            stage,
        };
        let stages = [
            census(2, LabelSide::Left, LaneStage::NotChosen),
            census(3, LabelSide::Right, LaneStage::NoCandidate),
            census(3, LabelSide::Left, LaneStage::FoundByRefinement),
        ];
        let got = rows(
            &f,
            3,
            true,
            &[Some(PredictedLane::without_extent([0.0, 0.0, 101.0])), None],
            &stages,
        );
        assert!(got.ends_with(",1.00,found_by_refinement\n"), "{got}");
        let got = rows(&f, 2, true, &[None, None], &stages);
        assert!(got.ends_with(",,not_chosen\n"), "{got}");
        // 40 px off: a far false positive; no prediction: a missed label with no error.
        let got = rows(
            &f,
            3,
            false,
            &[Some(PredictedLane::without_extent([0.0, 0.0, 140.0])), None],
            &[],
        );
        assert_eq!(
            got,
            "\"my,set\",\"frames/a\"\"b.png\",hold-out,left,1,1,0.0000,0,0,far,40.00,\n"
        );
        let got = rows(&f, 3, false, &[None, None], &[]);
        assert!(got.ends_with(",hold-out,left,1,0,0.0000,0,0,,,\n"), "{got}");
        // Only the left label: a right prediction is scored on its own row, unlabelled.
        let mut left_only = f.clone();
        left_only.lanes.truncate(1);
        let got = rows(
            &left_only,
            3,
            true,
            &[None, Some(PredictedLane::without_extent([0.0, 0.0, 250.0]))],
            &[],
        );
        let lines: Vec<&str> = got.lines().collect();
        assert_eq!(lines.len(), 2);
        assert!(
            lines[1].ends_with(",dev,right,0,1,,,,unlabelled_side,,"),
            "{got}"
        );
        // Every row has the header's columns (the quoted fields hold commas).
        for l in lines {
            let unquoted = l.replace("\"my,set\"", "s");
            assert_eq!(unquoted.split(',').count(), columns, "{l}");
        }
    }
}
