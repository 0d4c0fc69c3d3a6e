//! Colour targets: what fragments are written into.

use glam::Vec3;
use rayon::prelude::*;

use crate::simd::{F32s, I32s, each3};

/// A framebuffer a draw writes shaded fragments into. Generic so the write is
/// inlined into the fragment loop.
///
/// `Send`: a threaded draw hands the target's bands to its threads.
pub trait ColorTarget: Send {
    /// Writes the linear RGB colour (components in 0..1) of pixel `index` (row-major).
    fn put(&mut self, index: usize, c: Vec3);
    /// Fills the whole target, resizing to `len` pixels only if needed.
    fn reset(&mut self, len: usize, c: Vec3);
    /// Pixels held.
    fn len(&self) -> usize;
    /// Whether the target holds no pixel.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes colour lane `k` (red, green, blue lanes) of a group for each set bit `k`
    /// of `mask`: to pixel `start + (k / 8)·stride + k % 8` (8 lanes per row, `F::ROWS`
    /// rows `stride` pixels apart; a stride of 0 when only the first row has bits).
    /// Must store what [`ColorTarget::put`] would.
    #[inline(always)]
    fn put_lanes<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, c: &[F; 3]) {
        let c = each3!(|i| c[i].to_array());
        let mut m = mask;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            let lane = |a: &F::Arr| a.as_ref()[k];
            let at = start + k / 8 * stride + k % 8;
            self.put(at, Vec3::new(lane(&c[0]), lane(&c[1]), lane(&c[2])));
            m &= m - 1;
        }
    }

    /// [`ColorTarget::put_lanes`] of a grey colour: `g` in all three channels.
    #[inline(always)]
    fn put_lanes_grey<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, g: F) {
        self.put_lanes(start, stride, mask, &[g, g, g]);
    }

    /// A band of whole rows of the target, indexed from the band's first pixel: what
    /// one thread of a threaded draw writes while the others write the other bands.
    type Rows<'a>: ColorTarget + SplitOff + Send
    where
        Self: 'a;

    /// The whole target as one band: what a triangle's fragment loop holds by value,
    /// so that the compiler keeps its storage's address in a register rather than
    /// loading it again behind a reference for every group.
    fn all_rows(&mut self) -> Self::Rows<'_>;

    /// The target in bands of `pixels` pixels each (the last may be shorter), first
    /// to last: disjoint borrows, so threads can write them at once.
    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = Self::Rows<'_>>;

    /// The target cut into bands of rows of different heights, ending at pixels
    /// `ends` (ascending, clamped to the target), first to last, each handed to `f`:
    /// disjoint borrows, for draws that share the rows unevenly among threads.
    fn split_rows<'s>(&'s mut self, ends: &[usize], f: impl FnMut(Self::Rows<'s>));
}

/// A band of rows that can be cut in two while it is drawn: a thread that runs out of
/// rows takes some of another's (see `render::tiles::strips`).
pub trait SplitOff: Sized {
    /// Keeps the first `pixels` pixels and returns the rest.
    fn split_off(&mut self, pixels: usize) -> Self;
}

/// [`SplitOff::split_off`] of a slice.
pub fn split_off_slice<'a, T>(slice: &mut &'a mut [T], pixels: usize) -> &'a mut [T] {
    let at = pixels.min(slice.len());
    let (kept, rest) = std::mem::take(slice).split_at_mut(at);
    *slice = kept;
    rest
}

/// Cuts `rest` at `ends` (ascending, clamped to its length), handing each piece to `f`
/// in order: [`ColorTarget::split_rows`] for targets held in slices.
pub fn split_slice<'s, T>(mut rest: &'s mut [T], ends: &[usize], mut f: impl FnMut(&'s mut [T])) {
    let mut at = 0;
    for &end in ends {
        let len = end.saturating_sub(at).min(rest.len());
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(len);
        f(piece);
        rest = tail;
        at += len;
    }
}

/// 8-bit RGBA. Alpha records coverage: the background is cleared with alpha 0 and
/// every written fragment has alpha 255 (the terminal leaves uncovered samples to its
/// own background).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rgba8(pub Vec<[u8; 4]>);

/// Linear colour to an 8-bit channel (no gamma: the values are shading, not photos).
#[must_use]
#[inline(always)]
pub fn to_u8(v: f32) -> u8 {
    // Not fused: this also runs outside the FMA-compiled draw loop (wireframes), where
    // a fused multiply-add is a library call per channel.
    (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// [`to_u8`] on lanes, bit for bit (NaN gives 0 in both).
#[must_use]
#[inline(always)]
pub fn to_u8_lanes<F: F32s>(v: F) -> F::I {
    // max(NaN, 0) is 0, as NaN's `as u8` is in `to_u8`.
    let v = v.max(F::splat(0.0)).min(F::splat(1.0));
    (v * F::splat(255.0) + F::splat(0.5)).trunc_i32()
}

/// Stores packed RGBA words `px` into the group's pixels of `out` where `mask` is set
/// (see [`ColorTarget::put_lanes`]), one blended or masked store per row.
#[inline(always)]
fn blend_lanes<I: I32s>(out: &mut [[u8; 4]], start: usize, stride: usize, mask: u32, px: I) {
    px.store_rows(bytemuck::cast_slice_mut(out), start, stride, mask);
}

/// The cleared pixel of background `c`: alpha 0, nothing covered.
fn background(c: Vec3) -> [u8; 4] {
    [to_u8(c.x), to_u8(c.y), to_u8(c.z), 0]
}

/// Fills `out` with background `c`.
fn fill_rgba(out: &mut [[u8; 4]], c: Vec3) {
    let px = background(c);
    if px == [0; 4] {
        // Black (the usual background): a byte fill, which compiles to `memset`,
        // whose string stores clear a large frame without reading it first. A fill
        // of 4-byte words is a vector loop that reads every line it writes.
        bytemuck::cast_slice_mut::<[u8; 4], u8>(out).fill(0);
    } else {
        out.fill(px);
    }
}

/// [`ColorTarget::put`] of [`Rgba8`] and its bands.
#[inline(always)]
fn put_rgba(out: &mut [[u8; 4]], index: usize, c: Vec3) {
    out[index] = [to_u8(c.x), to_u8(c.y), to_u8(c.z), 255];
}

/// [`ColorTarget::put_lanes`] of [`Rgba8`] and its bands.
#[inline(always)]
fn put_lanes_rgba<F: F32s>(
    out: &mut [[u8; 4]],
    start: usize,
    stride: usize,
    mask: u32,
    c: &[F; 3],
) {
    // Pack to little-endian RGBA words and blend each row's 8 pixels in one store.
    let [r, g, b] = each3!(|i| to_u8_lanes(c[i]));
    let px = r | g.shl::<8>() | b.shl::<16>() | F::I::splat(0xFF << 24);
    blend_lanes(out, start, stride, mask, px);
}

/// [`ColorTarget::put_lanes_grey`] of [`Rgba8`] and its bands.
#[inline(always)]
fn put_lanes_grey_rgba<F: F32s>(out: &mut [[u8; 4]], start: usize, stride: usize, mask: u32, g: F) {
    // One conversion; the byte is copied to red, green and blue by shifts (a
    // multiply by 0x010101 is the same bits but ends the shading's longest
    // dependency chain with ten cycles of latency).
    let v = to_u8_lanes(g);
    let px = v | v.shl::<8>() | v.shl::<16>() | F::I::splat(0xFF << 24);
    blend_lanes(out, start, stride, mask, px);
}

impl ColorTarget for Rgba8 {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        put_rgba(&mut self.0, index, c);
    }
    #[inline(always)]
    fn put_lanes<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, c: &[F; 3]) {
        put_lanes_rgba(&mut self.0, start, stride, mask, c);
    }
    #[inline(always)]
    fn put_lanes_grey<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, g: F) {
        put_lanes_grey_rgba(&mut self.0, start, stride, mask, g);
    }
    fn reset(&mut self, len: usize, c: Vec3) {
        if self.0.len() != len {
            self.0.clear();
            crate::memory::reserve_frame(&mut self.0, len);
            self.0.resize(len, background(c));
        } else {
            fill_rgba(&mut self.0, c);
        }
    }
    fn len(&self) -> usize {
        self.0.len()
    }

    type Rows<'a> = Rgba8Rows<'a>;

    #[inline(always)]
    fn all_rows(&mut self) -> Rgba8Rows<'_> {
        Rgba8Rows(&mut self.0[..])
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = Rgba8Rows<'_>> {
        self.0.par_chunks_mut(pixels).map(Rgba8Rows)
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], mut f: impl FnMut(Rgba8Rows<'s>)) {
        split_slice(&mut self.0[..], ends, |p| f(Rgba8Rows(p)));
    }
}

/// A band of rows of an [`Rgba8`] target (see [`ColorTarget::bands`]).
#[derive(Debug)]
pub struct Rgba8Rows<'a>(pub &'a mut [[u8; 4]]);

impl SplitOff for Rgba8Rows<'_> {
    fn split_off(&mut self, pixels: usize) -> Self {
        Rgba8Rows(split_off_slice(&mut self.0, pixels))
    }
}

impl ColorTarget for Rgba8Rows<'_> {
    #[inline(always)]
    fn put(&mut self, index: usize, c: Vec3) {
        put_rgba(self.0, index, c);
    }
    #[inline(always)]
    fn put_lanes<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, c: &[F; 3]) {
        put_lanes_rgba(self.0, start, stride, mask, c);
    }
    #[inline(always)]
    fn put_lanes_grey<F: F32s>(&mut self, start: usize, stride: usize, mask: u32, g: F) {
        put_lanes_grey_rgba(self.0, start, stride, mask, g);
    }
    /// Fills the band (it cannot change size).
    fn reset(&mut self, len: usize, c: Vec3) {
        debug_assert_eq!(len, self.0.len(), "a band keeps its size");
        fill_rgba(self.0, c);
    }
    fn len(&self) -> usize {
        self.0.len()
    }

    type Rows<'a>
        = Rgba8Rows<'a>
    where
        Self: 'a;

    #[inline(always)]
    fn all_rows(&mut self) -> Rgba8Rows<'_> {
        Rgba8Rows(&mut self.0[..])
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = Rgba8Rows<'_>> {
        self.0.par_chunks_mut(pixels).map(Rgba8Rows)
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], mut f: impl FnMut(Rgba8Rows<'s>)) {
        split_slice(&mut self.0[..], ends, |p| f(Rgba8Rows(p)));
    }
}

/// Rec. 709 luminance of a linear colour.
#[must_use]
#[inline(always)]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use proptest::prelude::*;
    use wide::f32x8;

    use super::{ColorTarget, Rgba8};
    use crate::simd::{F32s, each3};

    /// The lane stores write exactly what `put` writes, lane by lane, and leave
    /// unmasked pixels alone; the grey store equals the colour store of `[g, g, g]`.
    /// Lanes of `F`, from `rgb[channel][lane]` (8 per row, rows `stride` apart).
    fn check<C: ColorTarget + Clone, F: F32s>(
        empty: C,
        bits: impl Fn(&C) -> Vec<u32>,
        rgb: &[Vec<f32>; 3],
        mask: u32,
        stride: usize,
    ) -> Result<(), TestCaseError> {
        let lanes = each3!(|i| {
            let mut a = F::Arr::default();
            a.as_mut().copy_from_slice(&rgb[i][..8 * F::ROWS]);
            F::from_array(a)
        });
        let mut reference = empty.clone();
        reference.reset(12 + 2 * stride, Vec3::new(0.25, 0.5, 0.75));
        let (mut colour, mut grey, mut grey_ref) =
            (reference.clone(), reference.clone(), reference.clone());
        let lanes_of = |i: usize| rgb[i].iter().take(8 * F::ROWS);
        for (k, ((&r, &g), &b)) in lanes_of(0).zip(lanes_of(1)).zip(lanes_of(2)).enumerate() {
            if mask >> k & 1 == 1 {
                let at = 1 + k / 8 * stride + k % 8;
                reference.put(at, Vec3::new(r, g, b));
                grey_ref.put(at, Vec3::splat(r));
            }
        }
        colour.put_lanes(1, stride, mask, &lanes);
        grey.put_lanes_grey(1, stride, mask, lanes[0]);
        prop_assert_eq!(bits(&colour), bits(&reference));
        prop_assert_eq!(bits(&grey), bits(&grey_ref));
        Ok(())
    }

    /// [`check`] on the colour target.
    fn check_targets<F: F32s>(
        rgb: &[Vec<f32>; 3],
        mask: u32,
        stride: usize,
    ) -> Result<(), TestCaseError> {
        let rgba = |c: &Rgba8| c.0.iter().map(|p| u32::from_le_bytes(*p)).collect();
        check::<_, F>(Rgba8::default(), rgba, rgb, mask, stride)
    }

    /// A reset leaves every pixel the background, whatever the target held before and
    /// whether its size changed (black takes its own byte-fill path).
    #[test]
    fn reset_fills_every_pixel_with_the_background() {
        let (red, black) = (Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO);
        let mut t = Rgba8::default();
        for (len, c, want) in [
            (5, red, [255, 0, 0, 0]),
            (5, black, [0, 0, 0, 0]),
            (5, red, [255, 0, 0, 0]),
            (7, black, [0, 0, 0, 0]),
            (7, Vec3::splat(0.5), [128, 128, 128, 0]),
            (3, black, [0, 0, 0, 0]),
        ] {
            t.0.fill([9; 4]);
            t.reset(len, c);
            assert_eq!(t.0, vec![want; len], "{len} {c}");
        }
    }

    fn channel() -> impl Strategy<Value = f32> {
        prop_oneof![
            -0.5f32..1.5,
            Just(f32::NAN),
            Just(0.5 / 255.0),
            Just(1.0),
            Just(0.0)
        ]
    }

    proptest! {
        #[test]
        fn lane_stores_equal_per_pixel_stores(
            rgb in prop::array::uniform3(prop::collection::vec(channel(), 16)),
            mask in any::<u16>(),
            stride in 8usize..20,
        ) {
            check_targets::<f32x8>(&rgb, u32::from(mask & 0xFF), stride)?;
            #[cfg(target_arch = "x86_64")]
            if crate::render::Isa::Avx512.is_supported() {
                // SAFETY of the AVX-512 lanes: the CPU was checked just above.
                check_targets::<crate::simd::avx512::F32x16>(&rgb, u32::from(mask), stride)?;
                check_targets::<crate::simd::avx512::F32x16>(&rgb, u32::from(mask & 0xFF), 0)?;
            }
        }
    }
}
