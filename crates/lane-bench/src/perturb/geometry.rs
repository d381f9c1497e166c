//! The geometric perturbations' images: the horizon shift, the bonnet and the resize (the
//! maths in the module docs of [`super`]).

use lane_io::GreyFrame;

/// `frame` with its content moved by `shift` rows (down when positive), the vacated rows one
/// flat grey: the mean of the content row beside them.
pub(super) fn shift_rows(frame: &GreyFrame, shift: isize) -> GreyFrame {
    let (w, h) = (frame.width(), frame.height());
    let src = frame.data();
    let mut out = vec![0u8; w * h];
    let d = shift.unsigned_abs().min(h);
    if d == h || w == 0 {
        // Everything left the frame: one flat grey, the frame's mean.
        out.fill(mean(src));
        return from_vec(w, h, out);
    }
    let (kept_from, kept_to, fill_rows, beside) = if shift >= 0 {
        // Down: input rows 0..h−d land on d..h; rows 0..d take input row 0's mean.
        (0, d, 0..d, &src[..w])
    } else {
        // Up: input rows d..h land on 0..h−d; rows h−d..h take input row h−1's mean.
        (d, 0, h - d..h, &src[(h - 1) * w..])
    };
    let n = (h - d) * w;
    out[kept_to * w..kept_to * w + n].copy_from_slice(&src[kept_from * w..kept_from * w + n]);
    let grey = mean(beside);
    out[fill_rows.start * w..fill_rows.end * w].fill(grey);
    from_vec(w, h, out)
}

/// The height of the frame extended by a bonnet taking `fraction` of it: `round(H / (1 − f))`.
pub(super) fn bonnet_frame_height(height: usize, fraction: f64) -> usize {
    ((height as f64 / (1.0 - fraction)).round() as usize).max(height + 1)
}

/// `frame` extended downward by a bonnet taking `fraction` of the new height, then resized back
/// to the frame's size (module docs of [`super`]).
pub(super) fn with_bonnet(frame: &GreyFrame, fraction: f64) -> GreyFrame {
    let (w, h) = (frame.width(), frame.height());
    if w == 0 || h == 0 {
        return frame.clone();
    }
    let h2 = bonnet_frame_height(h, fraction);
    let b = (h2 - h) as f64;
    let mut ext = vec![0u8; w * h2];
    ext[..w * h].copy_from_slice(frame.data());
    let shadow = 0.7 * f64::from(mean(&frame.data()[(h - 1) * w..]));
    for x in 0..w {
        // Across the width, u ∈ (−1, 1); the edge touches the road at the centre.
        let u = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
        let edge = h as f64 + 0.3 * b * u * u;
        let depth_px = h2 as f64 - edge;
        for y in h..h2 {
            let yc = y as f64 + 0.5;
            // Depth into the bonnet, 0 at its edge, 1 at the frame's bottom.
            let d = ((yc - edge) / depth_px).clamp(0.0, 1.0);
            let highlight = 60.0 * (-0.5 * ((d - 0.3) / 0.12).powi(2)).exp() * (1.0 - 0.5 * u * u);
            let paint = 70.0 * (1.0 - 0.35 * d) * (1.0 - 0.25 * u * u) + highlight;
            // The pixel's coverage by the bonnet (its centre row ± 0.5 against the edge).
            let alpha = (yc + 0.5 - edge).clamp(0.0, 1.0);
            let v = alpha * paint + (1.0 - alpha) * shadow;
            ext[y * w + x] = v.round().clamp(0.0, 255.0) as u8;
        }
    }
    resize(&from_vec(w, h2, ext), w, h)
}

/// `frame` resized to `new_w × new_h`: per axis, area (box) resampling to reduce, bilinear to
/// enlarge, pixel centres at `+0.5` (module docs of [`super`]); the same size is a copy.
pub(crate) fn resize(frame: &GreyFrame, new_w: usize, new_h: usize) -> GreyFrame {
    let (w, h) = (frame.width(), frame.height());
    if (w, h) == (new_w, new_h) {
        return frame.clone();
    }
    if w == 0 || h == 0 || new_w == 0 || new_h == 0 {
        return from_vec(new_w, new_h, vec![0; new_w * new_h]);
    }
    let (cols, rows) = (taps(w, new_w), taps(h, new_h));
    // Along the rows first: h × new_w.
    let mut mid = vec![0f32; h * new_w];
    for (src_row, mid_row) in frame
        .data()
        .chunks_exact(w)
        .zip(mid.chunks_exact_mut(new_w))
    {
        for (o, tap) in mid_row.iter_mut().zip(&cols) {
            *o = tap.iter().map(|&(j, k)| k * f32::from(src_row[j])).sum();
        }
    }
    // Then along the columns, a row at a time.
    let mut out = vec![0u8; new_w * new_h];
    let mut acc = vec![0f32; new_w];
    for (out_row, tap) in out.chunks_exact_mut(new_w).zip(&rows) {
        acc.fill(0.0);
        for &(j, k) in tap {
            for (a, &m) in acc.iter_mut().zip(&mid[j * new_w..(j + 1) * new_w]) {
                *a += k * m;
            }
        }
        for (o, a) in out_row.iter_mut().zip(&acc) {
            *o = a.round().clamp(0.0, 255.0) as u8;
        }
    }
    from_vec(new_w, new_h, out)
}

/// Per output pixel of an axis `n → m`, its input pixels and their weights (summing to 1):
/// the overlaps of `[i·n/m, (i+1)·n/m)` for `m < n`, the two neighbours of
/// `(i + 0.5)·n/m − 0.5` for `m > n`, the pixel itself for `m = n`.
fn taps(n: usize, m: usize) -> Vec<Vec<(usize, f32)>> {
    let s = n as f64 / m as f64;
    (0..m)
        .map(|i| {
            if m == n {
                vec![(i, 1.0)]
            } else if m < n {
                let (a, b) = (i as f64 * s, (i + 1) as f64 * s);
                let first = a.floor() as usize;
                let last = (b.ceil() as usize).min(n);
                (first..last)
                    .map(|j| {
                        let overlap = (b.min(j as f64 + 1.0) - a.max(j as f64)).max(0.0);
                        (j, (overlap / s) as f32)
                    })
                    .filter(|&(_, k)| k > 0.0)
                    .collect()
            } else {
                let u = ((i as f64 + 0.5) * s - 0.5).clamp(0.0, (n - 1) as f64);
                let j0 = u.floor() as usize;
                let t = u - j0 as f64;
                let j1 = (j0 + 1).min(n - 1);
                vec![(j0, (1.0 - t) as f32), (j1, t as f32)]
            }
        })
        .collect()
}

/// The mean grey of `px`, rounded (0 for none).
fn mean(px: &[u8]) -> u8 {
    if px.is_empty() {
        return 0;
    }
    let sum: u64 = px.iter().map(|&v| u64::from(v)).sum();
    ((sum as f64 / px.len() as f64).round()).clamp(0.0, 255.0) as u8
}

/// A frame of `w × h` from `data`, which has that many pixels by construction here.
pub(super) fn from_vec(w: usize, h: usize, data: Vec<u8>) -> GreyFrame {
    GreyFrame::from_vec(w, h, data).unwrap_or_default()
}
