//! Ordered-grid supersampling: `n` samples per pixel are a √n × √n grid, rendered as a
//! target that many times larger and resolved by averaging. The scene renderer, the
//! inspector and the anti-aliasing benchmark all use this one layout.

/// Side of the sample grid (1, 2 or 4) for a sample count (1, 4 or 16).
#[must_use]
pub fn grid_side(samples: u32) -> u32 {
    match samples {
        0..=1 => 1,
        2..=4 => 2,
        _ => 4,
    }
}
