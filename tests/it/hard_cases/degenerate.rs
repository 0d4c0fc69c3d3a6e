//! Slivers, needles, collinear and repeated vertices; huge and tiny triangles; NaN and infinity.

use super::*;

/// Pass: NaN, infinities and coordinates beyond the ±2^20 px guard band are rejected
/// by setup with the reason; at the guard band itself coverage is exact.
#[test]
fn hostile_inputs_are_rejected_cleanly() {
    let ok = [[1.0, 1.0], [30.0, 2.0], [4.0, 40.0]];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..6 {
            let mut t = ok;
            t[i / 2][i % 2] = bad;
            assert_eq!(Setup::new(t, T), Err(Reject::NonFinite));
        }
    }
    let mut far = ok;
    far[1][0] = 2_000_000.0;
    assert_eq!(Setup::new(far, T), Err(Reject::BeyondGuardBand));
    // Right at the guard band the triangle is exact and covers the whole target.
    let g = termrast::raster::GUARD_BAND_PX;
    let huge = [[-g, -g], [g, -g], [0.0, g]];
    assert_all_match_oracle(huge, T);
    assert_eq!(
        coverage(Traversal::Wide, huge, T).covered().count(),
        T.len()
    );
    assert_eq!(
        Setup::new([[-5.0, -5.0], [-1.0, -5.0], [-5.0, -1.0]], T),
        Err(Reject::Offscreen)
    );
}

/// Pass: a triangle whose clipped polygon rounding makes slightly non-convex (w of
/// 1e34 beside w of 1: the guard-band planes then cut it more than twice) is dropped
/// instead of outgrowing the polygon's nine vertices; it used to index past them.
#[test]
fn clipping_a_polygon_rounding_made_non_convex_does_not_overflow() {
    let target = Target::new(24, 16);
    let guard = guard_band_ndc(target.width, target.height);
    let pos = [
        Vec4::new(0.0, -0.0, 33_554_432.0, 1.038_459_4e34),
        Vec4::new(1.0, -0.333_893, 1.640_763_4, 0.0),
        Vec4::new(2.569_394, 1.0, -1.214_852_7, 0.166_220_95),
    ];
    let tri = pos.map(|pos| ClipVertex { pos, var: () });
    if let Some(poly) = clip_straddling(tri, guard) {
        assert!(poly.vertices().len() <= MAX_CLIPPED);
        assert!(poly.vertices().iter().all(|v| v.pos.w > 0.0));
    }
    // And through the whole pipeline, both windings, every traversal.
    for traversal in Traversal::ALL {
        let shader = Direct {
            attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
            clip: pos.to_vec(),
        };
        let opts = DrawOptions {
            traversal,
            ..DrawOptions::default()
        };
        let mut r = Renderer::new(target);
        let mut color = Exact::default();
        let mut cache = VertexCache::default();
        r.begin_frame(target, &mut color, Vec3::ZERO);
        transform(&shader, 3, &mut cache);
        r.draw(&shader, &cache, &[0, 1, 2, 2, 1, 0], &opts, &mut color);
        assert!(r.depth.to_vec().iter().all(|d| (0.0..=1.0).contains(d)));
    }
}

/// Pass: triangles smaller than one subpixel step are exact (usually empty; a
/// 1/256 px triangle on a centre owned by its left/top edges covers that one pixel).
#[test]
fn tiny_triangles_below_a_subpixel() {
    // Smaller than 1/256 px: they snap to a point (zero area) or to one subpixel step.
    for (x, y) in [(3.5, 3.5), (3.501, 3.499), (10.0, 2.0)] {
        let tri = [[x, y], [x + 0.001, y], [x, y + 0.001]];
        assert_all_match_oracle(tri, T);
    }
    // A 1/256 px right triangle with its corner exactly on a centre: left/top edges own it.
    let tri = [
        [4.5, 4.5],
        [4.5 + 1.0 / 256.0, 4.5],
        [4.5, 4.5 + 1.0 / 256.0],
    ];
    assert_all_match_oracle(tri, T);
    assert_eq!(coverage(Traversal::Scalar, tri, T).covered().count(), 1);
}

/// Pass: a triangle whose clip-space vertices lie far beyond the guard band is
/// clipped to it and still covers exactly the part of the target it should: here,
/// all of it, with finite depth.
#[test]
fn vertices_beyond_the_guard_band_are_clipped_not_lost() {
    let target = Target::new(40, 30);
    for far in [1.0e4f32, 1.0e7, 1.0e12, 1.0e30] {
        let clip = vec![
            Vec4::new(-far, -far, 0.5, 1.0),
            Vec4::new(far, -far, 0.5, 1.0),
            Vec4::new(0.0, far, 0.5, 1.0),
        ];
        let (img, r) = draw(
            &Direct {
                clip,
                attr: vec![Vec3::X, Vec3::Y, Vec3::Z],
            },
            &[0, 1, 2],
            target,
            &DrawOptions::default(),
        );
        assert!(
            img.colors.iter().all(Option::is_some),
            "{far}: covers the target"
        );
        assert!(
            r.depth.to_vec().iter().all(|d| (d - 0.5).abs() < 1e-6),
            "{far}"
        );
        for c in img.colors.iter().flatten() {
            assert!(c.is_finite());
        }
    }
}

/// Pass: NaN or an infinity in any component of any vertex discards the triangle
/// (nothing drawn, counted as rejected), never panics, and leaves the other
/// triangles of the draw untouched.
#[test]
fn nan_and_infinity_anywhere_are_discarded() {
    let target = Target::new(32, 24);
    let good = vec![
        Vec4::new(-0.9, -0.9, 0.5, 1.0),
        Vec4::new(0.9, -0.9, 0.5, 1.0),
        Vec4::new(0.0, 0.9, 0.5, 1.0),
    ];
    let other = vec![
        Vec4::new(-1.0, 0.95, 0.2, 1.0),
        Vec4::new(-0.95, 1.0, 0.2, 1.0),
        Vec4::new(-1.0, 1.0, 0.2, 1.0),
    ];
    let (reference, _) = draw(
        &Direct {
            clip: other.clone(),
            attr: vec![Vec3::ONE; 3],
        },
        &[0, 1, 2],
        target,
        &DrawOptions::default(),
    );
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for v in 0..3 {
            for c in 0..4 {
                let mut clip = good.clone();
                clip[v][c] = bad;
                clip.extend(other.clone());
                let (img, r) = draw(
                    &Direct {
                        clip,
                        attr: vec![Vec3::ONE; 6],
                    },
                    &[0, 1, 2, 3, 4, 5],
                    target,
                    &DrawOptions::default(),
                );
                assert_eq!(r.stats.rejected, 1, "{bad} in vertex {v} component {c}");
                assert_eq!(
                    img.colors, reference.colors,
                    "{bad} in vertex {v} component {c}"
                );
            }
        }
    }
}
