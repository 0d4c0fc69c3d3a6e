//! Transitional: the model path (`StandardFrame`, `Viewport::render`) against the
//! scene path, frame by frame.

use termrast::cli::view_cmd::load_model;
use termrast::raster::interp::Interpolation;
use termrast::raster::{Target, Traversal};
use termrast::render::standard::{Model, StandardFrame, StandardView};
use termrast::render::wire::Mode;
use termrast::render::{Cull, DrawOptions, Rgba8};
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::viewport::{ViewSettings, Viewport};

struct Case {
    fixed: bool,
    angle: f32,
    tilt: f32,
    zoom: f32,
    aspect: f32,
    mode: Mode,
    cull: bool,
    interpolation: Interpolation,
    traversal: Traversal,
    size: (u32, u32),
}

fn old_frame(model: &Model, c: &Case) -> (Vec<[u8; 4]>, Vec<u32>, u64, u64) {
    let target = Target::new(c.size.0, c.size.1);
    let mut view = if c.fixed {
        StandardView::at(c.angle)
    } else {
        StandardView::framed(model, c.zoom, c.angle)
    };
    view.tilt = c.tilt;
    view.pixel_aspect = c.aspect;
    let opts = DrawOptions {
        cull: if c.cull { Cull::Back } else { Cull::None },
        interpolation: c.interpolation,
        traversal: c.traversal,
        ..DrawOptions::default()
    };
    let mut f = StandardFrame::new(target);
    let mut color = Rgba8::default();
    let w = f.draw(model, &view, target, &opts, c.mode, &mut color);
    let depth = if c.mode.fills() {
        f.renderer
            .depth
            .to_vec()
            .iter()
            .map(|d| d.to_bits())
            .collect()
    } else {
        Vec::new()
    };
    (color.0, depth, w.lines, w.pixels)
}

fn new_frame(scene: &Scene, c: &Case) -> (Vec<[u8; 4]>, Vec<u32>, u64, u64) {
    let target = Target::new(c.size.0, c.size.1);
    let mut scene = scene.clone();
    if c.fixed {
        scene.camera = termrast::camera::Camera::default();
        scene.rig = termrast::scene::Rig::Turntable { framing: None };
    }
    scene.set_mode(c.mode);
    scene.set_cull(c.cull);
    let mut f = SceneFrame::new(&scene);
    f.interpolation = c.interpolation;
    f.traversal = c.traversal;
    let view = SceneView {
        time: 0.0,
        yaw: c.angle,
        pitch: c.tilt,
        zoom: c.zoom,
        pixel_aspect: c.aspect,
    };
    f.draw(&scene, target, &view);
    let depth = if c.mode.fills() {
        f.renderer
            .depth
            .to_vec()
            .iter()
            .map(|d| d.to_bits())
            .collect()
    } else {
        Vec::new()
    };
    (f.color.0.clone(), depth, f.wire.lines, f.wire.pixels)
}

#[test]
fn frames_of_both_paths() {
    let mut bad = Vec::new();
    let mut n = 0;
    for spec in ["teapot", "bunny", "sphere:20000"] {
        let model = load_model(spec).unwrap();
        let scene = Scene::for_model(spec).unwrap();
        let mut cases = Vec::new();
        for fixed in [false, true] {
            for (angle, tilt) in [(0.0, 0.0), (0.6, 0.25), (2.2, -0.7), (4.0, 1.3)] {
                for mode in Mode::ALL {
                    for cull in [false, true] {
                        cases.push(Case {
                            fixed,
                            angle,
                            tilt,
                            zoom: 1.0,
                            aspect: 1.0,
                            mode,
                            cull,
                            interpolation: Interpolation::Perspective,
                            traversal: Traversal::Wide,
                            size: (160, 120),
                        });
                    }
                }
            }
        }
        for zoom in [0.3, 0.8, 2.5, 7.0] {
            for aspect in [0.5, 0.25, 1.5] {
                cases.push(Case {
                    fixed: false,
                    angle: 1.1,
                    tilt: 0.4,
                    zoom,
                    aspect,
                    mode: Mode::FillWire,
                    cull: false,
                    interpolation: Interpolation::Perspective,
                    traversal: Traversal::Wide,
                    size: (200, 96),
                });
            }
        }
        for interpolation in Interpolation::ALL {
            for traversal in Traversal::ALL {
                cases.push(Case {
                    fixed: false,
                    angle: 0.6,
                    tilt: 0.25,
                    zoom: 1.0,
                    aspect: 0.5,
                    mode: Mode::Fill,
                    cull: false,
                    interpolation,
                    traversal,
                    size: (120, 90),
                });
            }
        }
        for c in &cases {
            n += 1;
            let (a, b) = (old_frame(&model, c), new_frame(&scene, c));
            let what = format!(
                "{spec} fixed {} angle {} tilt {} zoom {} aspect {} {:?} cull {} {:?} {:?}",
                c.fixed,
                c.angle,
                c.tilt,
                c.zoom,
                c.aspect,
                c.mode,
                c.cull,
                c.interpolation,
                c.traversal
            );
            if a.0 != b.0 {
                let d = a.0.iter().zip(&b.0).filter(|(x, y)| x != y).count();
                bad.push(format!("{what}: colour differs at {d} pixels"));
            }
            if a.1 != b.1 {
                bad.push(format!("{what}: depth differs"));
            }
            if (a.2, a.3) != (b.2, b.3) {
                eprintln!("{what}: wire counts {:?} vs {:?}", (a.2, a.3), (b.2, b.3));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{n} cases, {} differ:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn viewport_cells_of_both_paths() {
    let mut bad = Vec::new();
    for spec in ["teapot", "bunny", "sphere:20000"] {
        let model = load_model(spec).unwrap();
        let scene = Scene::for_model(spec).unwrap();
        for glyphs in GlyphMode::ALL {
            for colors in ColorMode::ALL {
                for (mode, cull) in [
                    (Mode::Fill, false),
                    (Mode::Wire, true),
                    (Mode::FillWire, true),
                ] {
                    let settings = ViewSettings {
                        glyphs,
                        colors,
                        mode,
                        cull,
                        angle: 2.0,
                        ..ViewSettings::default()
                    };
                    let mut old = Viewport::default();
                    old.render(&model, &settings, 70, 22);
                    let mut scene = scene.clone();
                    scene.set_mode(mode);
                    scene.set_cull(cull);
                    let mut frame = SceneFrame::new(&scene);
                    let mut new = Viewport::default();
                    new.render_scene(&scene, &mut frame, &settings, (70, 22), 0.0);
                    if old.color.0 != new.color.0 || old.cells != new.cells {
                        bad.push(format!("{spec} {glyphs:?} {colors:?} {mode:?} {cull}"));
                    }
                }
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn line_panel_of_both_paths() {
    use termrast::tui::inspector::line_at_sample;
    use termrast::tui::viewport::SceneState;
    for spec in ["teapot", "bunny", "sphere:2000"] {
        let model = load_model(spec).unwrap();
        for mode in Mode::ALL {
            let settings = ViewSettings {
                glyphs: GlyphMode::Quadrant,
                colors: ColorMode::None,
                mode,
                ..ViewSettings::default()
            };
            let mut old = Viewport::default();
            old.render(&model, &settings, 60, 20);
            let mut scene = Scene::for_model(spec).unwrap();
            scene.set_mode(mode);
            let frame = SceneFrame::new(&scene);
            let mut s = SceneState {
                scene,
                frame,
                time: 0.0,
            };
            let mut new = Viewport::default();
            new.render_scene(&s.scene, &mut s.frame, &settings, (60, 20), 0.0);
            let (mut same, mut edge_differs, mut other) = (0, 0, 0);
            for cy in 0..20 {
                for cx in 0..60 {
                    for sub in 0..4 {
                        let a = line_at_sample(&old, &model, None, (cx, cy, sub));
                        let b = line_at_sample(&new, &model, Some(&s), (cx, cy, sub));
                        match (a, b) {
                            (Some((fa, la)), Some((fb, lb)))
                                if fa.edge == fb.edge && fa.k == fb.k && la == lb =>
                            {
                                same += 1
                            }
                            (Some((_, la)), Some((_, lb)))
                                if la.line.a == lb.line.a && la.line.b == lb.line.b =>
                            {
                                edge_differs += 1
                            }
                            (None, None) => same += 1,
                            _ => other += 1,
                        }
                    }
                }
            }
            eprintln!(
                "{spec} {mode:?}: same {same}, only the edge ids differ {edge_differs}, other {other}"
            );
        }
    }
}
