//! The exact reference: coverage by the definition, in `i128`, sharing no code with
//! [`super::setup`] or the traversals.
//!
//! It snaps the same way (the rule, not the code), then tests each pixel centre against
//! each edge with the unbiased cross product and applies the top-left rule by its
//! definition rather than by a bias. Slow and obviously correct; the tests and the
//! accuracy benchmark compare everything else with it.

/// Snaps to 1/256 px by the rule in the module docs, or `None` if rejected.
fn snap(v: f64) -> Option<i128> {
    if !v.is_finite() || v.abs() > 1_048_576.0 {
        return None;
    }
    Some((v * 256.0).round() as i128)
}

/// The snapped, positively wound triangle, or `None` if it covers nothing.
fn prepare(tri: [[f64; 2]; 3]) -> Option<[[i128; 2]; 3]> {
    let mut p = [[0i128; 2]; 3];
    for i in 0..3 {
        for c in 0..2 {
            p[i][c] = snap(tri[i][c])?;
        }
    }
    let area = cross(p[0], p[1], p[2]);
    if area == 0 {
        return None;
    }
    if area < 0 {
        p.swap(1, 2);
    }
    Some(p)
}

/// `(b − a) × (p − a)`: positive when p is on the inner side of a→b.
fn cross(a: [i128; 2], b: [i128; 2], p: [i128; 2]) -> i128 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

fn covers_prepared(p: &[[i128; 2]; 3], x: i64, y: i64) -> bool {
    let c = [i128::from(x) * 256 + 128, i128::from(y) * 256 + 128];
    (0..3).all(|e| {
        let (a, b) = (p[e], p[(e + 1) % 3]);
        let f = cross(a, b, c);
        let top_left = b[1] < a[1] || (b[1] == a[1] && b[0] > a[0]);
        f > 0 || (f == 0 && top_left)
    })
}

/// Whether the centre of pixel `(x, y)` is covered by the triangle (pixel units).
#[must_use]
pub fn covers(tri: [[f64; 2]; 3], x: i64, y: i64) -> bool {
    prepare(tri).is_some_and(|p| covers_prepared(&p, x, y))
}

/// The covered pixels of a `width × height` target, as a row-major mask.
#[must_use]
pub fn coverage(tri: [[f64; 2]; 3], width: u32, height: u32) -> Vec<bool> {
    let mut out = vec![false; width as usize * height as usize];
    for_each_covered(tri, width, height, |x, y| {
        out[y as usize * width as usize + x as usize] = true;
    });
    out
}

/// Calls `f(x, y)` for each covered pixel of a `width × height` target, in row-major
/// order. Only the pixels near the snapped bounds are tested.
pub fn for_each_covered(tri: [[f64; 2]; 3], width: u32, height: u32, mut f: impl FnMut(u32, u32)) {
    let Some(p) = prepare(tri) else { return };
    let lo = |c: usize| p.iter().map(|v| v[c]).min().unwrap_or(0).div_euclid(256) - 1;
    let hi = |c: usize| p.iter().map(|v| v[c]).max().unwrap_or(0).div_euclid(256) + 1;
    let xs = lo(0).max(0)..=hi(0).min(i128::from(width) - 1);
    let ys = lo(1).max(0)..=hi(1).min(i128::from(height) - 1);
    for y in ys {
        for x in xs.clone() {
            if covers_prepared(&p, x as i64, y as i64) {
                f(x as u32, y as u32);
            }
        }
    }
}

/// Doubled signed area of the snapped triangle in subpixel² units (positive for the
/// winding the crate calls positive), or `None` if a coordinate is rejected.
#[must_use]
pub fn snapped_area2(tri: [[f64; 2]; 3]) -> Option<i128> {
    let mut p = [[0i128; 2]; 3];
    for i in 0..3 {
        for c in 0..2 {
            p[i][c] = snap(tri[i][c])?;
        }
    }
    Some(cross(p[0], p[1], p[2]))
}
