use wide::{i32x8, i64x4};

use crate::raster::{CoverageSink, Setup};
use crate::simd::{I32s, each3};

/// Edge values of a group: 8 lanes per row of pixels, [`Lanes::ROWS`] rows.
trait Lanes: Copy {
    /// Rows per group (see [`I32s::ROWS`]).
    const ROWS: u32;
    /// `i·sx + r·sy` in the lane of pixel `i` of row `r`.
    fn ramp(sx: i64, sy: i64) -> Self;
    fn splat(v: i64) -> Self;
    fn add(self, o: Self) -> Self;
    /// Bit `k` set when lane `k` is ≥ 0 in all three.
    fn inside_mask(a: Self, b: Self, c: Self) -> u32;
    /// Hands a group to the sink, with the lanes when the sink can use them.
    fn emit<S: CoverageSink>(sink: &mut S, y: u32, x0: u32, mask: u32, f: &[Self; 3]);
}

impl<L: I32s> Lanes for L {
    const ROWS: u32 = L::ROWS as u32;
    #[inline(always)]
    fn ramp(sx: i64, sy: i64) -> Self {
        // Exact: `fits_i32` bounded every lane value before this path was chosen (and
        // wrapping i32 arithmetic agrees with i64 on values that fit). Two constant
        // vectors and two lane multiplies: built lane by lane in `i64`, the ramps were
        // 15 % of the time of a frame of tiny triangles.
        let (mut col, mut row) = (L::Arr::default(), L::Arr::default());
        for (k, (c, r)) in col.as_mut().iter_mut().zip(row.as_mut()).enumerate() {
            (*c, *r) = ((k % 8) as i32, (k / 8) as i32);
        }
        L::from_array(col) * L::splat(sx as i32) + L::from_array(row) * L::splat(sy as i32)
    }
    #[inline(always)]
    fn splat(v: i64) -> Self {
        L::splat(v as i32)
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline(always)]
    fn inside_mask(a: Self, b: Self, c: Self) -> u32 {
        // The OR of three values is negative iff one of them is: one sign-bit mask.
        !(a | b | c).bitmask()
    }
    #[inline(always)]
    fn emit<S: CoverageSink>(sink: &mut S, y: u32, x0: u32, mask: u32, f: &[Self; 3]) {
        sink.edge_lanes(y, x0, mask, f);
    }
}

/// The `i64` fallback for boxes too large for `i32` lanes: two `i64x4` halves.
#[derive(Clone, Copy)]
struct Lanes64(i64x4, i64x4);

impl Lanes for Lanes64 {
    const ROWS: u32 = 1;
    #[inline(always)]
    fn ramp(sx: i64, _: i64) -> Self {
        let l = |o: i64| i64x4::new(std::array::from_fn(|i| (i as i64 + o) * sx));
        Lanes64(l(0), l(4))
    }
    #[inline(always)]
    fn splat(v: i64) -> Self {
        Lanes64(i64x4::splat(v), i64x4::splat(v))
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Lanes64(self.0 + o.0, self.1 + o.1)
    }
    #[inline(always)]
    fn inside_mask(a: Self, b: Self, c: Self) -> u32 {
        let lo = (a.0 | b.0 | c.0).to_bitmask();
        let hi = (a.1 | b.1 | c.1).to_bitmask();
        !(lo | (hi << 4)) & 0xFF
    }
    #[inline(always)]
    fn emit<S: CoverageSink>(sink: &mut S, y: u32, x0: u32, mask: u32, _: &[Self; 3]) {
        // Values that need i64 lanes do not fit the sink's i32 lanes.
        sink.mask8(y, x0, mask as u8);
    }
}

/// The edge values the lanes carry: `G = ⌊F / 256⌋`.
///
/// At pixel centres `F = 256·(I·x + J·y) + c` for a constant `c`, so `⌊F/256⌋` steps by
/// exactly `I` per pixel and `J` per row, and `F ≥ 0 ⇔ ⌊F/256⌋ ≥ 0`. The test is
/// unchanged bit for bit while the values are 256 times smaller, which keeps
/// triangles up to a few thousand pixels within `i32`.
#[inline(always)]
fn reduced(s: &Setup) -> ([i64; 3], [i64; 3], [i64; 3]) {
    (s.reduced_at_origin(), s.i, s.j)
}

/// Whether every value the `wide` traversal forms for this setup fits in `i32`: the
/// reduced edge values over the bounding box widened by the 7 pixels a group can
/// overhang on either side and the row a two-row group can reach below it, plus the
/// group step `8·I`. The bound is the triangle inequality from the box origin
/// (`|G0| + |I|·(w + 14) + |J|·(h + 1)`): a few operations, conservative, and cheap
/// because tiny triangles pay it as often as they cover pixels.
#[must_use]
#[inline(always)]
pub fn fits_i32(s: &Setup) -> bool {
    let b = s.bbox;
    let (g, i, j) = reduced(s);
    let (w, h) = (u64::from(b.width()) + 14, u64::from(b.height()) + 1);
    let fits = |e: usize| {
        let (ax, ay) = (i[e].unsigned_abs(), j[e].unsigned_abs());
        g[e].unsigned_abs() + 8 * ax + ax * w + ay * h <= i32::MAX as u64
    };
    // Not `(0..3).all(..)`: the iterator stays out of line in the renderer's loop.
    fits(0) && fits(1) && fits(2)
}

/// Pixel-parallel traversal: 8 pixels per step, the fast path, on the reduced edge
/// values `⌊F/256⌋` (see `reduced`). Row starts are stepped exactly in `i64`; each row
/// is walked only over the range its edges allow (slivers and large triangles skip the
/// empty part of their box), in groups placed on that range rather than on multiples
/// of 8 (see `walk_run`), and the lanes step by `8·I` in `i32x8` when the box allows it
/// (almost always), else in two `i64x4`. With two-row lanes ([`wide_lanes`] on the
/// AVX-512 backend) a group covers 8 pixels of two rows and walks the union of the
/// two rows' ranges; the coverage is the same pixel for pixel.
#[inline(always)]
pub fn wide<S: CoverageSink>(s: &Setup, sink: &mut S) {
    wide_lanes::<i32x8, S>(s, sink);
}

/// [`wide()`] on the `i32` lanes of backend `L` (see [`crate::simd`]): identical
/// coverage and edge values, different instructions.
#[inline(always)]
pub fn wide_lanes<L: I32s, S: CoverageSink>(s: &Setup, sink: &mut S) {
    if fits_i32(s) {
        walk::<L, S>(s, sink);
    } else {
        walk::<Lanes64, S>(s, sink);
    }
}

/// The pixels of one row that can pass all three edges: a conservative range (at
/// least one pixel of slack on each side of the real-valued crossings), so skipping
/// the rest is exact; the lanes still test every pixel inside it. `None` when the row
/// is empty. `neg_inv[e]` is `−1/sx[e]` (see [`neg_reciprocals`]): a multiply per edge
/// and row instead of a division, whose latency every row start would wait for. Its
/// relative error of a few ulp moves a crossing by far less than a pixel within any
/// box, and truncation with two pixels of slack stands in for floor/ceil (library
/// calls on baseline x86-64).
#[inline(always)]
fn row_range(f: [i64; 3], sx: [i64; 3], neg_inv: [f64; 3], x0: u32, x1: u32) -> Option<(u32, u32)> {
    let (mut lo, mut hi) = (i64::from(x0), i64::from(x1));
    for e in 0..3 {
        // The crossing F(x) = f + (x − x0)·sx = 0 lies at x0 − f/sx.
        let cross = f[e] as f64 * neg_inv[e];
        // SAFETY: finite and within `i64`: `sx ≠ 0` here (else `neg_inv` is 0), and
        // `|f| < 2^54` (an edge value in the guard band, divided by 256), so
        // `|cross| ≤ |f|`. Unchecked because `as` would add a saturating clamp and a NaN
        // test (five instructions) per edge and row.
        let cross: i64 = unsafe { cross.to_int_unchecked() };
        if sx[e] > 0 {
            lo = lo.max(i64::from(x0) + cross - 2);
        } else if sx[e] < 0 {
            hi = hi.min(i64::from(x0) + cross + 2);
        } else if f[e] < 0 {
            return None;
        }
    }
    (lo <= hi).then_some((lo as u32, hi as u32))
}

/// `−1/sx` per edge, 0 for horizontal edges (which [`row_range`] decides by sign).
#[inline(always)]
fn neg_reciprocals(sx: [i64; 3]) -> [f64; 3] {
    each3!(|e| if sx[e] == 0 { 0.0 } else { -1.0 / sx[e] as f64 })
}

#[inline(always)]
fn walk<L: Lanes, S: CoverageSink>(s: &Setup, sink: &mut S) {
    let b = s.bbox;
    // Boxes of two groups or fewer gain nothing from the per-row range.
    if b.width() <= 16 {
        walk_narrow::<L, S>(s, sink);
        return;
    }
    let (mut row, sx, sy) = reduced(s);
    let neg_inv = neg_reciprocals(sx);
    let step8 = each3!(|e| L::splat(sx[e] * 8));
    // Lane offsets `i·sx + r·sy`, built once per triangle; a group start is one splat
    // and add.
    let ramp = each3!(|e| L::ramp(sx[e], sy[e]));
    let mut y = b.y0;
    loop {
        // A group's rows: `L::ROWS`, fewer at the bottom of the box.
        let two = L::ROWS == 2 && y < b.y1;
        let mut range = row_range(row, sx, neg_inv, b.x0, b.x1);
        if two {
            let below = each3!(|e| row[e] + sy[e]);
            range = match (range, row_range(below, sx, neg_inv, b.x0, b.x1)) {
                (Some((a, b)), Some((c, d))) => Some((a.min(c), b.max(d))),
                (r, None) | (None, r) => r,
            };
        }
        if let Some((lo, hi)) = range {
            let at = GroupLanes { row, sx, x0: b.x0 };
            let rows = if two { 0xFFFF } else { 0xFF };
            walk_run(sink, y, (lo, hi, b.x1), rows, &at, &ramp, &step8);
        }
        if b.y1 - y < L::ROWS {
            return;
        }
        y += L::ROWS;
        for e in 0..3 {
            row[e] += sy[e] * i64::from(L::ROWS);
        }
    }
}

/// An 8-pixel lane mask repeated for each row of a group, limited to `rows` (the
/// group's rows that lie in the box: `0xFF` for one, `0xFFFF` for two).
#[inline(always)]
fn per_row(m: u8, rows: u32) -> u32 {
    (u32::from(m) * 0x0101) & rows
}

/// [`walk`] for boxes at most 16 pixels wide (most triangles of a dense mesh): every
/// group row has the same one or two groups (see [`walk_run`]), so their lanes are the
/// previous ones plus `J` per row and their masks are fixed per triangle.
#[inline(always)]
fn walk_narrow<L: Lanes, S: CoverageSink>(s: &Setup, sink: &mut S) {
    let b = s.bbox;
    let (row, sx, sy) = reduced(s);
    let step_y = each3!(|e| L::splat(sy[e] * i64::from(L::ROWS)));
    let ramp = each3!(|e| L::ramp(sx[e], sy[e]));
    let at = GroupLanes { row, sx, x0: b.x0 };
    // One group, or one from x0 and one ending at x1 without the lanes the first had.
    let (n, x, mask) = if b.x1 - b.x0 < 8 {
        let x = first_group(b.x0, b.x1);
        (1, [x, x], [lanes(b.x0 - x, b.x1 - x), 0])
    } else {
        let xb = b.x1 - 7;
        (2, [b.x0, xb], [!0, !0u8 << (b.x0 + 8 - xb)])
    };
    // Two call sites (the sink's fragment code is inlined twice): with one, in a loop
    // over the groups, the lanes live in an array indexed by the loop and go through
    // memory (on the sphere, 32 instructions per visited group with the rows'
    // overhead, against 23 this way; a version that swaps the two groups was worse).
    let (mut f, mut f2) = (at.at(x[0], &ramp), at.at(x[1], &ramp));
    let mut y = b.y0;
    loop {
        let rows = if L::ROWS == 2 && y < b.y1 {
            0xFFFF
        } else {
            0xFF
        };
        group(sink, y, x[0], per_row(mask[0], rows), &f);
        for e in 0..3 {
            f[e] = f[e].add(step_y[e]);
        }
        if n == 2 {
            group(sink, y, x[1], per_row(mask[1], rows), &f2);
            for e in 0..3 {
                f2[e] = f2[e].add(step_y[e]);
            }
        }
        if b.y1 - y < L::ROWS {
            return;
        }
        y += L::ROWS;
    }
}

/// The lanes of a group starting anywhere in a row: `row` holds the reduced edge
/// values at the box's first column `x0`. A struct with a method rather than a
/// closure: closures are compiled on their own, without the AVX2 draw loop's target
/// features, and stay out of line.
struct GroupLanes {
    row: [i64; 3],
    sx: [i64; 3],
    x0: u32,
}

impl GroupLanes {
    /// Lanes of the group starting at pixel `x`; `ramp` holds `i·sx` in lane `i`.
    #[inline(always)]
    fn at<L: Lanes>(&self, x: u32, ramp: &[L; 3]) -> [L; 3] {
        let skip = i64::from(x) - i64::from(self.x0);
        each3!(|e| L::splat(self.row[e] + skip * self.sx[e]).add(ramp[e]))
    }

    /// Lanes of the group starting at pixel `to`, from those `f` of the group at `from`.
    #[inline(always)]
    fn moved<L: Lanes>(&self, f: [L; 3], to: u32, from: u32) -> [L; 3] {
        let d = i64::from(to) - i64::from(from);
        each3!(|e| f[e].add(L::splat(d * self.sx[e])))
    }
}

/// Where the one group of a run `lo..=hi` of at most 8 pixels starts: at `hi − 7`
/// (never right of `lo`), so its lanes lie in the target whenever the target is at
/// least 8 pixels wide (the run lies in it), or at 0 when the run ends before pixel 7.
#[inline(always)]
fn first_group(lo: u32, hi: u32) -> u32 {
    lo.min(hi.saturating_sub(7))
}

/// Lanes `a..=b` of a group (`a ≤ b ≤ 7`).
#[inline(always)]
fn lanes(a: u32, b: u32) -> u8 {
    (!0u8 >> (7 - b)) & (!0u8 << a)
}

/// One group at `x` with lanes `f`, limited to the lanes of `mask`.
#[inline(always)]
fn group<L: Lanes, S: CoverageSink>(sink: &mut S, y: u32, x: u32, mask: u32, f: &[L; 3]) {
    let m = L::inside_mask(f[0], f[1], f[2]) & mask;
    if m != 0 {
        L::emit(sink, y, x, m, f);
    }
}

/// The groups of the run `lo..=hi` of the group row at `y` in a box ending at `x1`
/// (at least 8 pixels wide), whose lanes `at` gives; `rows` limits the masks to the
/// group's rows in the box (see [`per_row`]). Groups start at the run, not at multiples
/// of 8: 8-pixel groups from `lo`, stepped by `8·I`, the last one with the lanes past
/// `hi` masked off, so a run of `n` pixels takes `⌈n/8⌉` groups. A group that would
/// reach past the box is moved left to end at `x1`, with the lanes already visited
/// masked off: the box lies in the target, so every group does too. That needs the
/// lanes recomputed, which only rows near the box's right side pay.
#[inline(always)]
fn walk_run<L: Lanes, S: CoverageSink>(
    sink: &mut S,
    y: u32,
    (lo, hi, x1): (u32, u32, u32),
    rows: u32,
    at: &GroupLanes,
    ramp: &[L; 3],
    step8: &[L; 3],
) {
    let mut x = lo;
    let mut f = at.at(x, ramp);
    loop {
        let mask = if x + 7 <= x1 {
            lanes(0, hi.min(x + 7) - x)
        } else {
            let left = x1 - 7;
            // From `f`, not `at.at(left, ..)`: that does not depend on the group, so
            // the compiler would compute it ahead for every row.
            f = at.moved(f, left, x);
            let mask = lanes(x - left, hi - left);
            x = left;
            mask
        };
        // One call site: the sink's fragment code is inlined once per traversal.
        group(sink, y, x, per_row(mask, rows), &f);
        if x + 7 >= hi {
            return;
        }
        x += 8;
        for e in 0..3 {
            f[e] = f[e].add(step8[e]);
        }
    }
}
