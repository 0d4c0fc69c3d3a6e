//! Models' frames held to the bits they had when the viewer, `render` and the
//! benchmark drew models apart from scenes: hashes of the colour and depth of frames
//! (every wire mode, culling on and off, every interpolation, the benchmark's fixed
//! camera and the viewer's framed one, zoomed, at several pixel aspects) and of the
//! viewport's cells in every glyph and colour mode, and the inspector's text, for the
//! teapot, the bunny and a sphere. The snapshots were recorded from that model path
//! (`StandardFrame`, `Viewport::render` and the model inspector), before models
//! became one-object scenes.

use std::fmt::Write as _;

use termrast::raster::interp::Interpolation;
use termrast::raster::{Target, Traversal};
use termrast::render::wire::Mode;
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};
use termrast::terminal::{ColorMode, GlyphMode};
use termrast::tui::app::App;
use termrast::tui::inspector::inspector_text;
use termrast::tui::viewport::ViewSettings;

const MODELS: [&str; 3] = ["teapot", "bunny", "sphere:20000"];

/// FNV-1a, 64 bits.
pub fn hash(bytes: impl IntoIterator<Item = u8>) -> u64 {
    bytes.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The colour hash recorded for a shot of a model (by [`Shot::name`]).
pub fn recorded_colour(spec: &str, shot: &str) -> u64 {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/it/snapshots/it__model_frames__model_frames_keep_their_bits.snap"
    );
    let text = std::fs::read_to_string(path).expect("the recorded frames");
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix(&format!("{spec} {shot}: colour ")))
        .unwrap_or_else(|| panic!("no recorded frame {spec} {shot}"));
    u64::from_str_radix(&line[..16], 16).expect("a hash")
}

/// One frame of a model as the command line and the tests draw it.
#[derive(Clone, Copy, Debug)]
struct Shot {
    /// The benchmark's fixed camera, else the viewer's framing at `zoom`.
    fixed: bool,
    angle: f32,
    tilt: f32,
    zoom: f32,
    pixel_aspect: f32,
    mode: Mode,
    cull: bool,
    interpolation: Interpolation,
    traversal: Traversal,
    size: (u32, u32),
}

impl Shot {
    const PLAIN: Shot = Shot {
        fixed: false,
        angle: 0.0,
        tilt: 0.0,
        zoom: 1.0,
        pixel_aspect: 1.0,
        mode: Mode::Fill,
        cull: false,
        interpolation: Interpolation::Perspective,
        traversal: Traversal::Wide,
        size: (160, 120),
    };

    fn name(&self) -> String {
        format!(
            "{} a{} t{} z{} pa{} {:?}{} {:?} {} {}x{}",
            if self.fixed { "fixed" } else { "framed" },
            self.angle,
            self.tilt,
            self.zoom,
            self.pixel_aspect,
            self.mode,
            if self.cull { " cull" } else { "" },
            self.interpolation,
            self.traversal.name(),
            self.size.0,
            self.size.1
        )
    }
}

fn shots() -> Vec<Shot> {
    let mut v = Vec::new();
    for angle in [0.0, 0.35, 1.55] {
        for cull in [false, true] {
            v.push(Shot {
                fixed: true,
                angle,
                cull,
                ..Shot::PLAIN
            });
        }
    }
    for (angle, tilt) in [(0.0, 0.0), (0.6, 0.25), (2.2, -0.7), (4.0, 1.3)] {
        for mode in Mode::ALL {
            for cull in [false, true] {
                v.push(Shot {
                    angle,
                    tilt,
                    mode,
                    cull,
                    ..Shot::PLAIN
                });
            }
        }
    }
    for zoom in [0.3, 2.5, 7.0] {
        for pixel_aspect in [0.5, 1.5] {
            v.push(Shot {
                angle: 1.1,
                tilt: 0.4,
                zoom,
                pixel_aspect,
                mode: Mode::FillWire,
                size: (200, 96),
                ..Shot::PLAIN
            });
        }
        // Close up the near plane cuts the model open: culling shows.
        v.push(Shot {
            angle: 1.1,
            tilt: 0.4,
            zoom,
            cull: true,
            ..Shot::PLAIN
        });
    }
    for interpolation in Interpolation::ALL {
        v.push(Shot {
            angle: 0.6,
            tilt: 0.25,
            pixel_aspect: 0.5,
            interpolation,
            ..Shot::PLAIN
        });
    }
    for traversal in Traversal::ALL {
        v.push(Shot {
            angle: 0.6,
            tilt: 0.25,
            interpolation: Interpolation::Affine,
            traversal,
            size: (97, 61),
            ..Shot::PLAIN
        });
    }
    v
}

/// The frame's colour, its depth bits when it fills triangles, and its triangles
/// drawn and culled.
fn draw(spec: &str, s: &Shot) -> (Vec<[u8; 4]>, Option<Vec<u32>>, [u64; 2]) {
    let mut scene = if s.fixed {
        Scene::standard(spec)
    } else {
        Scene::for_model(spec)
    }
    .unwrap();
    scene.set_mode(s.mode);
    scene.set_cull(s.cull);
    let mut frame = SceneFrame::new(&scene);
    frame.interpolation = s.interpolation;
    frame.traversal = s.traversal;
    let view = SceneView {
        time: 0.0,
        yaw: s.angle,
        pitch: s.tilt,
        zoom: s.zoom,
        pixel_aspect: s.pixel_aspect,
    };
    frame.draw(&scene, Target::new(s.size.0, s.size.1), &view);
    let depth = s.mode.fills().then(|| {
        frame
            .renderer
            .depth
            .to_vec()
            .iter()
            .map(|d| d.to_bits())
            .collect()
    });
    (
        frame.color.0,
        depth,
        [frame.stats.drawn, frame.stats.culled],
    )
}

/// A viewer of the model, paused.
fn viewer(spec: &str, settings: ViewSettings) -> App {
    let mut app = App::new(Scene::for_model(spec).unwrap(), settings);
    app.paused = true;
    app
}

/// The viewer's cells (glyph and colours) after a frame of `cols × rows`.
fn cells(app: &mut App, cols: u16, rows: u16) -> String {
    app.viewport
        .render(&mut app.scene, &app.settings, (cols, rows));
    let mut out = String::new();
    for c in &app.viewport.cells {
        let _ = write!(out, "{}{:?}{:?}", c.ch, c.fg, c.bg);
    }
    out
}

/// The inspector's text for cell `(cx, cy)`, sample `sub`.
fn inspector(app: &App, cx: u16, cy: u16, sub: usize) -> String {
    inspector_text(&app.viewport, &app.scene, cx, cy, sub).plain()
}

fn set_look(app: &mut App, mode: Mode, cull: bool) {
    app.scene.scene.set_mode(mode);
    app.scene.scene.set_cull(cull);
}

#[test]
fn model_frames_keep_their_bits() {
    let mut out = String::new();
    for spec in MODELS {
        for s in shots() {
            let (color, depth, [drawn, culled]) = draw(spec, &s);
            let covered = color.iter().filter(|p| p[3] == 255).count();
            assert!(
                covered > 100 || culled > 1000,
                "{spec} {}: {covered} pixels drawn",
                s.name()
            );
            let depth = depth.map_or("-".to_string(), |d| {
                format!("{:016x}", hash(d.iter().flat_map(|b| b.to_le_bytes())))
            });
            let _ = writeln!(
                out,
                "{spec} {}: colour {:016x} depth {depth} drawn {drawn} culled {culled}",
                s.name(),
                hash(color.iter().flatten().copied())
            );
        }
    }
    insta::assert_snapshot!(out);
}

#[test]
fn model_viewports_keep_their_cells() {
    let mut out = String::new();
    for spec in MODELS {
        for glyphs in GlyphMode::ALL {
            for colors in ColorMode::ALL {
                let settings = ViewSettings {
                    glyphs,
                    colors,
                    angle: 2.0,
                    ..ViewSettings::default()
                };
                let mut app = viewer(spec, settings);
                for (mode, cull) in [
                    (Mode::Fill, false),
                    (Mode::Wire, true),
                    (Mode::FillWire, true),
                ] {
                    set_look(&mut app, mode, cull);
                    let cells = cells(&mut app, 70, 22);
                    let _ = writeln!(
                        out,
                        "{spec} {} {} {mode:?}{}: {:016x}",
                        glyphs.name(),
                        colors.name(),
                        if cull { " cull" } else { "" },
                        hash(cells.bytes())
                    );
                }
            }
        }
    }
    insta::assert_snapshot!(out);
}

/// The inspector's text on a grid of cells, filled and with edges.
#[test]
fn model_inspector_keeps_its_text() {
    let mut out = String::new();
    for spec in ["teapot", "bunny"] {
        for mode in [Mode::Fill, Mode::FillWire] {
            let settings = ViewSettings {
                glyphs: GlyphMode::Quadrant,
                colors: ColorMode::None,
                ..ViewSettings::default()
            };
            let mut app = viewer(spec, settings);
            set_look(&mut app, mode, mode == Mode::FillWire);
            cells(&mut app, 60, 20);
            let mut text = String::new();
            for cy in (1..20).step_by(3) {
                for cx in (2..60).step_by(5) {
                    text += &inspector(&app, cx, cy, usize::from(cx % 4));
                }
            }
            assert!(text.matches("covered by").count() > 20, "{spec}");
            let _ = writeln!(out, "{spec} {mode:?}: {:016x}", hash(text.bytes()));
        }
    }
    insta::assert_snapshot!(out);
}
