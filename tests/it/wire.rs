//! Wireframes: unique edges, hidden-line removal, and the line probe against the image.

use glam::{Vec3, Vec4};
use termrast::mesh::Mesh;
use termrast::raster::Target;
use termrast::render::target::to_u8;
use termrast::render::wire::{Mode, WIRE_COLOR, draw_wireframe, unique_edges};
use termrast::render::{DrawOptions, Renderer, Rgba8, VertexCache, transform};
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};

use crate::common::Direct;

#[test]
fn shared_edges_are_drawn_once() {
    assert_eq!(
        unique_edges(&[0, 1, 2, 2, 1, 3]),
        vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    );
    let teapot = Mesh::teapot();
    let edges = unique_edges(&teapot.indices);
    assert!(edges.windows(2).all(|w| w[0] < w[1]));
    // Every edge belongs to a triangle, every triangle edge is listed.
    for t in teapot.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if a != b {
                assert!(edges.binary_search(&[a.min(b), a.max(b)]).is_ok());
            }
        }
    }
    assert!(
        edges.len() < teapot.indices.len(),
        "shared edges were merged"
    );
}

#[test]
fn hidden_lines_behind_a_face_are_removed() {
    // A near quad covering the middle, and a far quad whose edges cross behind it.
    let target = Target::new(64, 64);
    let quad = |s: f32, z: f32| {
        [[-s, -s], [s, -s], [s, s], [-s, s]].map(|p| Vec4::new(p[0], p[1], z, 1.0))
    };
    let mut verts = quad(0.5, 0.2).to_vec();
    verts.extend(quad(0.9, 0.8).map(|v| Vec4::new(v.x * 0.3, v.y * 1.1, v.z, v.w)));
    let shader = Direct {
        attr: vec![Vec3::splat(0.5); verts.len()],
        clip: verts,
    };
    let mut cache = VertexCache::default();
    transform(&shader, 8, &mut cache);
    let mut r = Renderer::new(target);
    let mut color = Rgba8::default();
    r.begin_frame(target, &mut color, Vec3::ZERO);
    r.draw(
        &shader,
        &cache,
        &[0, 1, 2, 0, 2, 3],
        &DrawOptions::default(),
        &mut color,
    );
    let far_edges = [[4, 5], [5, 6], [6, 7], [4, 7]];
    let near_edges = [[0, 1], [1, 2], [2, 3], [0, 3]];
    let wire = [
        to_u8(WIRE_COLOR.x),
        to_u8(WIRE_COLOR.y),
        to_u8(WIRE_COLOR.z),
        255,
    ];
    let mut hidden = color.clone();
    draw_wireframe(
        &cache,
        &far_edges,
        target,
        Some(&r.depth),
        WIRE_COLOR,
        &mut hidden,
    );
    let mut all = color.clone();
    draw_wireframe(&cache, &far_edges, target, None, WIRE_COLOR, &mut all);
    let (mut behind, mut outside) = (0, 0);
    for i in 0..target.len() {
        let under_near = color.0[i][3] == 255;
        if all.0[i] == wire {
            if under_near {
                behind += 1;
                assert_ne!(
                    hidden.0[i], wire,
                    "far edge drawn through the near quad at {i}"
                );
            } else {
                outside += 1;
                assert_eq!(hidden.0[i], wire, "visible far edge missing at {i}");
            }
        }
    }
    assert!(behind > 10 && outside > 10);
    // The near quad's own edges survive the depth test (the bias at work).
    let mut own = color.clone();
    let n = draw_wireframe(
        &cache,
        &near_edges,
        target,
        Some(&r.depth),
        WIRE_COLOR,
        &mut own,
    );
    let m = draw_wireframe(
        &cache,
        &near_edges,
        target,
        None,
        WIRE_COLOR,
        &mut color.clone(),
    );
    assert_eq!(n, m);
}

#[test]
fn line_probe_explains_every_wire_pixel() {
    let mut scene = Scene::standard("teapot").unwrap();
    let target = Target::new(96, 64);
    let wire = [
        to_u8(WIRE_COLOR.x),
        to_u8(WIRE_COLOR.y),
        to_u8(WIRE_COLOR.z),
        255,
    ];
    for mode in [Mode::Wire, Mode::FillWire] {
        scene.set_mode(mode);
        let mut frame = SceneFrame::new(&scene);
        let view = SceneView {
            yaw: 0.4,
            ..SceneView::default()
        };
        frame.draw(&scene, target, &view);
        // Hidden lines are tested against the filled mesh's depth.
        assert_eq!(frame.renderer.has_depth(), mode.fills());
        let mut lit = 0;
        for y in 0..target.height {
            for x in 0..target.width {
                let hits: Vec<_> = frame
                    .probe_lines(&scene, x, y)
                    .into_iter()
                    .map(|(_, h)| h)
                    .collect();
                let visible: Vec<_> = hits.iter().filter(|h| h.visible).collect();
                let is_wire = frame.color.0[(y * target.width + x) as usize] == wire;
                assert_eq!(is_wire, !visible.is_empty(), "({x},{y}) in {mode:?}");
                for h in &hits {
                    assert_eq!(h.step.pixel, (i64::from(x), i64::from(y)));
                    if let Some((d, _, _)) = h.step.decision {
                        assert_eq!(d, h.screen.line.d_at(h.step.k));
                    }
                }
                lit += usize::from(is_wire);
            }
        }
        assert!(lit > 300, "{mode:?}: {lit}");
    }
}
