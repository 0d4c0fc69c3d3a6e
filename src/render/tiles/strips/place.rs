//! Where the strips of a draw go: each vertex's rows, each strip's share of the
//! vertices, corrected by when the strips ended, and the borders that give each strip
//! its share.

use super::MAX_STRIPS;
use crate::render::prepare::Projected;

/// The draws of a frame that keep their own [`Shares`]; later draws share the last.
pub const SHARED_DRAWS: usize = 8;

/// Each strip's share of a draw's vertices, corrected from frame to frame by the time
/// each strip took to end, so that the strips end together. A frame differs little
/// from the last (a model turns a little), so the last frame's times say where the
/// work lies better than vertex counts do: how large the triangles are, how long the
/// other thread took to start.
#[derive(Clone, Copy, Debug)]
pub struct Shares {
    shares: [f32; MAX_STRIPS],
    strips: usize,
}

/// Equal shares (of any number of strips).
const EQUAL: [f32; MAX_STRIPS] = [1.0; MAX_STRIPS];

impl Default for Shares {
    fn default() -> Self {
        Self {
            shares: EQUAL,
            strips: 0,
        }
    }
}

impl Shares {
    /// The least share a strip keeps, so that one slow frame cannot starve a strip.
    const MIN_SHARE: f32 = 1.0 / 64.0;

    /// The shares of `strips` strips: equal ones unless these were for as many.
    pub fn of(&self, strips: usize) -> &[f32] {
        let strips = strips.clamp(1, MAX_STRIPS);
        if self.strips == strips {
            &self.shares[..strips]
        } else {
            &EQUAL[..strips]
        }
    }

    /// Sets the shares of `shares.len()` strips (at most [`MAX_STRIPS`]), normalised;
    /// a share that is not a positive number gets the least.
    pub fn set(&mut self, shares: &[f32]) {
        let n = shares.len().min(MAX_STRIPS);
        let valid = |s: f32| if s.is_finite() && s > 0.0 { s } else { 0.0 };
        let sum: f32 = shares[..n].iter().map(|&s| valid(s)).sum();
        self.strips = n;
        for (d, &s) in self.shares.iter_mut().zip(&shares[..n]) {
            *d = if sum > 0.0 && sum.is_finite() {
                valid(s) / sum
            } else {
                1.0 / n as f32
            }
            .max(Self::MIN_SHARE);
        }
    }

    /// Corrects the shares by the time each strip took to end, `ends[i]` from the
    /// strips' common start: a strip that ended late gives up part of its share. The
    /// step is the square root of the ratio to the mean, at most a factor of √2, so a
    /// frame slowed by something else moves the strips little. Shares of another
    /// number of strips start again from equal ones.
    pub fn correct(&mut self, ends: &[u64]) {
        let n = ends.len();
        if !(2..=MAX_STRIPS).contains(&n) || ends.contains(&0) {
            return;
        }
        if self.strips != n {
            *self = Self {
                strips: n,
                ..Self::default()
            };
        }
        let mean = ends.iter().map(|&e| e as f64).sum::<f64>() / n as f64;
        for (s, &e) in self.shares.iter_mut().zip(ends) {
            *s *= (mean / e as f64).clamp(0.5, 2.0).sqrt() as f32;
        }
        let sum: f32 = self.shares[..n].iter().sum();
        for s in &mut self.shares[..n] {
            *s = (*s / sum).max(Self::MIN_SHARE);
        }
    }
}

/// A vertex's [`vertex_spans`] entry when a triangle with it needs clipping or is
/// rejected: from row 0 to every row, so every strip sets the triangle up and the first
/// counts it. A vertex of a triangle drawn unclipped never has it, as its first row
/// (clamped) is its last or the next.
pub const ALL_ROWS: u32 = 0xffff_0000;

/// Fills `spans` with one word per vertex of `projected` for a target `height` rows
/// high: `first | last << 16`, the first and last row (clamped to the target) of the
/// box of a triangle with that vertex alone (`Projected::rows`), or [`ALL_ROWS`] if
/// a triangle with it needs clipping or is rejected.
pub fn vertex_spans(projected: &[Projected], height: u32, spans: &mut Vec<u32>) {
    let last = i64::from(height.max(1)) - 1;
    spans.clear();
    spans.extend(projected.iter().map(|p| match p.rows() {
        Some([first, end]) => first.clamp(0, last) as u32 | (end.clamp(0, last) as u32) << 16,
        None => ALL_ROWS,
    }));
}

/// The first and last row of the box of the triangle with vertices `tri` (clamped to
/// the target), from their [`vertex_spans`]: a box is monotone in its vertices, so
/// these are the least first row and the greatest last row of the three. `None` for
/// a vertex index out of range.
#[inline(always)]
#[must_use]
pub fn box_rows(spans: &[u32], tri: &[u32]) -> Option<[u32; 2]> {
    let span = |k: usize| spans.get(*tri.get(k)? as usize).copied();
    let (a, b, c) = (span(0)?, span(1)?, span(2)?);
    let top = (a & 0xffff).min(b & 0xffff).min(c & 0xffff);
    let bottom = (a >> 16).max(b >> 16).max(c >> 16);
    Some([top, bottom])
}

/// Bit `k` set for triangle `k` of `tris` (at most 64) if rows `[first, last]` draw
/// it or count it ([`box_rows`]): its box reaches them, or its first row is in them
/// (a box that holds no row, its first after its last, is counted there), or it has
/// no box from the spans (every strip sets it up, or counts it as out of range).
#[inline(always)]
#[must_use]
pub fn reaching(spans: &[u32], tris: &[u32], [first, last]: [u32; 2]) -> u64 {
    let mut bits = 0;
    for (k, tri) in tris.chunks_exact(3).take(u64::BITS as usize).enumerate() {
        let hit =
            box_rows(spans, tri).is_none_or(|[top, end]| top <= last && top.max(end) >= first);
        bits |= u64::from(hit) << k;
    }
    bits
}

/// Where the strips of a target `height` rows high end, one per entry of `shares`,
/// each a multiple of 8 rows but the last, so that each holds about its share of the
/// vertices (by their first rows in `spans`, see [`vertex_spans`]; `hist` is
/// scratch): each end is the block border nearer to where the strips so far reach
/// their shares. Strips left without rows are dropped. Returns the ends and how many
/// strips there are.
#[must_use]
pub fn strip_ends(
    spans: &[u32],
    height: u32,
    shares: &[f32],
    hist: &mut Vec<u32>,
) -> ([u32; MAX_STRIPS], usize) {
    let strips = shares.len().clamp(1, MAX_STRIPS);
    let blocks = height.div_ceil(8) as usize;
    hist.clear();
    hist.resize(blocks, 0);
    for &s in spans {
        if s != ALL_ROWS
            && let Some(h) = hist.get_mut((s & 0xffff) as usize / 8)
        {
            *h += 1;
        }
    }
    // Without vertices, every block counts one (strips of equal height).
    let total: u64 = hist.iter().map(|&c| u64::from(c)).sum();
    let count_of = |c: u32| if total == 0 { 1.0 } else { f64::from(c) };
    let all: f64 = hist.iter().map(|&c| count_of(c)).sum();
    let share_sum: f64 = shares.iter().map(|&x| f64::from(x.max(0.0))).sum();
    // Where strip `k` should end, in vertices.
    let goal = |k: usize| {
        let before: f64 = shares[..=k].iter().map(|&x| f64::from(x.max(0.0))).sum();
        if share_sum > 0.0 && share_sum.is_finite() {
            all * before / share_sum
        } else {
            all * (k + 1) as f64 / strips as f64
        }
    };
    let mut ends = [height; MAX_STRIPS];
    let mut count = 0;
    let mut seen = 0.0;
    for (b, &c) in hist.iter().enumerate() {
        let (start, end) = (b as u32 * 8, ((b + 1) * 8).min(height as usize) as u32);
        let before = seen;
        seen += count_of(c);
        while count + 1 < strips && seen >= goal(count) {
            let want = goal(count);
            let cut = if want - before < seen - want {
                start
            } else {
                end
            };
            let last = if count == 0 { 0 } else { ends[count - 1] };
            // An end at or before the last one: the strip would have no rows.
            let cut = if cut > last { cut } else { end };
            if cut <= last {
                break;
            }
            ends[count] = cut;
            count += 1;
        }
    }
    if count == 0 || ends[count - 1] < height {
        ends[count] = height;
        count += 1;
    }
    (ends, count)
}

/// Slices a thread's rows are counted in by [`handover_row`].
const HANDOVER_SLICES: usize = 64;

/// Where to cut rows `first..end` (`first` a multiple of 8) that a thread draws from
/// triangle `next` on, so that a thread asking for rows gets about half of the work
/// left there: the block border, leaving a block on each side, nearest the middle of
/// the triangles left that reach those rows, each counted in the block of its box's
/// first row there (from `spans`, see [`vertex_spans`]; in up to 64 slices of whole
/// blocks). 0 when no such border or triangle is left: the rows are then cut in half.
#[must_use]
pub fn handover_row(spans: &[u32], indices: &[u32], [first, end]: [u32; 2], next: u32) -> u32 {
    let blocks = end.saturating_sub(first).div_ceil(8) as usize;
    if blocks < 2 {
        return 0;
    }
    let per = blocks.div_ceil(HANDOVER_SLICES);
    let mut hist = [0u32; HANDOVER_SLICES];
    let start = (next as usize).saturating_mul(3).min(indices.len());
    for tri in indices[start..].chunks_exact(3) {
        // A triangle with a vertex out of range is drawn nowhere.
        let Some([top, bottom]) = box_rows(spans, tri) else {
            continue;
        };
        if bottom < first || top >= end {
            continue;
        }
        hist[(top.max(first) - first) as usize / 8 / per] += 1;
    }
    let total: u32 = hist.iter().sum();
    let (mut best, mut best_gap, mut seen) = (0, u32::MAX, 0);
    for (k, &count) in hist.iter().enumerate() {
        seen += count;
        let at = first + ((k + 1) * per * 8) as u32;
        if at + 8 > end {
            break;
        }
        let gap = (2 * seen).abs_diff(total);
        if gap < best_gap {
            (best, best_gap) = (at, gap);
        }
    }
    if total == 0 { 0 } else { best }
}

#[cfg(test)]
mod tests {
    use glam::Vec4;
    use proptest::prelude::*;

    use super::{ALL_ROWS, MAX_STRIPS, Shares, handover_row, reaching, strip_ends, vertex_spans};
    use crate::raster::Target;
    use crate::raster::clip::{ClipVertex, guard_band_ndc};
    use crate::render::Projected;
    use crate::render::options::DrawOptions;
    use crate::render::prepare::{PrepareOutcome, Prepared, VertexCache, prepare_projected};

    /// A strip's rows reach the triangles whose box meets them, those whose box's
    /// first row they hold (a box without a row is counted there alone), and every
    /// triangle without a box from the spans; at most 64 at a time.
    #[test]
    fn rows_reach_the_triangles_they_draw_or_count() {
        let span = |first: u32, last: u32| first | last << 16;
        // Rows 2–5, rows 10–12, a point's box between rows 6 and 7, all rows.
        let spans = [span(2, 5), span(10, 12), span(7, 6), ALL_ROWS];
        // The last has a vertex index out of range.
        let tris = [0, 0, 0, 1, 1, 1, 2, 2, 2, 0, 3, 0, 0, 1, 9];
        for (rows, bits) in [
            ([6, 9], 0b11100),
            ([0, 5], 0b11001),
            ([8, 20], 0b11010),
            ([7, 7], 0b11100),
            ([0, 0], 0b11000),
            ([12, 12], 0b11010),
        ] {
            assert_eq!(reaching(&spans, &tris, rows), bits, "rows {rows:?}");
        }
        let many = [3; 70 * 3];
        assert_eq!(reaching(&spans, &many, [0, 0]).count_ones(), 64);
    }

    /// Each strip ends at the 8-row block border nearer to where the strips so far
    /// hold their share of the vertices; vertices off the target count at its nearest
    /// row, and vertices that need clipping not at all.
    #[test]
    fn strips_hold_about_their_share_of_the_vertices() {
        let target = Target::new(100, 240);
        let guard = guard_band_ndc(target.width, target.height);
        let at_row = |y: f32| {
            let ndc = 1.0 - y / 240.0 * 2.0;
            Projected::of(Vec4::new(0.1, ndc, 0.5, 1.0), target, guard)
        };
        // 10 vertices in rows 0-7, 10 above the target, 30 in rows 200-207, 20 in
        // rows 232-239, and 50 behind the eye.
        let mut pv: Vec<Projected> = Vec::new();
        pv.extend((0..10).map(|i| at_row(0.5 + i as f32 * 0.7)));
        pv.extend((0..10).map(|_| at_row(-20.0)));
        pv.extend((0..30).map(|i| at_row(200.5 + i as f32 * 0.2)));
        pv.extend((0..20).map(|_| at_row(239.5)));
        let behind = Projected::of(Vec4::new(0.0, 0.0, 0.5, -1.0), target, guard);
        pv.extend((0..50).map(|_| behind));
        let (mut hist, mut spans) = (Vec::new(), Vec::new());
        vertex_spans(&pv, 240, &mut spans);
        let ends = |shares: &[f32], hist: &mut Vec<u32>| {
            let (ends, count) = strip_ends(&spans, 240, shares, hist);
            ends[..count].to_vec()
        };
        // Halves: 35 of 70 lie 15 past 20 (by row 200) and 15 short of 50 (by row 208).
        assert_eq!(ends(&[1.0; 2], &mut hist), [208, 240]);
        // Quarters: 17.5 is nearer 20 (row 8) than 0, 35 as above, 52.5 nearer 50 (row
        // 232) than 70.
        assert_eq!(ends(&[1.0; 4], &mut hist), [8, 208, 232, 240]);
        // A quarter and three: 17.5 again; a tenth: 7 nearer 0 than 20, so no rows,
        // and the border moves to the block's end.
        assert_eq!(ends(&[1.0, 3.0], &mut hist), [8, 240]);
        assert_eq!(ends(&[0.1, 0.9], &mut hist), [8, 240]);
        // Nine tenths: 63 nearer 70 (row 240) than 50, so one strip.
        assert_eq!(ends(&[0.9, 0.1], &mut hist), [240]);
        // Shares that are not positive numbers count as none; none at all as equal.
        assert_eq!(ends(&[f32::NAN, 1.0, -1.0], &mut hist), [8, 240]);
        assert_eq!(ends(&[0.0, 0.0], &mut hist), [208, 240]);
        // Nothing to count: equal heights.
        vertex_spans(&[behind], 240, &mut spans);
        assert_eq!(spans, [ALL_ROWS]);
        assert_eq!(
            strip_ends(&spans, 240, &[1.0; 3], &mut hist).0[..3],
            [80, 160, 240]
        );
    }

    /// Strips whose vertices cost unequally, the second also starting late (as a
    /// woken thread does): from equal vertex counts the corrected shares move the
    /// border until the strips end within a block's work of each other, and stay
    /// there.
    #[test]
    fn corrected_shares_make_strips_end_together() {
        // 30 vertices per 8 rows; a vertex of the first 80 rows costs 3, others 1.
        let height = 240;
        let spans: Vec<u32> = (0..height)
            .flat_map(|y| std::iter::repeat_n(y | y << 16, if y % 8 < 3 { 10 } else { 0 }))
            .collect();
        let cost = |y0: u32, y1: u32| -> u64 {
            (y0..y1)
                .map(|y| {
                    if y % 8 < 3 {
                        10 * if y < 80 { 3 } else { 1 }
                    } else {
                        0
                    }
                })
                .sum()
        };
        let late = 20;
        let times = |ends: &[u32]| -> Vec<u64> {
            let (mut y, mut out) = (0, Vec::new());
            for (i, &e) in ends.iter().enumerate() {
                out.push(cost(y, e) + if i > 0 { late } else { 0 });
                y = e;
            }
            out
        };
        let mut shares = Shares::default();
        let mut hist = Vec::new();
        let first = {
            let (ends, count) = strip_ends(&spans, height, shares.of(2), &mut hist);
            times(&ends[..count])
        };
        // Equal counts: 120 rows each, times 30·... ≈ 2:1.
        assert!(first[0] > first[1] * 3 / 2, "{first:?}");
        for frame in 0..40 {
            let (ends, count) = strip_ends(&spans, height, shares.of(2), &mut hist);
            assert_eq!(count, 2);
            let t = times(&ends[..count]);
            if frame >= 20 {
                // The border moves by blocks of 8 rows: after 8 or 9 of the costly ones
                // (720 against 800, or 810 against 710).
                assert!(t[0].abs_diff(t[1]) <= 100, "frame {frame}: {ends:?} {t:?}");
            }
            shares.correct(&t);
        }
        // A time of 0 (a strip that was not timed) changes nothing; times of three
        // strips start three equal shares again, and leave two strips equal ones.
        let before = shares;
        shares.correct(&[5, 0]);
        assert_eq!(before.shares, shares.shares);
        assert_ne!(shares.of(2), [0.5, 0.5]);
        shares.correct(&[5, 5, 5]);
        assert_eq!(shares.of(3), [1.0 / 3.0; 3]);
        assert_eq!(shares.of(2), [1.0; 2]);
        // One slow frame moves a share by at most a factor of √2 (before normalising).
        let mut s = Shares::default();
        s.correct(&[1, 1000]);
        let ratio = s.shares[0] / s.shares[1];
        assert!((1.99..=2.0 + 1e-5).contains(&ratio), "{:?}", s.shares);
        // Shares never fall below the least.
        let mut s = Shares::default();
        s.set(&[1.0, 0.0]);
        assert_eq!(s.shares[1], Shares::MIN_SHARE);
        for _ in 0..100 {
            s.correct(&[1, 1000]);
        }
        assert!(s.shares[..2].iter().all(|&x| x >= Shares::MIN_SHARE));
    }

    /// A clip coordinate: mostly within the frustum, some outside it, behind the eye,
    /// beyond the guard band, or not finite.
    fn coord() -> impl Strategy<Value = f32> {
        prop_oneof![
            6 => -1.2f32..1.2,
            1 => -40.0f32..40.0,
            1 => prop::sample::select(vec![0.0, -0.0, 1.0, -1.0, 1e9, -1e9, f32::NAN]),
        ]
    }

    proptest! {
        /// The rows the scan takes from a triangle's vertex spans are the rows of the
        /// box its set-up makes, and a triangle that needs clipping (or is rejected
        /// for its vertices) has a vertex spanning every row.
        #[test]
        fn spans_give_the_set_up_box_rows(
            pos in prop::collection::vec((coord(), coord(), 0.1f32..0.9, 0.5f32..2.0), 3),
            w_sign in prop::collection::vec(prop::bool::weighted(0.1), 3),
            (w, h) in (1u32..300, 1u32..300),
        ) {
            let target = Target::new(w, h);
            let guard = guard_band_ndc(w, h);
            let verts: Vec<ClipVertex<()>> = pos
                .iter()
                .zip(&w_sign)
                .map(|(&(x, y, z, w), &behind)| {
                    let w = if behind { -w } else { w };
                    ClipVertex { pos: Vec4::new(x * w, y * w, z * w, w), var: () }
                })
                .collect();
            let pv: Vec<Projected> = verts.iter().map(|v| Projected::of(v.pos, target, guard)).collect();
            let mut spans = Vec::new();
            vertex_spans(&pv, h, &mut spans);
            let cache = VertexCache { verts, projected: pv.clone(), projected_for: Some(target) };
            let mut boxes = Vec::new();
            let outcome = prepare_projected(
                &cache, Some(&pv), &[0, 1, 2], 0, target, &DrawOptions::default(),
                &mut |p: &Prepared<()>| boxes.push(p.setup.bbox),
            );
            if spans.contains(&ALL_ROWS) {
                let clipped = matches!(
                    outcome,
                    PrepareOutcome::Rejected | PrepareOutcome::Drawn { clipped: true }
                );
                prop_assert!(clipped);
            } else {
                let unclipped = !matches!(outcome, PrepareOutcome::Drawn { clipped: true });
                prop_assert!(unclipped);
                let top = spans.iter().map(|s| s & 0xffff).min().unwrap();
                let bottom = spans.iter().map(|s| s >> 16).max().unwrap();
                prop_assert!(boxes.len() <= 1);
                for b in boxes {
                    prop_assert_eq!([b.y0, b.y1], [top, bottom]);
                }
            }
        }
    }

    /// Strips cover the target in order, end on multiples of 8 rows (but the last),
    /// and are never empty, whatever the thread count and height.
    /// A handed-over part starts at the block border that halves the triangles left
    /// in the rows, counted by their first rows there; triangles drawn already or
    /// outside the rows do not count, and rows without triangles left, or of fewer
    /// than two blocks, are cut in half (0).
    #[test]
    fn rows_are_handed_over_where_the_work_left_is_halved() {
        // Vertex i lies on row rows[i]; triangle t is vertex t three times.
        let rows = [[4; 30].as_slice(), &[44; 10], &[76; 20], &[100; 5]].concat();
        let spans: Vec<u32> = rows.iter().map(|&r| r | r << 16).collect();
        let indices: Vec<u32> = (0..rows.len() as u32).flat_map(|t| [t; 3]).collect();
        // 30 triangles in the first block, 30 below: cut after the first block.
        assert_eq!(handover_row(&spans, &indices, [0, 80], 0), 8);
        // Drawn from triangle 30 on: 10 in block 5, 20 in block 9.
        assert_eq!(handover_row(&spans, &indices, [0, 80], 30), 48);
        // Rows 40..96: the 10 of row 44 and the 20 of row 76.
        assert_eq!(handover_row(&spans, &indices, [40, 96], 0), 48);
        assert_eq!(handover_row(&spans, &indices, [0, 80], 60), 0);
        assert_eq!(handover_row(&spans, &indices, [0, 15], 0), 0);
        // A triangle from row 0 to row 100 counts in the first block of any rows.
        let tall = [100 << 16; 3];
        assert_eq!(handover_row(&tall, &[0, 1, 2, 0, 1, 2], [48, 96], 0), 56);
    }

    #[test]
    fn strips_cover_the_target_in_blocks_of_rows() {
        for strips in 1..=MAX_STRIPS + 2 {
            for height in 1..300 {
                let shares = vec![1.0; strips];
                let (ends, count) = strip_ends(&[], height, &shares, &mut Vec::new());
                assert!((1..=strips.min(MAX_STRIPS)).contains(&count));
                assert_eq!(ends[count - 1], height);
                let mut y = 0;
                for &e in &ends[..count] {
                    assert!(e > y, "{height} {strips}: {ends:?}");
                    assert!(e == height || e.is_multiple_of(8));
                    y = e;
                }
            }
        }
    }
}
