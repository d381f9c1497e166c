//! Labels from the two public lane benchmarks' formats, read into this crate's schema, so that a
//! user's own labelled recordings in either format are scored by `nav-app eval-lanes` like
//! the shared sets (`nav-app import-lanes`, [`crate::import_set`], does the file work around these functions).
//!
//! ## TuSimple (`label_data_*.json`, `test_label.json`)
//! One JSON object per line: `{"lanes": [[x₀, x₁, …], …], "h_samples": [y₀, y₁, …],
//! "raw_file": "clips/…/20.jpg"}`; lane `k`'s point on row `h_samples[i]` is `lanes[k][i]`, and a
//! negative column (the benchmark writes −2) means no point on that row. Other fields (the test
//! set's `run_time`) are ignored. The image is `raw_file` under the label file's directory.
//!
//! ## CULane (`list/*.txt` and `*.lines.txt`)
//! A list file names one image per line, relative to the data root (`/driver_…/…MP4/00000.jpg`,
//! with a leading slash; `train_gt.txt`'s further columns are ignored). Each image's labels are in
//! the file beside it with the extension replaced by `.lines.txt`: one lane per line, its points
//! as `x y x y …`.
//!
//! ## Both
//! Coordinates are the image's own pixels (x column, y row), as this schema's. Points outside the
//! frame are dropped and the rest sorted by row; a lane left with fewer than 2 points is dropped.
//! The **ego pair** is chosen by the rule the shared sets were converted with
//! (`fixtures/real/README.md`, "Ego pair"; [`assign_sides`]). Frames of one clip (TuSimple: each
//! labelled frame is its clip's last; CULane: one video's frames) share the `clip` id of their
//! image's directory, so `eval-lanes` tracks CULane's videos as sequences.
//!
//! A record that cannot be read is reported as a [`Skipped`] (file, line, reason) and the others
//! are kept: one bad line does not lose a set.

use serde::Deserialize;

use super::{LabelLane, LabelSide};

/// One labelled image read from a benchmark's label file, before its ego pair is chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedFrame {
    /// The image, relative to the format's image root (TuSimple: the label file's directory;
    /// CULane: the data root), without a leading `/`.
    pub image: String,
    /// Clip id: the image's directory.
    pub clip: String,
    /// The labelled markings, `[x_px, y_px]` each, in the file's order.
    pub lanes: Vec<Vec<[f64; 2]>>,
}

/// A record that was not imported, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// The file holding it.
    pub path: String,
    /// Its line, 1-based (0: the whole file).
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

impl std::fmt::Display for Skipped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.path, self.reason)
        } else {
            write!(f, "{}:{}: {}", self.path, self.line, self.reason)
        }
    }
}

/// One line of a TuSimple label file.
#[derive(Deserialize)]
struct TusimpleRecord {
    lanes: Vec<Vec<f64>>,
    h_samples: Vec<f64>,
    raw_file: String,
}

impl ImportedFrame {
    /// A frame of `image` (a `/`-separated relative path) with its `lanes`; its clip is the
    /// image's directory (`""` for a bare file name).
    pub fn new(image: String, lanes: Vec<Vec<[f64; 2]>>) -> Self {
        let clip = image.rsplit_once('/').map_or("", |(dir, _)| dir).to_owned();
        Self { image, clip, lanes }
    }
}

/// A TuSimple label file's records (`name` is used in the skipped records' reports).
pub fn parse_tusimple(name: &str, text: &str) -> (Vec<ImportedFrame>, Vec<Skipped>) {
    let mut frames = Vec::new();
    let mut skipped = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let skip = |reason: String| Skipped {
            path: name.to_owned(),
            line: k + 1,
            reason,
        };
        if line.trim().is_empty() {
            continue;
        }
        let record: TusimpleRecord = match serde_json::from_str(line) {
            Ok(r) => r,
            Err(e) => {
                skipped.push(skip(format!("not a TuSimple label record: {e}")));
                continue;
            }
        };
        if let Some((i, lane)) = record
            .lanes
            .iter()
            .enumerate()
            .find(|(_, lane)| lane.len() != record.h_samples.len())
        {
            skipped.push(skip(format!(
                "lane {i} has {} columns for {} h_samples",
                lane.len(),
                record.h_samples.len()
            )));
            continue;
        }
        let image = record.raw_file.trim_start_matches('/').to_owned();
        if image.is_empty() {
            skipped.push(skip("empty raw_file".to_owned()));
            continue;
        }
        let lanes = record
            .lanes
            .iter()
            .map(|xs| {
                xs.iter()
                    .zip(&record.h_samples)
                    .filter(|&(&x, _)| x >= 0.0)
                    .map(|(&x, &y)| [x, y])
                    .collect()
            })
            .collect();
        frames.push(ImportedFrame::new(image, lanes));
    }
    (frames, skipped)
}

/// A CULane list file's images, relative to the data root (first column of each non-empty line,
/// its leading `/` removed).
pub fn parse_culane_list(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(|p| p.trim_start_matches('/').to_owned())
        .filter(|p| !p.is_empty())
        .collect()
}

/// The label file of a CULane image: its extension replaced by `.lines.txt`.
pub fn culane_lines_file(image: &str) -> String {
    let stem = match image.rsplit_once('.') {
        Some((stem, ext)) if !ext.contains('/') => stem,
        _ => image,
    };
    format!("{stem}.lines.txt")
}

/// The lanes of one CULane `.lines.txt` (`name` is used in the error): one lane per non-empty
/// line, `x y` pairs. A token that is not a number, or an odd count, is refused with its line.
pub fn parse_culane_lines(name: &str, text: &str) -> Result<Vec<Vec<[f64; 2]>>, Skipped> {
    let mut lanes = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let bad = |reason: String| Skipped {
            path: name.to_owned(),
            line: k + 1,
            reason,
        };
        let mut values = Vec::new();
        for token in line.split_whitespace() {
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => values.push(v),
                _ => return Err(bad(format!("`{token}` is not a coordinate"))),
            }
        }
        if values.is_empty() {
            continue;
        }
        if values.len() % 2 != 0 {
            return Err(bad(format!(
                "{} numbers: a lane is x y pairs",
                values.len()
            )));
        }
        lanes.push(values.chunks_exact(2).map(|p| [p[0], p[1]]).collect());
    }
    Ok(lanes)
}

/// A lane's column at the bottom row `height − 1`: the least-squares line `x(y)` through its
/// lowest third of points (at least 2, at most 15), extrapolated; the lowest point's column when
/// they share one row. `points` sorted by row, at least one.
fn bottom_column(points: &[[f64; 2]], height: usize) -> f64 {
    let k = (points.len() / 3).clamp(2, 15).min(points.len());
    let low = &points[points.len() - k..];
    let n = low.len() as f64;
    let mean_y = low.iter().map(|p| p[1]).sum::<f64>() / n;
    let mean_x = low.iter().map(|p| p[0]).sum::<f64>() / n;
    let syy: f64 = low.iter().map(|p| (p[1] - mean_y).powi(2)).sum();
    let last = low[low.len() - 1][0];
    if syy < 1e-9 {
        return last;
    }
    let sxy: f64 = low.iter().map(|p| (p[1] - mean_y) * (p[0] - mean_x)).sum();
    let slope = sxy / syy;
    mean_x + slope * ((height as f64 - 1.0) - mean_y)
}

/// The lanes of a `width × height` frame as this schema's: points outside the frame dropped, the
/// rest sorted by row, lanes with fewer than 2 points dropped; ordered by their column at the
/// bottom row (the least-squares line through their lowest third of points, 2 to 15,
/// extrapolated); the lane with the largest one left of the centre column `(width − 1)/2` is
/// `left`, the one with the smallest at or right of it `right`, every other one `other`.
pub fn assign_sides(lanes: &[Vec<[f64; 2]>], width: usize, height: usize) -> Vec<LabelLane> {
    let (w, h) = (width as f64, height as f64);
    let mut kept: Vec<(f64, Vec<[f64; 2]>)> = lanes
        .iter()
        .filter_map(|lane| {
            let mut points: Vec<[f64; 2]> = lane
                .iter()
                .copied()
                .filter(|&[x, y]| (-0.5..=w - 0.5).contains(&x) && (-0.5..=h - 0.5).contains(&y))
                .collect();
            points.sort_by(|a, b| a[1].total_cmp(&b[1]));
            (points.len() >= 2).then(|| (bottom_column(&points, height), points))
        })
        .collect();
    kept.sort_by(|a, b| a.0.total_cmp(&b.0));
    let centre = (w - 1.0) / 2.0;
    let left = kept.iter().rposition(|(x, _)| *x < centre);
    let right = kept.iter().position(|(x, _)| *x >= centre);
    kept.into_iter()
        .enumerate()
        .map(|(i, (_, points))| LabelLane {
            side: if Some(i) == left {
                LabelSide::Left
            } else if Some(i) == right {
                LabelSide::Right
            } else {
                LabelSide::Other
            },
            points,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tusimple_records_give_their_rows_points_and_skip_what_cannot_be_read() {
        let text = concat!(
            r#"{"lanes": [[-2, 100, 90], [200, 210, -2]], "h_samples": [10, 20, 30], "raw_file": "clips/a/1/20.jpg", "run_time": 5}"#,
            "\n",
            "{not json\n",
            "\n",
            r#"{"lanes": [[1, 2]], "h_samples": [10, 20, 30], "raw_file": "clips/a/2/20.jpg"}"#,
            "\n",
            r#"{"lanes": [], "h_samples": [], "raw_file": "/top.jpg"}"#,
        );
        let (frames, skipped) = parse_tusimple("labels.json", text);
        assert_eq!(frames.len(), 2);
        assert_eq!(frames[0].image, "clips/a/1/20.jpg");
        assert_eq!(frames[0].clip, "clips/a/1");
        // −2 is no point: each lane keeps only its labelled rows, paired with their h_sample.
        assert_eq!(
            frames[0].lanes,
            vec![
                vec![[100.0, 20.0], [90.0, 30.0]],
                vec![[200.0, 10.0], [210.0, 20.0]]
            ]
        );
        // A leading slash is dropped; a file at the root is its own clip "".
        assert_eq!(
            (frames[1].image.as_str(), frames[1].clip.as_str()),
            ("top.jpg", "")
        );
        let lines: Vec<usize> = skipped.iter().map(|s| s.line).collect();
        assert_eq!(lines, vec![2, 4], "{skipped:?}");
        assert!(
            skipped[1].reason.contains("2 columns for 3 h_samples"),
            "{}",
            skipped[1]
        );
        assert!(
            skipped[0].to_string().starts_with("labels.json:2: "),
            "{}",
            skipped[0]
        );
    }

    #[test]
    fn culane_lists_and_lines_files_read_as_their_format_says() {
        let list = "/driver_100_30frame/05251517_0433.MP4/00000.jpg /laneseg/x.png 1 1 0 0\n\n\
                    driver_23_30frame/v.MP4/00030.jpg\n";
        assert_eq!(
            parse_culane_list(list),
            vec![
                "driver_100_30frame/05251517_0433.MP4/00000.jpg",
                "driver_23_30frame/v.MP4/00030.jpg"
            ]
        );
        assert_eq!(
            culane_lines_file("driver_100_30frame/05251517_0433.MP4/00000.jpg"),
            "driver_100_30frame/05251517_0433.MP4/00000.lines.txt"
        );
        let lanes =
            parse_culane_lines("a.lines.txt", "10.5 590 20 580 \n\n-3 590 4 580\n").expect("valid");
        assert_eq!(
            lanes,
            vec![
                vec![[10.5, 590.0], [20.0, 580.0]],
                vec![[-3.0, 590.0], [4.0, 580.0]]
            ]
        );
        let odd = parse_culane_lines("a.lines.txt", "1 2\n1 2 3\n").expect_err("odd count");
        assert_eq!((odd.line, odd.path.as_str()), (2, "a.lines.txt"));
        let nan = parse_culane_lines("a.lines.txt", "1 x\n").expect_err("not a number");
        assert!(nan.to_string().starts_with("a.lines.txt:1: `x`"), "{nan}");
    }

    #[test]
    fn the_ego_pair_is_the_nearest_lane_each_side_of_the_centre_at_the_bottom_row() {
        // A 100 × 50 frame, centre column 49.5. Lines x = x_bottom + s·(49 − y) sampled on rows
        // 20..=45, so each lane's bottom column is x_bottom whatever its slope.
        let line = |x_bottom: f64, s: f64| -> Vec<[f64; 2]> {
            (20..=45)
                .rev()
                .map(|y| [x_bottom + s * (49.0 - f64::from(y)), f64::from(y)])
                .collect()
        };
        let lanes = vec![
            line(70.0, -0.5),                  // right, nearest the centre on its side
            line(10.0, 1.0),                   // other (left of the left one)
            line(45.0, 0.9),                   // left: its top leans far right, its bottom decides
            line(95.0, -1.0),                  // other
            vec![[50.0, 30.0], [500.0, 40.0]], // one point inside the frame: dropped
        ];
        let out = assign_sides(&lanes, 100, 50);
        let sides: Vec<LabelSide> = out.iter().map(|l| l.side).collect();
        assert_eq!(
            sides,
            vec![
                LabelSide::Other,
                LabelSide::Left,
                LabelSide::Right,
                LabelSide::Other
            ]
        );
        // Points sorted by row, the frame's rule kept.
        assert!(
            out.iter()
                .all(|l| l.points.windows(2).all(|p| p[0][1] <= p[1][1]))
        );
        assert_eq!(out[1].points[0], [45.0 + 0.9 * 29.0, 20.0]);
        // A lane exactly on the centre column at the bottom is the right boundary.
        let on_centre = assign_sides(&[line(49.5, 0.3)], 100, 50);
        assert_eq!(on_centre[0].side, LabelSide::Right);
        // Only lanes on one side: that side alone.
        let left_only = assign_sides(&[line(20.0, 0.5), line(30.0, 0.5)], 100, 50);
        let sides: Vec<LabelSide> = left_only.iter().map(|l| l.side).collect();
        assert_eq!(sides, vec![LabelSide::Other, LabelSide::Left]);
    }

    #[test]
    fn the_bottom_column_extrapolates_the_lowest_third_only() {
        // Lower 15 rows on x = 2y; rows above bend away: only the lowest third (here 15 of 45) count.
        let mut points: Vec<[f64; 2]> = (0..30).map(|y| [1000.0, f64::from(y)]).collect();
        points.extend((30..45).map(|y| [2.0 * f64::from(y), f64::from(y)]));
        assert!((bottom_column(&points, 60) - 118.0).abs() < 1e-9);
        // Two points on one row: the lowest one's column.
        assert_eq!(bottom_column(&[[3.0, 7.0], [5.0, 7.0]], 60), 5.0);
    }
}
