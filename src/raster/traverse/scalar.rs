use crate::raster::{CoverageSink, PixelRect, Setup};

/// The reference traversal: start from the edge values at the bounding box's origin,
/// add `I` per pixel and `J` per row, plain `i64`, one test per pixel.
pub fn scalar<S: CoverageSink>(s: &Setup, sink: &mut S) {
    walk_rect(s.bbox, s.edges_at_origin(), s.step_x(), s.step_y(), sink);
}

/// The per-pixel walk of rectangle `r`, whose top-left pixel has edge values `origin`;
/// `scalar` walks the whole box with it and `block` its partial blocks.
#[inline]
pub(super) fn walk_rect<S: CoverageSink>(
    r: PixelRect,
    origin: [i64; 3],
    sx: [i64; 3],
    sy: [i64; 3],
    sink: &mut S,
) {
    let mut cy = origin;
    for y in r.y0..=r.y1 {
        let mut cx = cy;
        for x in r.x0..=r.x1 {
            if cx[0] >= 0 && cx[1] >= 0 && cx[2] >= 0 {
                sink.pixel(x, y);
            }
            for e in 0..3 {
                cx[e] += sx[e];
            }
        }
        for e in 0..3 {
            cy[e] += sy[e];
        }
    }
}
