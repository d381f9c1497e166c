//! Periodic stripes along a row (an addition beyond the paper): the edge pixels of a crosswalk
//! (a "zebra"), of road text and of railings are dropped before the Hough vote.
//!
//! A lane mark crosses a row once: a rising edge (dark → bright to the right) and, a mark width
//! later, a falling one. Two marks of one lane (a double line) cross it twice, close together;
//! the marks of neighbouring lanes are a lane width apart, many mark widths. A crosswalk's
//! stripes, the strokes of painted letters and the bars of a railing cross the same row many
//! times, **bright and dark in turn at a steady pitch**: stripes of about one width, separated
//! by gaps of about that width. Their stripes run along the road too (a crosswalk's lie in the
//! driving direction, a letter's long strokes nearly so), so the edge direction does not tell
//! them from marks, and each one alone is a well-formed bright stripe. What tells them apart is
//! the row they share, and the rows above and below it: a crosswalk or a word spans several
//! rows. [`drop_periodic_stripes`] finds, in every row, each chain of at least `min_stripes`
//! bright stripes in which every stripe is `min_width_px..=max_width_px` wide, neighbours
//! differ in width by at most `max_width_ratio` and the dark gap between neighbours is at most
//! `max_gap_to_width` times the wider one. A chain counts only where a chain of an adjacent row
//! overlaps its columns (texture and sensor noise make chains too, at random, one row here and
//! one there; a mark among them would lose its pixels in those rows), and then the edge pixels
//! of its row and of the two adjacent rows lose every pixel from the chain's first rising edge
//! to its last falling edge (a row whose chain broke on one missed edge is covered by its
//! neighbours').
//!
//! An edge is a run of edge pixels of one polarity on consecutive columns (a Sobel response is
//! 2–3 px wide); its column is the run's middle. A stripe is a rising edge followed at once by
//! a falling one. Edges that form no stripe (a lone step, a crack across a gap) neither join
//! nor break a chain; a stripe too narrow or too wide breaks it.
//!
//! Known gap: a stripe running exactly vertically in the image (straight ahead of the camera)
//! has no lean, so its edges are no edge pixels ([`crate::GradientParams`]); a crosswalk's chain
//! breaks there when the stripes beside it are more than `max_gap_to_width` widths apart, and
//! what is left of a near-vertical stripe with one edge can still vote. And near the camera a
//! crosswalk's stripes are wide: fewer than `min_stripes` of them may fit in a row.

use crate::edges::EdgeBuffer;

/// Bit of [`crate::EdgePixel::magnitude`] used as a temporary "drop" flag (magnitudes are at
/// most 2040 < 2¹¹).
const DROP_BIT: u16 = 1 << 15;
/// Bits of a real magnitude.
const MAG_MASK: u16 = (1 << 11) - 1;
/// Most edges examined in one row (a 640-px row holds at most 320 alternating edges; a row with
/// more is examined up to this many, the rest kept).
const MAX_EDGES_PER_ROW: usize = 256;
/// Most chains dropped in one row.
const MAX_CHAINS_PER_ROW: usize = 16;

/// What [`drop_periodic_stripes`] calls a periodic chain. Widths are along the row, px.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodicStripeParams {
    /// Fewest stripes in a chain (≥ 3: a double line is two stripes and is never dropped).
    pub min_stripes: usize,
    /// Narrowest stripe of a chain, px (between the middles of its two edges).
    pub min_width_px: f64,
    /// Widest stripe of a chain, px.
    pub max_width_px: f64,
    /// Largest ratio of two neighbouring stripes' widths (≥ 1).
    pub max_width_ratio: f64,
    /// Largest dark gap between neighbours, in widths of the wider one (> 0).
    pub max_gap_to_width: f64,
}

impl Default for PeriodicStripeParams {
    /// Three stripes 2–48 px wide, neighbours within a factor 2 in width and at most three
    /// widths apart.
    fn default() -> Self {
        Self {
            min_stripes: 3,
            min_width_px: 2.0,
            max_width_px: 48.0,
            max_width_ratio: 2.0,
            max_gap_to_width: 3.0,
        }
    }
}

/// One edge: a run of same-polarity pixels on consecutive columns of a row.
#[derive(Debug, Clone, Copy, Default)]
struct Edge {
    first_col_px: u16,
    last_col_px: u16,
    rising: bool,
}

impl Edge {
    fn mid_col_px(&self) -> f64 {
        0.5 * (f64::from(self.first_col_px) + f64::from(self.last_col_px))
    }
}

/// Drops the edge pixels of periodic stripe chains confirmed by an adjacent row, on their row
/// and the two adjacent ones (module docs); returns the number dropped. `edges` must come from
/// [`crate::GradientDetector::detect`] (rows contiguous, columns increasing within a row,
/// polarity from [`crate::EdgePixel::gx`]). Pixels of both classes form the edges.
/// `min_stripes = 0` drops nothing. No allocation.
pub fn drop_periodic_stripes(edges: &mut EdgeBuffer, params: &PeriodicStripeParams) -> usize {
    if params.min_stripes == 0 {
        return 0;
    }
    let mut row_edges = [Edge::default(); MAX_EDGES_PER_ROW];
    // The last four rows' chains (a ring, by row order in the buffer).
    let mut ring = [RowChains::default(); 4];
    let mut any = false;
    let px = edges.pixels_mut();
    let n = px.len();
    let mut start = 0;
    let mut t = 0usize;
    while start < n {
        let end = crate::edges::row_end(px, start);
        // The row's edges.
        let mut m = 0;
        for p in &px[start..end] {
            let rising = p.gx > 0;
            if m > 0 {
                let last = &mut row_edges[m - 1];
                if last.rising == rising && p.col_px <= last.last_col_px.saturating_add(1) {
                    last.last_col_px = last.last_col_px.max(p.col_px);
                    continue;
                }
            }
            if m == MAX_EDGES_PER_ROW {
                break;
            }
            row_edges[m] = Edge {
                first_col_px: p.col_px,
                last_col_px: p.col_px,
                rising,
            };
            m += 1;
        }
        let cur = &mut ring[t % 4];
        *cur = RowChains {
            row_px: px[start].row_px,
            start,
            end,
            ..RowChains::default()
        };
        cur.count = find_chains(&row_edges[..m], params, &mut cur.spans);
        if t >= 1 {
            confirm(&mut ring, t - 1, t);
        }
        if t >= 2 {
            any |= drop_row(px, &ring, t - 2, t);
        }
        t += 1;
        start = end;
    }
    // The last two rows.
    if t >= 1 {
        confirm(&mut ring, t - 1, t - 1);
        if t >= 2 {
            any |= drop_row(px, &ring, t - 2, t - 1);
        }
        any |= drop_row(px, &ring, t - 1, t - 1);
    }
    if !any {
        return 0;
    }
    // `retain_flagged` keeps the flagged pixels: flip the flag.
    for p in edges.pixels_mut() {
        p.magnitude ^= DROP_BIT;
    }
    edges.retain_flagged(DROP_BIT, MAG_MASK)
}

/// One row's chains: their column spans, and which of them a chain on an adjacent row
/// overlaps.
#[derive(Debug, Clone, Copy, Default)]
struct RowChains {
    row_px: u16,
    /// The row's pixels in the buffer, `start..end`.
    start: usize,
    end: usize,
    spans: [(u16, u16); MAX_CHAINS_PER_ROW],
    count: usize,
    confirmed: [bool; MAX_CHAINS_PER_ROW],
}

impl RowChains {
    fn spans(&self) -> &[(u16, u16)] {
        &self.spans[..self.count]
    }
}

/// Whether the rows of ring positions `a` and `b` are adjacent image rows.
fn adjacent(ring: &[RowChains; 4], a: usize, b: usize) -> bool {
    ring[a % 4].row_px.abs_diff(ring[b % 4].row_px) == 1
}

fn overlap(a: (u16, u16), b: (u16, u16)) -> bool {
    a.0 <= b.1 && b.0 <= a.1
}

/// Marks the chains of row `t` (ring position) confirmed that overlap a chain on row `t − 1`
/// or `t + 1` (if those are adjacent image rows and `≤ last`).
fn confirm(ring: &mut [RowChains; 4], t: usize, last: usize) {
    let mut confirmed = [false; MAX_CHAINS_PER_ROW];
    for (k, &span) in ring[t % 4].spans().iter().enumerate() {
        let near = |u: usize| {
            adjacent(ring, t, u) && ring[u % 4].spans().iter().any(|&o| overlap(span, o))
        };
        confirmed[k] = (t >= 1 && near(t - 1)) || (t < last && near(t + 1));
    }
    ring[t % 4].confirmed = confirmed;
}

/// Flags the pixels of row `t` (ring position) inside a confirmed chain of row `t − 1`, `t` or
/// `t + 1` (adjacent image rows, `≤ last`); returns whether any was flagged.
fn drop_row(px: &mut [crate::EdgePixel], ring: &[RowChains; 4], t: usize, last: usize) -> bool {
    let this = &ring[t % 4];
    let mut any = false;
    for p in &mut px[this.start..this.end] {
        let inside = |u: usize| {
            let r = &ring[u % 4];
            (u == t || adjacent(ring, t, u))
                && r.spans()
                    .iter()
                    .zip(&r.confirmed)
                    .any(|(&(a, b), &c)| c && (a..=b).contains(&p.col_px))
        };
        if (t >= 1 && inside(t - 1)) || inside(t) || (t < last && inside(t + 1)) {
            p.magnitude |= DROP_BIT;
            any = true;
        }
    }
    any
}

/// A chain being grown, as indices into one row's edges.
#[derive(Debug, Clone, Copy)]
struct Chain {
    /// Its first stripe's rising edge.
    first: usize,
    /// Its stripes.
    count: usize,
    /// Its last stripe's falling edge.
    last: usize,
    /// Its last stripe's width, px.
    last_width_px: f64,
}

/// The column spans `[first, last]` of the periodic chains among one row's `edges`, written to
/// `out`; returns how many.
fn find_chains(edges: &[Edge], params: &PeriodicStripeParams, out: &mut [(u16, u16)]) -> usize {
    let mut found = 0;
    let mut close = |chain: Option<Chain>, found: &mut usize| {
        if let Some(c) = chain
            && c.count >= params.min_stripes
            && *found < out.len()
        {
            out[*found] = (edges[c.first].first_col_px, edges[c.last].last_col_px);
            *found += 1;
        }
    };
    let mut chain: Option<Chain> = None;
    let mut i = 0;
    while i + 1 < edges.len() {
        let (rise, fall) = (&edges[i], &edges[i + 1]);
        if !rise.rising || fall.rising {
            // Not a stripe (a lone step, a crack across the gap): neither part of a chain nor
            // a break in one.
            i += 1;
            continue;
        }
        let width = fall.mid_col_px() - rise.mid_col_px();
        let alone = Chain {
            first: i,
            count: 1,
            last: i + 1,
            last_width_px: width,
        };
        if !(params.min_width_px..=params.max_width_px).contains(&width) {
            close(chain.take(), &mut found);
            i += 2;
            continue;
        }
        chain = match chain {
            Some(c) => {
                let gap = rise.mid_col_px() - edges[c.last].mid_col_px();
                let within = |a: f64, b: f64, ratio: f64| a.max(b) <= ratio * a.min(b);
                let fits = within(c.last_width_px, width, params.max_width_ratio)
                    && gap <= params.max_gap_to_width * c.last_width_px.max(width);
                if fits {
                    Some(Chain {
                        count: c.count + 1,
                        last: i + 1,
                        last_width_px: width,
                        ..c
                    })
                } else {
                    close(Some(c), &mut found);
                    Some(alone)
                }
            }
            None => Some(alone),
        };
        i += 2;
    }
    close(chain, &mut found);
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EdgeClass, EdgePixel};

    /// `(first column, last column, rising)`: one run of edge pixels.
    type Run = (u16, u16, bool);

    /// Edge pixels of the given rows (increasing), each from its runs.
    fn rows(rows: &[(u16, Vec<Run>)]) -> EdgeBuffer {
        let mut edges = EdgeBuffer::with_capacity(1 << 14);
        for (row_px, runs) in rows {
            for &(a, b, rising) in runs {
                for col_px in a..=b {
                    edges.push(EdgePixel {
                        col_px,
                        row_px: *row_px,
                        magnitude: 200,
                        class: EdgeClass::RightLane,
                        gx: if rising { 100 } else { -100 },
                    });
                }
            }
        }
        edges
    }

    /// The same runs on rows 7 and 8 (a chain there confirms itself).
    fn twice(runs: &[Run]) -> EdgeBuffer {
        rows(&[(7, runs.to_vec()), (8, runs.to_vec())])
    }

    /// `n` stripes `width` px wide every `pitch` px from column `start` (edges 2 px wide).
    fn stripes(start: u16, n: u16, width: u16, pitch: u16) -> Vec<Run> {
        (0..n)
            .flat_map(|k| {
                let a = start + k * pitch;
                [(a, a + 1, true), (a + width, a + width + 1, false)]
            })
            .collect()
    }

    fn kept(edges: &EdgeBuffer) -> Vec<(u16, u16)> {
        edges
            .pixels()
            .iter()
            .map(|p| (p.row_px, p.col_px))
            .collect()
    }

    const FOUR: PeriodicStripeParams = PeriodicStripeParams {
        min_stripes: 4,
        min_width_px: 2.0,
        max_width_px: 48.0,
        max_width_ratio: 2.0,
        max_gap_to_width: 3.0,
    };

    #[test]
    fn a_crosswalk_is_dropped_and_a_double_line_and_lane_marks_are_kept() {
        // Five stripes 12 px wide, 14 px apart, on two rows: all dropped, the rest intact.
        let mut walk = twice(&stripes(20, 5, 12, 26));
        let n = walk.len();
        assert_eq!(drop_periodic_stripes(&mut walk, &FOUR), n);
        assert!(walk.is_empty());
        // A double line (two 4-px stripes 4 px apart) and a lane mark 80 px away: all kept,
        // magnitudes intact.
        let mut runs = stripes(40, 2, 4, 8);
        runs.extend(stripes(130, 1, 5, 0));
        let mut marks = twice(&runs);
        let before = kept(&marks);
        assert_eq!(drop_periodic_stripes(&mut marks, &FOUR), 0);
        assert_eq!(kept(&marks), before);
        assert!(marks.pixels().iter().all(|p| p.magnitude == 200));
        // Off: nothing dropped.
        let mut off = twice(&stripes(20, 5, 12, 26));
        let off_params = PeriodicStripeParams {
            min_stripes: 0,
            ..FOUR
        };
        assert_eq!(drop_periodic_stripes(&mut off, &off_params), 0);
    }

    #[test]
    fn a_lone_edge_in_a_gap_does_not_break_a_chain_but_a_misfit_stripe_does() {
        // A crack (a falling edge) in the gap between the first and second stripes: still one
        // chain of five, the crack inside it dropped too.
        let mut runs = stripes(20, 5, 12, 26);
        runs.push((40, 40, false));
        runs.sort_by_key(|r| r.0);
        let mut cracked = twice(&runs);
        let n = cracked.len();
        assert_eq!(drop_periodic_stripes(&mut cracked, &FOUR), n);
        // The third stripe three times as wide as the second: chains of two, one and two
        // stripes (the wide one alone), none of four: all kept.
        let mut runs = stripes(20, 2, 12, 26);
        runs.extend(stripes(72, 1, 36, 0));
        runs.extend(stripes(122, 2, 12, 26));
        let mut misfit = twice(&runs);
        assert_eq!(drop_periodic_stripes(&mut misfit, &FOUR), 0);
        // Gaps (between edge middles) of three widths and one pixel more: no chain; of three
        // widths: a chain.
        let mut sparse = twice(&stripes(0, 5, 6, 6 + 19));
        assert_eq!(drop_periodic_stripes(&mut sparse, &FOUR), 0);
        let mut dense = twice(&stripes(0, 5, 6, 6 + 18));
        let n = dense.len();
        assert_eq!(drop_periodic_stripes(&mut dense, &FOUR), n);
    }

    #[test]
    fn a_chain_counts_only_with_a_neighbour_row_and_then_covers_the_rows_beside_it() {
        let walk = stripes(20, 5, 12, 26);
        // The same stripes with the third one's falling edge missed: no chain of four.
        let mut broken = walk.clone();
        broken.remove(5);
        // One row alone (noise makes such chains): kept.
        let mut alone = rows(&[(7, walk.clone())]);
        assert_eq!(drop_periodic_stripes(&mut alone, &FOUR), 0);
        // Two chains two rows apart (no row between them in the buffer): kept.
        let mut apart = rows(&[(7, walk.clone()), (9, walk.clone())]);
        assert_eq!(drop_periodic_stripes(&mut apart, &FOUR), 0);
        // Chains on rows 8 and 9, the broken pattern on rows 6, 7, 10 and 11: rows 7 to 10 lose
        // the span, rows 6 and 11 (two rows from a chain) keep everything.
        let mut walk_rows = rows(&[
            (6, broken.clone()),
            (7, broken.clone()),
            (8, walk.clone()),
            (9, walk.clone()),
            (10, broken.clone()),
            (11, broken.clone()),
        ]);
        drop_periodic_stripes(&mut walk_rows, &FOUR);
        let rows_left: Vec<u16> = kept(&walk_rows).iter().map(|&(r, _)| r).collect();
        let per_row = broken.iter().map(|&(a, b, _)| b - a + 1).sum::<u16>() as usize;
        assert_eq!(rows_left.iter().filter(|&&r| r == 6).count(), per_row);
        assert_eq!(rows_left.iter().filter(|&&r| r == 11).count(), per_row);
        assert!(
            rows_left.iter().all(|&r| r == 6 || r == 11),
            "{rows_left:?}"
        );
    }

    /// `drop_periodic_stripes`'s rolling four-row ring drops exactly what the rule read
    /// literally drops (every row's chains found first, then confirmed and spread with the whole
    /// frame in view), on seeded random rows of stripes, steps and gaps.
    #[test]
    fn the_rolling_rows_drop_what_the_literal_rule_drops() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        let (mut dropped, mut untouched) = (0, 0);
        for _ in 0..200 {
            let mut spec = Vec::new();
            let mut row_px = 0u16;
            for _ in 0..12 {
                row_px += 1 + next(2) as u16; // some rows missing
                let mut runs = Vec::new();
                let mut col = next(10) as u16;
                // A periodic stretch or scattered edges.
                let width = 4 + next(8) as u16;
                let periodic = next(5) == 0;
                while col < 300 {
                    let w = if periodic { width } else { 2 + next(12) as u16 };
                    runs.push((col, col + 1, true));
                    if next(8) > 0 {
                        runs.push((col + w, col + w + 1, false));
                    }
                    col += w + 3 + if periodic { width } else { next(30) as u16 };
                }
                spec.push((row_px, runs));
            }
            let mut edges = rows(&spec);
            let mut literal = edges.pixels().to_vec();
            let n = drop_periodic_stripes(&mut edges, &FOUR);
            dropped += n;
            untouched += usize::from(n == 0);
            // The literal rule.
            let mut chains: Vec<(u16, Vec<(u16, u16)>)> = Vec::new();
            for (row_px, _) in &spec {
                let mut row_edges: Vec<Edge> = Vec::new();
                for p in literal.iter().filter(|p| p.row_px == *row_px) {
                    let rising = p.gx > 0;
                    match row_edges.last_mut() {
                        Some(e) if e.rising == rising && p.col_px <= e.last_col_px + 1 => {
                            e.last_col_px = p.col_px;
                        }
                        _ => row_edges.push(Edge {
                            first_col_px: p.col_px,
                            last_col_px: p.col_px,
                            rising,
                        }),
                    }
                }
                let mut out = [(0, 0); MAX_CHAINS_PER_ROW];
                let k = find_chains(&row_edges, &FOUR, &mut out);
                chains.push((*row_px, out[..k].to_vec()));
            }
            let spans_at = |r: u16| {
                chains
                    .iter()
                    .filter(move |(q, _)| *q == r)
                    .flat_map(|(_, s)| s.iter().copied())
            };
            let confirmed = |r: u16, span: (u16, u16)| {
                [r.wrapping_sub(1), r + 1]
                    .into_iter()
                    .any(|q| spans_at(q).any(|o| overlap(span, o)))
            };
            literal.retain(|p| {
                ![p.row_px.wrapping_sub(1), p.row_px, p.row_px + 1]
                    .into_iter()
                    .any(|r| {
                        spans_at(r).any(|s| confirmed(r, s) && (s.0..=s.1).contains(&p.col_px))
                    })
            });
            let literal: Vec<(u16, u16)> = literal.iter().map(|p| (p.row_px, p.col_px)).collect();
            assert_eq!(kept(&edges), literal, "{spec:?}");
        }
        // Both outcomes were exercised.
        assert!(
            dropped > 1000 && untouched > 20,
            "{dropped} dropped, {untouched} untouched"
        );
    }
}
