//! The set-up step of a binned draw: each chunk of triangles set up into records, and
//! each record filed in the bins of the bands its box touches, in draw order.

use std::ops::Range;

use super::Job;
use crate::raster::Setup;
use crate::render::options::DrawStats;
use crate::render::prepare::{EmitPiece, Prepared, prepare_projected};
use crate::render::shader::Shader;

/// What a piece costs the walk of a band besides its pixels, in pixels (the walk's
/// per-triangle set-up: its first row's edge values and groups).
const RECORD_COST: u64 = 24;

/// A run of consecutive triangles set up by one thread.
#[derive(Debug)]
pub(in crate::render) struct Chunk<V> {
    /// The pieces that reached the rasterizer, in draw order.
    pub(super) records: Vec<Prepared<V>>,
    /// The bins, one after another: band `b`'s is `entries[starts[b]..starts[b + 1]]`,
    /// the indices in `records` of the pieces whose box touches it, ascending. One
    /// array per chunk keeps the memory in proportion to the pieces, whatever the
    /// number of bands.
    pub(super) entries: Vec<u32>,
    /// Where each band's bin starts in `entries`, and where the last ends (while
    /// binning, `starts[b + 1]` counts band `b`'s pieces).
    pub(super) starts: Vec<u32>,
    /// Per record, the first and last band its box touches: what filling the bins
    /// reads, instead of each record's cache line again.
    pub(super) spans: Vec<[u16; 2]>,
    /// Per band, the work its bin holds: box pixels in the band plus [`RECORD_COST`]
    /// per piece (the order bands are walked in: `queue::plan_bands`).
    pub(super) cost: Vec<u64>,
    /// The triangle counters of the chunk (the fragment counters come from the walk).
    pub(super) stats: DrawStats,
}

impl<V> Chunk<V> {
    /// The indices in `records` of band `band`'s pieces, in draw order.
    pub(super) fn bin(&self, band: usize) -> &[u32] {
        &self.entries[self.starts[band] as usize..self.starts[band + 1] as usize]
    }
}

impl<V> Default for Chunk<V> {
    fn default() -> Self {
        Self {
            records: Vec::new(),
            entries: Vec::new(),
            starts: Vec::new(),
            spans: Vec::new(),
            cost: Vec::new(),
            stats: DrawStats::default(),
        }
    }
}

/// Files each piece into its chunk and counts it in the bins of the bands its box
/// touches ([`fill_bins`] then places it).
struct Binner<'a, V> {
    chunk: &'a mut Chunk<V>,
    bands: BandOf,
}

/// The band of a row, by a multiply and a shift instead of a division (which takes
/// tens of cycles, twice per piece): `⌊y·m / 2^40⌋` with `m = ⌊2^40 / rows⌋ + 1` is
/// `⌊y / rows⌋` for every row of a target (`y < 2^16`), since the error `y·(m −
/// 2^40/rows) / 2^40 < 2^-24` stays below `1 / rows`, the least distance from `y /
/// rows` up to the next integer.
#[derive(Clone, Copy, Debug)]
struct BandOf {
    rows: u32,
    m: u64,
}

impl BandOf {
    fn new(rows: u32) -> Self {
        assert!(rows > 0, "bands of no rows");
        Self {
            rows,
            m: (1u64 << 40) / u64::from(rows) + 1,
        }
    }

    #[inline(always)]
    fn of(self, y: u32) -> u32 {
        debug_assert!(y < 1 << 16, "row {y}");
        ((u64::from(y) * self.m) >> 40) as u32
    }
}

impl<V: Copy> EmitPiece<V> for Binner<'_, V> {
    #[inline(always)]
    fn piece(&mut self, p: &Prepared<V>) {
        let b = p.setup.bbox;
        // A box of at most four pixels covering none of them (most triangles of a mesh
        // far denser than the pixels) would be walked for nothing: it is not stored.
        // The stale depth tiles the walk would have filled read as cleared anyway.
        if u64::from(b.width()) * u64::from(b.height()) <= 4 && !covers_any(&p.setup) {
            return;
        }
        let c = &mut *self.chunk;
        c.records.push(*p);
        let (rows, first, last) = (self.bands.rows, self.bands.of(b.y0), self.bands.of(b.y1));
        // Bands fit 16 bits: a target is at most 2^16 rows and a band at least 8.
        c.spans.push([first as u16, last as u16]);
        for band in first..last + 1 {
            c.starts[band as usize + 1] += 1;
            let y0 = b.y0.max(band * rows);
            let y1 = b.y1.min(band * rows + rows - 1);
            c.cost[band as usize] += u64::from((y1 - y0 + 1) * b.width()) + RECORD_COST;
        }
    }
}

/// Whether any pixel of a setup's box is covered.
#[inline(always)]
fn covers_any(s: &Setup) -> bool {
    let b = s.bbox;
    for y in b.y0..=b.y1 {
        for x in b.x0..=b.x1 {
            let f = s.edges(i64::from(x), i64::from(y));
            if f[0] >= 0 && f[1] >= 0 && f[2] >= 0 {
                return true;
            }
        }
    }
    false
}

/// Sets up triangles `range` of the draw into `chunk`, counting them as one thread
/// does: the body of every copy's [`super::TileCopy::setup`].
#[inline(always)]
pub(in crate::render) fn setup_chunk<S: Shader>(
    job: &Job<'_, S>,
    range: Range<u32>,
    chunk: &mut Chunk<S::Varying>,
) {
    // Room for a piece per triangle of the range (unless clipping splits one), each in
    // two bands: kept from draw to draw, so a model turning into new shapes does not
    // grow them frame after frame.
    let room = range.len();
    chunk.records.clear();
    chunk.records.reserve(room);
    chunk.entries.clear();
    chunk.entries.reserve(2 * room);
    chunk.spans.clear();
    chunk.spans.reserve(room);
    chunk.starts.fill(0);
    chunk.cost.fill(0);
    let mut stats = DrawStats::default();
    let mut binner = Binner {
        chunk,
        bands: BandOf::new(job.band_rows),
    };
    let pv = Some(job.projected);
    for t in range {
        let (cache, indices, target) = (job.cache, job.indices, job.target);
        prepare_projected(cache, pv, indices, t, target, &job.opts, &mut binner)
            .count(&mut stats, 1);
    }
    binner.chunk.stats = stats;
    fill_bins(binner.chunk);
}

/// Places every record's index in the bins its box touches, once the records are
/// counted per band: a counting sort, so each bin is in draw order.
#[inline(always)]
fn fill_bins<V>(c: &mut Chunk<V>) {
    // Counts to starts: starts[b] is where band b's bin begins.
    for b in 1..c.starts.len() {
        c.starts[b] += c.starts[b - 1];
    }
    let total = c.starts.last().copied().unwrap_or(0) as usize;
    c.entries.resize(total, 0);
    // Each record at its band's next free place; starts[b] then holds the bin's end,
    // which is where band b + 1's begins.
    for (i, &[first, last]) in c.spans.iter().enumerate() {
        for band in usize::from(first)..=usize::from(last) {
            c.entries[c.starts[band] as usize] = i as u32;
            c.starts[band] += 1;
        }
    }
    // Back to starts (the last, the total, was never moved and rotates to the front).
    c.starts.rotate_right(1);
    if let Some(first) = c.starts.first_mut() {
        *first = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::{BandOf, Chunk, fill_bins};

    /// The multiply and shift give the quotient for every row of the largest target,
    /// for every band height the draws use and more.
    #[test]
    fn band_of_a_row_is_the_quotient() {
        for rows in (8..=512).step_by(8).chain([1, 3, 1000, 65_535, 65_536]) {
            let b = BandOf::new(rows);
            for y in 0..1u32 << 16 {
                assert_eq!(b.of(y), y / rows, "row {y}, bands of {rows}");
            }
        }
    }

    /// Each band's bin holds exactly the records whose span covers it, in draw order.
    #[test]
    fn bins_hold_each_band_s_records_in_order() {
        let spans = [[0, 2], [1, 1], [2, 3], [0, 0], [3, 3], [1, 3]];
        let mut c = Chunk::<()> {
            starts: vec![0; 5],
            spans: spans.to_vec(),
            ..Chunk::default()
        };
        for &[a, b] in &spans {
            for band in a..=b {
                c.starts[usize::from(band) + 1] += 1;
            }
        }
        fill_bins(&mut c);
        for band in 0..4u16 {
            let want: Vec<u32> = (0..spans.len() as u32)
                .filter(|&i| (spans[i as usize][0]..=spans[i as usize][1]).contains(&band))
                .collect();
            assert_eq!(c.bin(usize::from(band)), want, "band {band}");
        }
    }
}
