//! Fuzzing the whole pipeline with arbitrary bit patterns, and the clip classification.

use super::*;

/// Interesting f32 values, mixed with arbitrary bit patterns.
fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => any::<u32>().prop_map(f32::from_bits),
        1 => prop::sample::select(vec![0.0f32, -0.0, 1.0, -1.0, 1e-30, -1e-30, 1e30, -1e30,
            f32::MAX, f32::MIN, f32::MIN_POSITIVE, f32::NAN, f32::INFINITY, f32::NEG_INFINITY]),
        2 => -4.0f32..4.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// Pass: arbitrary f32 bit patterns as clip-space vertices, through transform,
    /// clipping, setup, every traversal, depth and shading, and the probe: no panic,
    /// no write outside the target, depth stays in [0, 1] where written.
    #[test]
    fn arbitrary_vertices_never_panic_or_escape(
        v in prop::array::uniform12(any_f32()),
        traversal in prop::sample::select(Traversal::ALL.to_vec()),
        px in 0u32..24, py in 0u32..16,
    ) {
        let target = Target::new(24, 16);
        let clip: Vec<Vec4> = v.chunks(4).map(|c| Vec4::new(c[0], c[1], c[2], c[3])).collect();
        let shader = Direct { attr: vec![Vec3::X, Vec3::Y, Vec3::Z], clip };
        let mut r = Renderer::new(target);
        let mut out = Exact::default();
        let mut cache = VertexCache::default();
        r.begin_frame(target, &mut out, Vec3::ZERO);
        transform(&shader, 3, &mut cache);
        let opts = DrawOptions { traversal, ..DrawOptions::default() };
        r.draw(&shader, &cache, &[0, 1, 2, 2, 1, 0], &opts, &mut out);
        for (i, &d) in r.depth.to_vec().iter().enumerate() {
            if out.colors[i].is_some_and(|c| c.is_finite()) {
                prop_assert!((0.0..=1.0).contains(&d), "depth {d}");
            }
        }
        let p = probe(&cache, &[0, 1, 2, 2, 1, 0], target, &opts, px, py);
        prop_assert_eq!(p.final_depth.to_bits(), r.depth.at((py * 24 + px) as usize).to_bits());
    }

    /// Pass: arbitrary f64 bit patterns as 2D vertices never make a traversal report
    /// a pixel outside the target or the bounding box, and exact traversals equal the
    /// oracle whenever setup accepts the triangle.
    #[test]
    fn arbitrary_2d_vertices_stay_inside(bits in prop::array::uniform6(any::<u64>())) {
        let v = bits.map(f64::from_bits);
        let tri = [[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]];
        for t in Traversal::ALL {
            let _ = coverage(t, tri, T);
        }
    }
}

/// A clip-space coordinate: ordinary values, values on and near the planes, and the
/// hostile ones (zero, subnormal-small, huge, infinite, NaN).
fn clip_coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -3.0f32..3.0,
        1 => Just(0.0f32),
        1 => Just(-0.0f32),
        1 => Just(1.0f32),
        1 => Just(1e-30f32),
        1 => Just(-1e-30f32),
        1 => Just(1e30f32),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NAN),
    ]
}

/// The clip classification as first written: plane by plane over the distances, no
/// outcodes. The renderer classifies from per-vertex outcodes instead.
fn classify_reference(tri: &[Vec4; 3], guard: [f32; 2]) -> ClipOutcome {
    if tri.iter().any(|p| !p.is_finite()) {
        return ClipOutcome::Rejected;
    }
    let d = tri.map(|p| {
        [
            p.z,
            p.w - p.z,
            guard[0] * p.w - p.x,
            guard[0] * p.w + p.x,
            guard[1] * p.w - p.y,
            guard[1] * p.w + p.y,
        ]
    });
    let mut outcome = ClipOutcome::Inside;
    for plane in 0..6 {
        let outside = d.iter().filter(|d| d[plane] < 0.0).count();
        if outside == 3 {
            return ClipOutcome::Rejected;
        }
        if outside > 0 {
            outcome = ClipOutcome::Clipped;
        }
    }
    if outcome == ClipOutcome::Inside && !tri.iter().all(|p| p.w > 0.0) {
        return ClipOutcome::Rejected;
    }
    outcome
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Outcodes combine to exactly the plane-by-plane classification, hostile values
    /// included.
    #[test]
    fn outcodes_classify_as_the_planes_do(c in prop::array::uniform12(clip_coord())) {
        let tri = [0, 1, 2].map(|i| Vec4::new(c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]));
        let guard = guard_band_ndc(64, 32);
        let codes = tri.map(|p| outcode(p, guard));
        prop_assert_eq!(classify_codes(codes), classify_reference(&tri, guard), "{:?}", tri);
    }
}
