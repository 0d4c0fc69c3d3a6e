use crate::raster::{CoverageSink, Setup};

/// Seed 000 §2: start from F at the bbox origin, add `I` per pixel and `J` per row.
/// The reference traversal: plain `i64`, one test per pixel.
pub fn scalar<S: CoverageSink>(s: &Setup, sink: &mut S) {
    let b = s.bbox;
    let (sx, sy) = (s.step_x(), s.step_y());
    let mut cy = s.edges_at_origin();
    for y in b.y0..=b.y1 {
        let mut cx = cy;
        for x in b.x0..=b.x1 {
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
