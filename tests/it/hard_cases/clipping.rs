//! w ≤ 0, w = 0, tiny w, triangles entirely behind the eye or straddling the near plane.

use super::*;

/// Pass: vertices with w < 0, w = 0, w = −0 or w = 1e-30 never produce a pixel from
/// behind the eye or a depth outside [0, 1]; triangles entirely behind draw nothing.
#[test]
fn vertices_behind_or_at_the_eye_never_leak() {
    let target = Target::new(48, 32);
    let front = Vec4::new(0.0, 0.5, 0.5, 1.0);
    let cases = [
        ("w < 0", Vec4::new(0.3, -0.4, -0.8, -0.5)),
        ("w = 0", Vec4::new(0.3, -0.4, 0.0, 0.0)),
        ("w = 1e-30", Vec4::new(0.3, -0.4, 1e-31, 1e-30)),
        ("w = -0", Vec4::new(0.3, -0.4, -0.0, -0.0)),
        ("nan", Vec4::new(f32::NAN, 0.0, 0.5, 1.0)),
        ("inf", Vec4::new(f32::INFINITY, 0.0, 0.5, 1.0)),
    ];
    for (name, bad) in cases {
        for (i0, i1) in [(0, 1), (1, 0)] {
            let clip = vec![front, Vec4::new(-0.6, -0.6, 0.5, 1.0), bad];
            let mut idx = [0u32, 1, 2];
            idx.swap(i0, i1);
            let (img, r) = draw(
                &Direct {
                    clip,
                    attr: vec![Vec3::ONE; 3],
                },
                &idx,
                target,
                &DrawOptions::default(),
            );
            for (i, c) in img.colors.iter().enumerate() {
                if c.is_some() {
                    let d = r.depth.at(i);
                    assert!(
                        d.is_finite() && (0.0..=1.0).contains(&d),
                        "{name}: depth {d}"
                    );
                }
            }
        }
        // Entirely behind the eye: nothing at all.
        let clip = vec![
            Vec4::new(0.0, 0.0, -1.0, -1.0),
            Vec4::new(0.5, 0.0, -1.0, -1.0),
            bad,
        ];
        let (img, r) = draw(
            &Direct {
                clip,
                attr: vec![Vec3::ONE; 3],
            },
            &[0, 1, 2],
            target,
            &DrawOptions::default(),
        );
        assert!(img.colors.iter().all(Option::is_none), "{name}");
        assert_eq!(r.stats.rejected, 1);
    }
}

/// Pass: a triangle straddling the near plane draws exactly the pixels of the part in
/// front (the polygon clipped by hand), with the same attributes.
#[test]
fn near_plane_straddling_renders_exactly_the_front_part() {
    // Clip space chosen so the near-plane crossings are at t = 1/2 exactly (z goes
    // from −1 to 1 along the cut edges): clipping is exact in f32, and the result
    // must equal drawing the hand-clipped quad.
    let target = Target::new(64, 48);
    let a = Vec4::new(-0.5, -0.5, 0.5, 1.0);
    let b = Vec4::new(0.6, -0.4, 0.5, 1.0);
    let c = Vec4::new(0.1, 0.7, -0.5, 1.0); // z < 0: in front of the eye but before near
    let attr = vec![Vec3::X, Vec3::Y, Vec3::Z];
    let (img, r) = draw(
        &Direct {
            clip: vec![a, b, c],
            attr: attr.clone(),
        },
        &[0, 1, 2],
        target,
        &DrawOptions::default(),
    );
    assert_eq!(r.stats.clipped, 1);
    let mid = |p: Vec4, q: Vec4| (p + q) * 0.5;
    let quad = vec![a, b, mid(b, c), mid(a, c)];
    let qattr = vec![
        Vec3::X,
        Vec3::Y,
        (Vec3::Y + Vec3::Z) * 0.5,
        (Vec3::X + Vec3::Z) * 0.5,
    ];
    let (want, _) = draw(
        &Direct {
            clip: quad,
            attr: qattr,
        },
        &[0, 1, 2, 0, 2, 3],
        target,
        &DrawOptions::default(),
    );
    let covered = |e: &Exact| e.colors.iter().map(Option::is_some).collect::<Vec<_>>();
    assert_eq!(covered(&img), covered(&want));
    for (g, w) in img.colors.iter().zip(&want.colors) {
        if let (Some(g), Some(w)) = (g, w) {
            assert!((*g - *w).abs().max_element() < 1e-5);
        }
    }
}
