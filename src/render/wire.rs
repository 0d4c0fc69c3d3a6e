//! Wireframes: each mesh edge drawn once with the midpoint line algorithm, optionally
//! with hidden-line removal against the filled mesh's depth buffer.
//!
//! Edges are clipped in clip space (near, far and the guard band, like triangles),
//! projected, and their endpoints rounded down to the pixel that contains them. Depth
//! along a line is NDC z interpolated linearly in screen space (exact for z_ndc) over
//! the major axis. Hidden-line removal draws a line pixel only if
//! `z_line − WIRE_DEPTH_BIAS ≤ z_buffer`: the bias lets an edge of a visible face win
//! against that face itself, whose depth differs from the line's only by rounding and
//! by the line's pixel-centre sampling.

use glam::Vec3;

use super::{ColorTarget, VertexCache, ndc_to_screen};
use crate::raster::Target;
use crate::raster::clip::{clip_segment, guard_band_ndc};
use crate::raster::depth::DepthBuffer;
use crate::raster::line::{Line, NoTrace, Step, Tracer};

/// NDC depth allowance for hidden-line removal. At the standard camera (near 0.1,
/// far 10, model at distance 2.6) it is about 0.014 world units, under 1 % of the
/// model's size.
pub const WIRE_DEPTH_BIAS: f32 = 2e-4;

/// Colour of wireframe lines.
pub const WIRE_COLOR: Vec3 = Vec3::new(1.0, 0.75, 0.2);

/// How the mesh is shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Mode {
    /// Filled, shaded triangles.
    #[default]
    Fill,
    /// Every edge, no depth test.
    Wire,
    /// Filled triangles with their visible edges on top.
    #[value(name = "fill+wire")]
    FillWire,
}

impl Mode {
    /// All modes in cycling order.
    pub const ALL: [Mode; 3] = [Mode::Fill, Mode::Wire, Mode::FillWire];

    /// Whether triangles are filled.
    #[must_use]
    pub fn fills(self) -> bool {
        self != Mode::Wire
    }

    /// Whether edges are drawn.
    #[must_use]
    pub fn wires(self) -> bool {
        self != Mode::Fill
    }
}

/// The unique edges of an indexed triangle list, each as `[low, high]`, sorted.
#[must_use]
pub fn unique_edges(indices: &[u32]) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> = indices
        .chunks_exact(3)
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .filter(|[a, b]| a != b)
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// An edge projected to the screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenLine {
    pub line: Line,
    /// NDC depth at the walk's first and last pixel.
    pub z: [f32; 2],
}

impl ScreenLine {
    /// Depth at step `k`.
    #[must_use]
    #[inline]
    pub fn depth_at(&self, k: i64) -> f32 {
        let t = if self.line.dx == 0 {
            0.0
        } else {
            k as f32 / self.line.dx as f32
        };
        self.z[0] + (self.z[1] - self.z[0]) * t
    }

    /// The step at which this line draws pixel `(x, y)`, if it does.
    #[must_use]
    pub fn step_at(&self, x: i64, y: i64) -> Option<i64> {
        let l = &self.line;
        let (sx, sy) = l.start();
        let k = if l.swap_xy { y - sy } else { x - sx };
        ((0..=l.dx).contains(&k) && l.pixel(k, l.minor_at(k)) == (x, y)).then_some(k)
    }
}

/// Clips and projects edge `[i, j]`; `None` if nothing of it is in front of the eye.
#[must_use]
pub fn project_edge<V>(
    cache: &VertexCache<V>,
    edge: [u32; 2],
    target: Target,
) -> Option<ScreenLine> {
    let a = cache.verts.get(edge[0] as usize)?.pos;
    let b = cache.verts.get(edge[1] as usize)?.pos;
    let ([p, q], _) = clip_segment(a, b, guard_band_ndc(target.width, target.height))?;
    let screen = |c: glam::Vec4| {
        let n = c / c.w;
        let size = [target.width as f32, target.height as f32];
        let [x, y] = ndc_to_screen([n.x, n.y], size);
        ((x.floor() as i64, y.floor() as i64), n.z)
    };
    let ((pa, za), (pb, zb)) = (screen(p), screen(q));
    let line = Line::new(pa, pb).ok()?;
    let z = if line.swap_ends { [zb, za] } else { [za, zb] };
    Some(ScreenLine { line, z })
}

/// What a wireframe drew.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WireCount {
    /// Lines with at least one pixel written.
    pub lines: u64,
    pub pixels: u64,
}

impl std::ops::AddAssign for WireCount {
    fn add_assign(&mut self, o: Self) {
        self.lines += o.lines;
        self.pixels += o.pixels;
    }
}

/// Draws the edges into `color`. With `depth`, only pixels passing the hidden-line
/// test are drawn.
pub fn draw_wireframe<V, C: ColorTarget>(
    cache: &VertexCache<V>,
    edges: &[[u32; 2]],
    target: Target,
    depth: Option<&DepthBuffer>,
    wire: Vec3,
    color: &mut C,
) -> WireCount {
    let (w, h) = (i64::from(target.width), i64::from(target.height));
    let mut count = WireCount::default();
    for &e in edges {
        let before = count.pixels;
        let written = &mut count.pixels;
        let Some(sl) = project_edge(cache, e, target) else {
            continue;
        };
        let mut k = sl.line.clip_range(w, h).map_or(0, |r| r.0);
        sl.line.draw_clipped(
            w,
            h,
            |x, y| {
                let i = y as usize * target.width as usize + x as usize;
                let visible = depth.is_none_or(|d| sl.depth_at(k) - WIRE_DEPTH_BIAS <= d.at(i));
                if visible {
                    color.put(i, wire);
                    *written += 1;
                }
                k += 1;
            },
            &mut NoTrace,
        );
        count.lines += u64::from(count.pixels > before);
    }
    count
}

/// What the probe knows about a line through a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineHit {
    /// The mesh edge (vertex indices).
    pub edge: [u32; 2],
    pub screen: ScreenLine,
    /// The trace step of the walk at this pixel.
    pub step: Step,
    /// Line depth here, and whether it passed the hidden-line test (true without one).
    pub depth: f32,
    pub visible: bool,
}

/// Every edge whose line draws pixel `(x, y)`, with its trace step there.
#[must_use]
pub fn probe_lines<V>(
    cache: &VertexCache<V>,
    edges: &[[u32; 2]],
    target: Target,
    depth: Option<&DepthBuffer>,
    x: u32,
    y: u32,
) -> Vec<LineHit> {
    let mut hits = Vec::new();
    for &e in edges {
        let Some(sl) = project_edge(cache, e, target) else {
            continue;
        };
        let Some(k) = sl.step_at(x.into(), y.into()) else {
            continue;
        };
        let mut one: Vec<Step> = Vec::with_capacity(1);
        let mut tracer = StepAt { k, out: &mut one };
        let (w, h) = (i64::from(target.width), i64::from(target.height));
        sl.line.draw_clipped(w, h, |_, _| {}, &mut tracer);
        let Some(step) = one.first().copied() else {
            continue;
        };
        let z = sl.depth_at(k);
        let i = y as usize * target.width as usize + x as usize;
        let visible = depth.is_none_or(|d| z - WIRE_DEPTH_BIAS <= d.at(i));
        hits.push(LineHit {
            edge: e,
            screen: sl,
            step,
            depth: z,
            visible,
        });
    }
    hits
}

/// Keeps only the step with index `k`.
struct StepAt<'a> {
    k: i64,
    out: &'a mut Vec<Step>,
}

impl Tracer for StepAt<'_> {
    fn step(&mut self, s: Step) {
        if s.k == self.k {
            self.out.push(s);
        }
    }
}

/// The line under pixel `(x, y)`, as the line panel shows it: a visible wireframe
/// line through the pixel when `wires` gives the drawn edges (and the depth they were
/// tested against), else the edge of `triangle` (the triangle covering the pixel)
/// nearest to the pixel's centre. Returns the mesh edge, its screen line and the
/// walk's step at (or nearest to) the pixel.
#[must_use]
pub fn line_under<V>(
    cache: &VertexCache<V>,
    indices: &[u32],
    wires: Option<(&[[u32; 2]], Option<&DepthBuffer>)>,
    triangle: Option<u32>,
    target: Target,
    x: u32,
    y: u32,
) -> Option<([u32; 2], ScreenLine, i64)> {
    if let Some((edges, depth)) = wires {
        let hits = probe_lines(cache, edges, target, depth, x, y);
        if let Some(h) = hits.iter().find(|h| h.visible) {
            return Some((h.edge, h.screen, h.step.k));
        }
    }
    let t = triangle? as usize;
    let tri = indices.get(t * 3..t * 3 + 3)?;
    let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
    [[tri[0], tri[1]], [tri[1], tri[2]], [tri[2], tri[0]]]
        .into_iter()
        .filter_map(|e| {
            let e = [e[0].min(e[1]), e[0].max(e[1])];
            let sl = project_edge(cache, e, target)?;
            let (a, b) = (sl.line.a, sl.line.b);
            let (dx, dy) = ((b.0 - a.0) as f64, (b.1 - a.1) as f64);
            let len = dx.hypot(dy).max(1e-9);
            let dist = ((px - a.0 as f64 - 0.5) * dy - (py - a.1 as f64 - 0.5) * dx).abs() / len;
            Some((dist, e, sl))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, e, sl)| {
            let (sx, sy) = sl.line.start();
            let k = if sl.line.swap_xy {
                i64::from(y) - sy
            } else {
                i64::from(x) - sx
            };
            (e, sl, k.clamp(0, sl.line.dx))
        })
}
