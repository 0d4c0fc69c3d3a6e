use super::scalar::walk_rect;
use crate::raster::{CoverageSink, PixelRect, Setup};

/// Default block side q.
pub const DEFAULT_BLOCK: u32 = 8;

/// How a block relates to the triangle, decided from the pixel centres at its corners.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlockClass {
    /// All four corners fail the same edge: no pixel of the block is covered.
    Outside,
    /// All four corners pass all three edges: every pixel is covered (convexity), so
    /// the block is filled without any per-pixel test.
    Inside,
    /// Neither: each pixel is tested.
    Partial,
}

impl BlockClass {
    /// Lower-case name for tables and the inspector.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BlockClass::Outside => "outside",
            BlockClass::Inside => "inside",
            BlockClass::Partial => "partial",
        }
    }
}

/// Classifies a block from the biased edge values at its four corner pixel centres,
/// `corners[e] = [top-left, top-right, bottom-left, bottom-right]` of edge `e`.
///
/// A block is inside only if all four corners pass *all* three edges, and outside as
/// soon as *one* edge rejects all four corners (a common mistake has these the other
/// way round).
#[must_use]
#[inline]
pub fn classify_corners(corners: [[i64; 4]; 3]) -> BlockClass {
    let mut inside = true;
    for c in corners {
        let passing = c.iter().filter(|&&f| f >= 0).count();
        if passing == 0 {
            return BlockClass::Outside;
        }
        inside &= passing == 4;
    }
    if inside {
        BlockClass::Inside
    } else {
        BlockClass::Partial
    }
}

/// The block of side `q` (aligned to the bounding-box origin, clipped to the box) that
/// contains pixel `(x, y)`, or `None` outside the box. The same grid the traversal uses.
#[must_use]
pub fn block_containing(s: &Setup, q: u32, x: u32, y: u32) -> Option<PixelRect> {
    let b = s.bbox;
    if !b.contains(x, y) {
        return None;
    }
    let bx = b.x0 + (x - b.x0) / q * q;
    let by = b.y0 + (y - b.y0) / q * q;
    Some(PixelRect {
        x0: bx,
        y0: by,
        x1: (bx + q - 1).min(b.x1),
        y1: (by + q - 1).min(b.y1),
    })
}

/// Classifies a block by direct evaluation (the probe's view of the traversal).
#[must_use]
pub fn classify_block(s: &Setup, r: PixelRect) -> BlockClass {
    let (x0, y0, x1, y1) = (
        i64::from(r.x0),
        i64::from(r.y0),
        i64::from(r.x1),
        i64::from(r.y1),
    );
    classify_corners([0, 1, 2].map(|e| {
        [
            s.edge(e, x0, y0),
            s.edge(e, x1, y0),
            s.edge(e, x0, y1),
            s.edge(e, x1, y1),
        ]
    }))
}

/// q×q blocks with trivial reject and accept. Block corners are stepped incrementally
/// by `q·I` and `q·J`; partial blocks run the scalar per-pixel walk inside the block.
pub fn block<S: CoverageSink>(s: &Setup, q: u32, sink: &mut S) {
    let q = q.max(1);
    let b = s.bbox;
    let (sx, sy) = (s.step_x(), s.step_y());
    let qi = i64::from(q);
    let (bsx, bsy) = (sx.map(|v| v * qi), sy.map(|v| v * qi));
    let mut row = s.edges_at_origin();
    let mut by = b.y0;
    while by <= b.y1 {
        let by1 = (by + q - 1).min(b.y1);
        let dy = i64::from(by1 - by);
        let mut c = row;
        let mut bx = b.x0;
        while bx <= b.x1 {
            let bx1 = (bx + q - 1).min(b.x1);
            let dx = i64::from(bx1 - bx);
            let corners = [0, 1, 2].map(|e| {
                let (ox, oy) = (dx * sx[e], dy * sy[e]);
                [c[e], c[e] + ox, c[e] + oy, c[e] + ox + oy]
            });
            match classify_corners(corners) {
                BlockClass::Outside => {}
                BlockClass::Inside => {
                    for y in by..=by1 {
                        sink.span(y, bx, bx1 + 1);
                    }
                }
                BlockClass::Partial => {
                    let r = PixelRect {
                        x0: bx,
                        y0: by,
                        x1: bx1,
                        y1: by1,
                    };
                    walk_rect(r, c, sx, sy, sink);
                }
            }
            for e in 0..3 {
                c[e] += bsx[e];
            }
            bx = match bx.checked_add(q) {
                Some(n) => n,
                None => break,
            };
        }
        for e in 0..3 {
            row[e] += bsy[e];
        }
        by = match by.checked_add(q) {
            Some(n) => n,
            None => break,
        };
    }
}
