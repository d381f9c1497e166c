//! The per-frame hot path (predict + power-sum update) does not allocate (counting global
//! allocator from `alloc-counter`, counting this thread's allocations).
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(missing_docs)]

use alloc_counter::allocations_in;
use info_filter::{ParabolaKif, RowNorm, ThetaCov};
use nalgebra::{Matrix3, Vector3};

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

#[test]
fn predict_and_update_do_not_allocate() {
    let points: Vec<(f32, f32)> = (0..150)
        .map(|i| {
            let y = 90.0 + f64::from(i);
            ((1e-3 * y * y - 0.5 * y + 200.0) as f32, y as f32)
        })
        .collect();
    let mut kif = ParabolaKif::new(
        &Vector3::new(0.0, 0.0, 160.0),
        &ThetaCov::Normalised(Matrix3::identity() * 100.0),
        RowNorm::default(),
    )
    .unwrap();
    let q = kif
        .process_noise(&ThetaCov::Normalised(Matrix3::identity() * 0.25))
        .unwrap();
    let ((), allocations) = allocations_in(|| {
        for _ in 0..100 {
            kif.predict(&q).unwrap();
            kif.update(&points, 1.0).unwrap();
        }
    });
    assert_eq!(allocations, 0);
    // The counter works: a Vec allocation on this thread is seen.
    let (v, allocations) = allocations_in(|| std::hint::black_box(vec![1u8; 16]));
    drop(v);
    assert_eq!(allocations, 1);
}
