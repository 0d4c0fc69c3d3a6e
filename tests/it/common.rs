//! Helpers shared by the integration tests.

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use termrast::raster::{CountGrid, CoverageSink, Setup, Target, Traversal, oracle};
use termrast::render::target::{split_off_slice, split_slice};
use termrast::render::{
    ColorTarget, DrawOptions, Renderer, Shader, SplitOff, VertexCache, transform,
};

/// A sink that checks every reported pixel lies in the target and the bbox.
pub struct CheckedGrid {
    pub grid: CountGrid,
    pub bbox: termrast::raster::PixelRect,
}

impl CoverageSink for CheckedGrid {
    fn pixel(&mut self, x: u32, y: u32) {
        assert!(
            x < self.grid.width && y < self.grid.height,
            "({x},{y}) outside target"
        );
        assert!(
            self.bbox.contains(x, y),
            "({x},{y}) outside bbox {:?}",
            self.bbox
        );
        let w = self.grid.width as usize;
        self.grid.counts[y as usize * w + x as usize] += 1;
    }
}

/// Coverage of one triangle by one traversal, every pixel bounds-checked.
pub fn coverage(t: Traversal, tri: [[f64; 2]; 3], target: Target) -> CountGrid {
    let mut sink = CheckedGrid {
        grid: CountGrid::new(target.width, target.height),
        bbox: termrast::raster::PixelRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        },
    };
    if let Ok(s) = Setup::new(tri, target) {
        sink.bbox = s.bbox;
        t.run(&s, &mut sink);
    }
    sink.grid
}

/// The oracle's coverage as a 0/1 count grid.
pub fn oracle_grid(tri: [[f64; 2]; 3], target: Target) -> CountGrid {
    let mask = oracle::coverage(tri, target.width, target.height);
    CountGrid {
        width: target.width,
        height: target.height,
        counts: mask.into_iter().map(u32::from).collect(),
    }
}

/// Asserts every traversal matches the oracle exactly, naming the first difference.
pub fn assert_all_match_oracle(tri: [[f64; 2]; 3], target: Target) {
    let want = oracle_grid(tri, target);
    for t in Traversal::ALL {
        let got = coverage(t, tri, target);
        if got != want {
            let diff = (0..want.counts.len())
                .find(|&i| got.counts[i] != want.counts[i])
                .map(|i| (i as u32 % target.width, i as u32 / target.width));
            panic!(
                "{} differs from the oracle for {tri:?} at {diff:?}",
                t.name()
            );
        }
    }
}

/// Adds one triangle's coverage (wide traversal) into a shared grid.
pub fn accumulate(grid: &mut CountGrid, tri: [[f64; 2]; 3], t: Traversal) {
    let target = Target::new(grid.width, grid.height);
    if let Ok(s) = Setup::new(tri, target) {
        t.run(&s, grid);
    }
}

/// A colour target that keeps exact f32 colours and counts the writes to each pixel;
/// a write outside it fails the test. The tests draw into this one target (and
/// `Rgba8`), so the draw loop is compiled for few target types.
#[derive(Default)]
pub struct Exact {
    pub colors: Vec<Option<Vec3>>,
    pub writes: Vec<u32>,
}

impl ColorTarget for Exact {
    fn put(&mut self, i: usize, c: Vec3) {
        assert!(
            i < self.colors.len(),
            "write at {i} outside {}",
            self.colors.len()
        );
        self.colors[i] = Some(c);
        self.writes[i] += 1;
    }
    fn reset(&mut self, len: usize, _: Vec3) {
        self.colors.clear();
        self.colors.resize(len, None);
        self.writes.clear();
        self.writes.resize(len, 0);
    }
    fn len(&self) -> usize {
        self.colors.len()
    }

    type Rows<'a> = ExactRows<'a>;

    fn all_rows(&mut self) -> ExactRows<'_> {
        ExactRows {
            colors: &mut self.colors[..],
            writes: &mut self.writes[..],
        }
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = ExactRows<'_>> {
        let writes = self.writes.par_chunks_mut(pixels);
        (self.colors.par_chunks_mut(pixels).zip(writes))
            .map(|(colors, writes)| ExactRows { colors, writes })
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], f: impl FnMut(ExactRows<'s>)) {
        split_exact(&mut self.colors, &mut self.writes, ends, f);
    }
}

/// A band of rows of an [`Exact`] target: a write outside the band fails the test.
pub struct ExactRows<'a> {
    colors: &'a mut [Option<Vec3>],
    writes: &'a mut [u32],
}

impl SplitOff for ExactRows<'_> {
    fn split_off(&mut self, pixels: usize) -> Self {
        ExactRows {
            colors: split_off_slice(&mut self.colors, pixels),
            writes: split_off_slice(&mut self.writes, pixels),
        }
    }
}

impl ColorTarget for ExactRows<'_> {
    fn put(&mut self, i: usize, c: Vec3) {
        assert!(
            i < self.colors.len(),
            "write at {i} outside a band of {}",
            self.colors.len()
        );
        self.colors[i] = Some(c);
        self.writes[i] += 1;
    }
    fn reset(&mut self, _: usize, _: Vec3) {
        self.colors.fill(None);
        self.writes.fill(0);
    }
    fn len(&self) -> usize {
        self.colors.len()
    }

    type Rows<'a>
        = ExactRows<'a>
    where
        Self: 'a;

    fn all_rows(&mut self) -> ExactRows<'_> {
        ExactRows {
            colors: &mut self.colors[..],
            writes: &mut self.writes[..],
        }
    }

    fn bands(&mut self, pixels: usize) -> impl IndexedParallelIterator<Item = ExactRows<'_>> {
        let writes = self.writes.par_chunks_mut(pixels);
        (self.colors.par_chunks_mut(pixels).zip(writes))
            .map(|(colors, writes)| ExactRows { colors, writes })
    }

    fn split_rows<'s>(&'s mut self, ends: &[usize], f: impl FnMut(ExactRows<'s>)) {
        split_exact(self.colors, self.writes, ends, f);
    }
}

/// [`ColorTarget::split_rows`] of an [`Exact`] target or band: its colours and write
/// counts cut at the same pixels.
fn split_exact<'s>(
    colors: &'s mut [Option<Vec3>],
    writes: &'s mut [u32],
    ends: &[usize],
    mut f: impl FnMut(ExactRows<'s>),
) {
    let mut pieces = Vec::new();
    split_slice(writes, ends, |w| pieces.push(w));
    let mut pieces = pieces.into_iter();
    split_slice(colors, ends, |colors| {
        let writes = pieces.next().expect("as many pieces as colours");
        f(ExactRows { colors, writes });
    });
}

/// Clip-space vertices given directly, with a Vec3 attribute each.
pub struct Direct {
    pub clip: Vec<Vec4>,
    pub attr: Vec<Vec3>,
}

impl Shader for Direct {
    type Varying = Vec3;
    fn vertex(&self, i: u32) -> (Vec4, Vec3) {
        (self.clip[i as usize], self.attr[i as usize])
    }
    fn fragment(&self, v: &Vec3) -> Vec3 {
        *v
    }
}

pub fn draw(
    shader: &Direct,
    indices: &[u32],
    target: Target,
    opts: &DrawOptions,
) -> (Exact, Renderer) {
    let mut r = Renderer::new(target);
    let mut out = Exact::default();
    let mut cache = VertexCache::default();
    r.begin_frame(target, &mut out, Vec3::ZERO);
    transform(shader, shader.clip.len(), &mut cache);
    r.draw(shader, &cache, indices, opts, &mut out);
    (out, r)
}
