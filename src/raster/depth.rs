//! The depth buffer.
//!
//! **Convention: depth is NDC z in [0, 1], 0 at the near plane, 1 at the far plane;
//! smaller is nearer.** The buffer clears to 1.0 (lazily, per tile: see
//! [`DepthBuffer`]), the default test is `Less`, and interpolated depth is clamped to
//! [0, 1] before the test, as a GPU clamps to its depth range.
//!
//! Seed 000's pseudo code stores `Depth = 1 / (1/z)` (the view distance) and writes when
//! `DepthBuffer < Depth`, which keeps the *farthest* surface: the comparison only makes
//! sense if the buffer held 1/z (larger = nearer). This crate stores z_ndc, which is
//! affine in screen space (exact to interpolate with screen-space barycentrics, no
//! divide), and compares with `<`.

use rayon::iter::Either;
use rayon::prelude::*;

/// When a fragment passes the depth test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum DepthFunc {
    /// Nearer than what is stored.
    Less,
    /// Nearer or equal (later draws win ties).
    LessEqual,
    /// Always (painter's order).
    Always,
}

impl DepthFunc {
    /// Whether `new` passes against the stored `old`.
    #[must_use]
    #[inline(always)]
    pub fn passes(self, new: f32, old: f32) -> bool {
        match self {
            DepthFunc::Less => new < old,
            DepthFunc::LessEqual => new <= old,
            DepthFunc::Always => true,
        }
    }

    /// Symbol for the inspector.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            DepthFunc::Less => "<",
            DepthFunc::LessEqual => "<=",
            DepthFunc::Always => "always",
        }
    }
}

/// Depth test and write configuration of a draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DepthState {
    pub func: DepthFunc,
    pub write: bool,
}

impl DepthState {
    /// No test and no write: the draw never touches the depth buffer (and a frame
    /// whose draws are all like this needs none).
    pub const OFF: DepthState = DepthState {
        func: DepthFunc::Always,
        write: false,
    };

    /// Whether a draw with this state reads or writes the depth buffer.
    #[must_use]
    #[inline(always)]
    pub fn uses_buffer(self) -> bool {
        self != Self::OFF
    }
}

impl Default for DepthState {
    fn default() -> Self {
        Self {
            func: DepthFunc::Less,
            write: true,
        }
    }
}

/// Value of a cleared depth buffer: the far plane.
pub const DEPTH_CLEAR: f32 = 1.0;

/// Width in pixels of a clear tile: one 64-byte cache line of depth values.
pub const TILE_W: u32 = 16;
/// Height in pixels of a clear tile.
pub const TILE_H: u32 = 4;

/// An f32 depth buffer, cleared lazily.
///
/// A clear only marks every `TILE_W × TILE_H` tile *stale* (one bit each): a stale
/// tile reads as [`DEPTH_CLEAR`] whatever its memory holds. The renderer fills the
/// stale tiles under a triangle's bounding box ([`DepthBuffer::fill_stale`]) before it
/// walks the triangle, so the far-plane values are written only where something is
/// drawn, while those lines are being fetched anyway, instead of streaming the whole
/// buffer through the cache every frame. Readers see the same values either way.
#[derive(Clone, Debug, Default)]
pub struct DepthBuffer {
    width: u32,
    height: u32,
    data: Vec<f32>,
    /// One bit per tile, row-major, `words` 64-bit words per tile row.
    stale: Vec<u64>,
    words: usize,
}

impl PartialEq for DepthBuffer {
    fn eq(&self, o: &Self) -> bool {
        self.width == o.width && self.height == o.height && self.to_vec() == o.to_vec()
    }
}

impl DepthBuffer {
    /// A cleared buffer.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        let mut d = Self::default();
        d.reset(width, height);
        d
    }

    /// A buffer of this size that holds no memory (see [`DepthBuffer::has_storage`]).
    #[must_use]
    pub fn empty(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            ..Self::default()
        }
    }

    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Whether the buffer holds a value for every pixel (an [`DepthBuffer::empty`] one
    /// does not).
    #[must_use]
    pub fn has_storage(&self) -> bool {
        self.data.len() == self.width as usize * self.height as usize
    }

    /// Bytes of memory held.
    #[must_use]
    pub fn capacity_bytes(&self) -> usize {
        self.data.capacity() * 4 + self.stale.capacity() * 8
    }

    /// Clears to the far plane (marks every tile stale), resizing only if the size
    /// changed.
    pub fn reset(&mut self, width: u32, height: u32) {
        self.width = width;
        self.height = height;
        let len = width as usize * height as usize;
        if self.data.len() != len {
            // Contents are irrelevant: every tile is stale below.
            self.data.clear();
            crate::memory::reserve_frame(&mut self.data, len);
            self.data.resize(len, DEPTH_CLEAR);
        }
        let tiles_x = width.div_ceil(TILE_W) as usize;
        let tiles_y = height.div_ceil(TILE_H) as usize;
        self.words = tiles_x.div_ceil(64);
        // Only the bits of tiles in the buffer are set, so `resolve` never looks past the edge.
        // Refilled in place: a steady viewer allocates nothing here.
        let words = self.words;
        self.stale.clear();
        self.stale.extend((0..tiles_y * words).map(|i| {
            let n = (tiles_x - i % words * 64).min(64);
            if n == 64 { !0 } else { (1u64 << n) - 1 }
        }));
    }

    /// Whether the tile holding pixel `(x, y)` is stale.
    #[inline(always)]
    fn is_stale(&self, x: u32, y: u32) -> bool {
        let (tx, ty) = ((x / TILE_W) as usize, (y / TILE_H) as usize);
        self.stale[ty * self.words + tx / 64] >> (tx % 64) & 1 != 0
    }

    /// Depth at a pixel.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> f32 {
        if self.is_stale(x, y) {
            DEPTH_CLEAR
        } else {
            self.data[y as usize * self.width as usize + x as usize]
        }
    }

    /// Depth at row-major index `i`.
    #[must_use]
    pub fn at(&self, i: usize) -> f32 {
        let w = self.width as usize;
        self.get((i % w) as u32, (i / w) as u32)
    }

    /// Every value, row-major.
    #[must_use]
    pub fn to_vec(&self) -> Vec<f32> {
        (0..self.data.len()).map(|i| self.at(i)).collect()
    }

    /// Fills every stale tile, so the memory holds what [`DepthBuffer::get`] reads.
    pub fn resolve(&mut self) {
        let (w, h) = (self.width, self.height);
        if self.has_storage() && w > 0 && h > 0 {
            self.fill_stale(0, 0, w - 1, h - 1);
        }
    }

    /// Fills the stale tiles overlapping pixels `x0..=x1` × `y0..=y1` with
    /// [`DEPTH_CLEAR`]. Costs a word test per tile row when none is stale: the
    /// renderer calls this once per triangle (see `DepthRows::fill_stale`).
    #[inline(always)]
    pub fn fill_stale(&mut self, x0: u32, y0: u32, x1: u32, y1: u32) {
        self.all_rows().fill_stale(x0, y0, x1, y1);
    }

    /// Every row as one [`DepthRows`].
    #[inline(always)]
    fn all_rows(&mut self) -> DepthRows<'_> {
        DepthRows {
            data: &mut self.data,
            stale: &mut self.stale,
            words: self.words,
            width: self.width,
            y0: 0,
            rows: self.height,
        }
    }

    /// The buffer in bands of `band` rows (a multiple of [`TILE_H`], so no clear tile
    /// is shared by two bands), top to bottom: disjoint borrows that threads can fill
    /// and write at once. A buffer without storage gives bands without values, for
    /// draws that do not use depth.
    pub(crate) fn bands(
        &mut self,
        band: u32,
    ) -> impl IndexedParallelIterator<Item = DepthRows<'_>> + '_ {
        assert!(
            band > 0 && band.is_multiple_of(TILE_H),
            "bands of {band} rows"
        );
        let (width, height, words) = (self.width, self.height, self.words);
        let rows = move |i: usize| {
            let y0 = i as u32 * band;
            (y0, band.min(height - y0))
        };
        if self.has_storage() && width > 0 {
            let px = band as usize * width as usize;
            let bits = (band / TILE_H) as usize * words;
            Either::Left(
                self.data
                    .par_chunks_mut(px)
                    .zip(self.stale.par_chunks_mut(bits))
                    .enumerate()
                    .map(move |(i, (data, stale))| {
                        let (y0, rows) = rows(i);
                        DepthRows {
                            data,
                            stale,
                            words,
                            width,
                            y0,
                            rows,
                        }
                    }),
            )
        } else {
            Either::Right(
                (0..height.div_ceil(band) as usize)
                    .into_par_iter()
                    .map(move |i| {
                        let (y0, rows) = rows(i);
                        DepthRows {
                            data: &mut [],
                            stale: &mut [],
                            words: 0,
                            width,
                            y0,
                            rows,
                        }
                    }),
            )
        }
    }

    /// The buffer cut into bands ending at rows `ends` (ascending, each a multiple of
    /// [`TILE_H`] but the last, which is the height), each handed to `f`:
    /// [`DepthBuffer::bands`] of different heights.
    pub(crate) fn split_rows<'s>(&'s mut self, ends: &[u32], mut f: impl FnMut(DepthRows<'s>)) {
        let (width, words) = (self.width, self.words);
        let storage = self.has_storage() && width > 0;
        let (mut data, mut stale) = if storage {
            (&mut self.data[..], &mut self.stale[..])
        } else {
            (&mut [][..], &mut [][..])
        };
        let mut y0 = 0;
        for &end in ends {
            let end = end.min(self.height).max(y0);
            let rows = end - y0;
            debug_assert!(y0.is_multiple_of(TILE_H), "a band from row {y0}");
            let (px, bits) = if storage {
                (
                    rows as usize * width as usize,
                    rows.div_ceil(TILE_H) as usize * words,
                )
            } else {
                (0, 0)
            };
            let (px, bits) = (px.min(data.len()), bits.min(stale.len()));
            let (d, d_rest) = std::mem::take(&mut data).split_at_mut(px);
            let (b, b_rest) = std::mem::take(&mut stale).split_at_mut(bits);
            f(DepthRows {
                data: d,
                stale: b,
                words: if storage { words } else { 0 },
                width,
                y0,
                rows,
            });
            (data, stale, y0) = (d_rest, b_rest, end);
        }
    }

    /// The values, row-major, for writers that filled the stale tiles they touch first.
    #[inline(always)]
    pub(crate) fn filled_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }
}

impl<'a> DepthRows<'a> {
    /// The first of these rows.
    pub(crate) fn first_row(&self) -> u32 {
        self.y0
    }

    /// The first row after these (exclusive).
    pub(crate) fn end(&self) -> u32 {
        self.y0 + self.rows
    }

    /// Cuts these rows at row `at` (of the frame, a multiple of [`TILE_H`] within
    /// them): keeps the rows above it and returns the rest, so a thread can hand part
    /// of its rows to another while drawing.
    pub(crate) fn split_off(&mut self, at: u32) -> DepthRows<'a> {
        assert!(
            at >= self.y0 && at <= self.end() && (at - self.y0).is_multiple_of(TILE_H),
            "rows {}..{} cut at {at}",
            self.y0,
            self.end()
        );
        let kept = at - self.y0;
        let px = (kept as usize * self.width as usize).min(self.data.len());
        let bits = ((kept / TILE_H) as usize * self.words).min(self.stale.len());
        let (data, data_rest) = std::mem::take(&mut self.data).split_at_mut(px);
        let (stale, stale_rest) = std::mem::take(&mut self.stale).split_at_mut(bits);
        let rest = DepthRows {
            data: data_rest,
            stale: stale_rest,
            words: self.words,
            width: self.width,
            y0: at,
            rows: self.rows - kept,
        };
        (self.data, self.stale, self.rows) = (data, stale, kept);
        rest
    }
}

/// Where the fragment stage tests and writes depth: the whole [`DepthBuffer`], or one
/// band of its rows ([`DepthRows`]) that a thread owns while others draw the rest.
pub(crate) trait DepthStore {
    /// The frame's row-major index of the first value [`DepthStore::filled_mut`] holds.
    fn base(&self) -> usize;
    /// [`DepthBuffer::fill_stale`], for pixels in these rows.
    fn fill_stale(&mut self, x0: u32, y0: u32, x1: u32, y1: u32);
    /// [`DepthBuffer::filled_mut`] of these rows.
    fn filled_mut(&mut self) -> &mut [f32];
}

impl DepthStore for DepthBuffer {
    #[inline(always)]
    fn base(&self) -> usize {
        0
    }
    #[inline(always)]
    fn fill_stale(&mut self, x0: u32, y0: u32, x1: u32, y1: u32) {
        DepthBuffer::fill_stale(self, x0, y0, x1, y1);
    }
    #[inline(always)]
    fn filled_mut(&mut self) -> &mut [f32] {
        DepthBuffer::filled_mut(self)
    }
}

/// Rows `y0..y0 + rows` of a [`DepthBuffer`] (`y0` a multiple of [`TILE_H`]): their
/// values and their tiles' stale bits.
#[derive(Debug)]
pub(crate) struct DepthRows<'a> {
    data: &'a mut [f32],
    /// From the bit word of tile row `y0 / TILE_H`.
    stale: &'a mut [u64],
    words: usize,
    width: u32,
    y0: u32,
    rows: u32,
}

impl DepthStore for DepthRows<'_> {
    #[inline(always)]
    fn base(&self) -> usize {
        self.y0 as usize * self.width as usize
    }
    #[inline(always)]
    fn fill_stale(&mut self, x0: u32, y0: u32, x1: u32, y1: u32) {
        DepthRows::fill_stale(self, x0, y0, x1, y1);
    }
    #[inline(always)]
    fn filled_mut(&mut self) -> &mut [f32] {
        &mut *self.data
    }
}

impl DepthRows<'_> {
    /// Fills the stale tiles overlapping pixels `x0..=x1` × `y0..=y1` (rows of this
    /// band) with [`DEPTH_CLEAR`]. A box within one bit word (every box narrower than
    /// 64 tiles that does not cross a word's edge) takes a loop of its own, with the
    /// span computed once.
    #[inline(always)]
    fn fill_stale(&mut self, x0: u32, y0: u32, x1: u32, y1: u32) {
        debug_assert!(y0 >= self.y0 && y1 < self.y0 + self.rows, "{y0}..={y1}");
        let (tx0, tx1) = ((x0 / TILE_W) as usize, (x1 / TILE_W) as usize);
        let (ty0, ty1) = (
            ((y0 - self.y0) / TILE_H) as usize,
            ((y1 - self.y0) / TILE_H) as usize,
        );
        let (w0, w1) = (tx0 / 64, tx1 / 64);
        if w0 == w1 {
            let span = word_span(tx0 % 64, tx1 % 64);
            for ty in ty0..ty1 + 1 {
                self.fill_stale_word(ty, w0, span);
            }
            return;
        }
        for ty in ty0..ty1 + 1 {
            for w in w0..w1 + 1 {
                let lo = if w == w0 { tx0 % 64 } else { 0 };
                let hi = if w == w1 { tx1 % 64 } else { 63 };
                self.fill_stale_word(ty, w, word_span(lo, hi));
            }
        }
    }

    /// Fills the stale tiles of `span` in bit word `w` of the band's tile row `ty`.
    #[inline(always)]
    fn fill_stale_word(&mut self, ty: usize, w: usize, span: u64) {
        let word = &mut self.stale[ty * self.words + w];
        let m = *word & span;
        if m != 0 {
            *word &= !span;
            self.fill_tiles(w, ty, m);
        }
    }

    /// Fills the tiles of the set bits `m` of bit word `w` in the band's tile row
    /// `ty`. Out of line: it runs about once per tile per frame, against once per
    /// triangle for the test before it.
    #[inline(never)]
    fn fill_tiles(&mut self, w: usize, ty: usize, mut m: u64) {
        let width = self.width as usize;
        let y0 = ty * TILE_H as usize;
        let y1 = (y0 + TILE_H as usize).min(self.rows as usize);
        while m != 0 {
            let x0 = (w * 64 + m.trailing_zeros() as usize) * TILE_W as usize;
            let x1 = (x0 + TILE_W as usize).min(width);
            for y in y0..y1 {
                let row = &mut self.data[y * width + x0..y * width + x1];
                // A whole tile row is one cache line of known length, stored as one
                // array: a slice `fill` of unknown length runs a loop of thrice the
                // instructions.
                match <&mut [f32; TILE_W as usize]>::try_from(&mut *row) {
                    Ok(line) => *line = [DEPTH_CLEAR; TILE_W as usize],
                    Err(_) => row.fill(DEPTH_CLEAR),
                }
            }
            m &= m - 1;
        }
    }
}

/// Bits `lo..=hi` of a word (`lo ≤ hi ≤ 63`).
#[inline(always)]
fn word_span(lo: usize, hi: usize) -> u64 {
    (!0u64 >> (63 - hi)) & (!0u64 << lo)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// An operation on a buffer: clear, or fill a box's stale tiles and write a pixel in it.
    #[derive(Clone, Debug)]
    enum Op {
        Reset,
        Write {
            x0: u32,
            y0: u32,
            x1: u32,
            y1: u32,
            at: (u32, u32),
            z: f32,
        },
    }

    fn op(w: u32, h: u32) -> impl Strategy<Value = Op> {
        prop_oneof![
            1 => Just(Op::Reset),
            6 => (0..w, 0..h, 0..w, 0..h, 0.0f32..1.0, any::<u32>(), any::<u32>()).prop_map(
                |(a, b, c, d, z, px, py)| {
                    let (x0, x1, y0, y1) = (a.min(c), a.max(c), b.min(d), b.max(d));
                    let at = (x0 + px % (x1 - x0 + 1), y0 + py % (y1 - y0 + 1));
                    Op::Write { x0, y0, x1, y1, at, z }
                }
            ),
        ]
    }

    proptest! {
        /// The lazy buffer reads exactly like an eagerly cleared one, before and after
        /// `resolve`, for sizes that are and are not multiples of the tile (and wider
        /// than 64 tiles, so rows span several bit words).
        #[test]
        fn lazy_clear_reads_like_an_eager_clear(
            (w, h, ops) in (1u32..1100, 1u32..20).prop_flat_map(|(w, h)| {
                (Just(w), Just(h), proptest::collection::vec(op(w, h), 1..40))
            })
        ) {
            let mut lazy = DepthBuffer::new(w, h);
            let mut eager = vec![DEPTH_CLEAR; (w * h) as usize];
            for op in &ops {
                match *op {
                    Op::Reset => {
                        lazy.reset(w, h);
                        eager.fill(DEPTH_CLEAR);
                    }
                    Op::Write { x0, y0, x1, y1, at, z } => {
                        lazy.fill_stale(x0, y0, x1, y1);
                        let i = (at.1 * w + at.0) as usize;
                        lazy.filled_mut()[i] = z;
                        eager[i] = z;
                    }
                }
                prop_assert_eq!(&lazy.to_vec(), &eager);
            }
            let (x, y) = (w / 2, h / 2);
            prop_assert_eq!(lazy.get(x, y), eager[(y * w + x) as usize]);
            lazy.resolve();
            prop_assert_eq!(lazy.filled_mut(), &eager[..]);
        }
    }

    #[test]
    fn a_clear_hides_the_previous_frame_and_resizes() {
        let mut d = DepthBuffer::new(40, 9);
        d.fill_stale(0, 0, 39, 8);
        d.filled_mut().fill(0.25);
        d.reset(40, 9);
        assert!(d.to_vec().iter().all(|&z| z == DEPTH_CLEAR));
        d.reset(17, 5);
        assert_eq!((d.width(), d.height(), d.to_vec().len()), (17, 5, 85));
        assert!(d.has_storage() && !DepthBuffer::empty(17, 5).has_storage());
    }
}
