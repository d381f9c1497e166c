//! Criterion bench: `convert::to_grey` for every pixel format at 320×240 (the paper's size) and
//! 640×480, into a caller-owned buffer.
#![allow(missing_docs)]

use bt848_capture::{PixelFormat, convert};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

fn bench_to_grey(c: &mut Criterion) {
    let mut group = c.benchmark_group("to_grey");
    for (w, h) in [(320u32, 240u32), (640, 480)] {
        for format in PixelFormat::ALL {
            let stride = w as usize * format.bytes_per_pixel();
            let len = match format {
                PixelFormat::Yu12 => stride * h as usize * 3 / 2,
                _ => stride * h as usize,
            };
            // Deterministic non-constant content.
            let src: Vec<u8> = (0..len).map(|i| (i.wrapping_mul(31) % 251) as u8).collect();
            let mut dst = vec![0u8; w as usize * h as usize];
            group.throughput(Throughput::Elements(u64::from(w) * u64::from(h)));
            group.bench_with_input(
                BenchmarkId::new(format.to_string(), format!("{w}x{h}")),
                &format,
                |b, &format| {
                    b.iter(|| convert::to_grey(format, &src, w, h, stride, &mut dst));
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, bench_to_grey);
criterion_main!(benches);
