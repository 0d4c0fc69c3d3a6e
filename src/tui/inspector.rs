//! The inspector and line panels: the raster state of one cell, from the probe, in
//! the names `docs/rasterization.md` defines (F01, F02, F03, u, v, w, depth, octant, dx, dy, incrE,
//! incrNE, d).

use glam::Vec3;

use crate::raster::line::Move;
use crate::raster::samples::grid_side;
use crate::render::probe::{DepthOutcome, Probe, ProbeRecord};
use crate::render::target::luminance;
use crate::render::wire::ScreenLine;
use crate::scene::render::ShadedProbe;
use crate::terminal::GlyphMode;
use crate::terminal::glyphs::{Sample, explain};

use super::panel::PanelText;
use super::viewport::{SceneState, Viewport};

/// The sample pixel of sub-sample `sub` of cell `(cx, cy)`.
#[must_use]
pub fn sample_pixel(vp: &Viewport, cx: u16, cy: u16, sub: usize) -> (u32, u32) {
    let (sx, sy) = vp.settings.glyphs.dims();
    let sub = sub as u32 % (sx * sy);
    (u32::from(cx) * sx + sub % sx, u32::from(cy) * sy + sub / sx)
}

fn hex(c: Option<[u8; 3]>) -> String {
    c.map_or("default".into(), |c| {
        format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
    })
}

/// The first lines of the inspector: the cell's glyph and colours and why; with the
/// cell's samples and their count. `None` outside the view.
fn cell_header(
    vp: &Viewport,
    cx: u16,
    cy: u16,
) -> Option<(PanelText, [Sample; GlyphMode::MAX_SAMPLES], usize)> {
    let g = vp.cell(cx, cy)?;
    let (samples, n) = vp.samples(cx, cy);
    let mut t = PanelText::default();
    t.fields(
        0,
        [
            format!("cell ({cx},{cy})"),
            format!("glyph '{}'", g.ch),
            format!("fg {}", hex(g.fg)),
            format!("bg {}", hex(g.bg)),
        ],
    );
    t.prose(2, &explain(vp.settings.glyphs, &samples[..n], g));
    Some((t, samples, n))
}

/// The samples the panel lists: all of a small cell, the selected sample's row of a
/// 4 × 8 one (32 lines would push the overdraw list off the panel).
fn listed(vp: &Viewport, n: usize, sub: usize) -> std::ops::Range<usize> {
    if n <= 8 {
        return 0..n;
    }
    let sx = vp.settings.glyphs.dims().0 as usize;
    let row = (sub % n) / sx;
    row * sx..(row + 1) * sx
}

/// A probe record with the colour its fragment was shaded.
type ShadedRecord = ProbeRecord<Option<Vec3>>;

/// What the probe of a scene pixel says, all objects together: the object and the
/// record in the framebuffer, if any, and how many triangles' boxes hold the pixel.
fn seen(probes: &[ShadedProbe]) -> (Option<(usize, &ShadedRecord)>, usize) {
    let touched = probes.iter().map(|p| p.records.len()).sum();
    let winner = probes
        .iter()
        .enumerate()
        .rev()
        .find_map(|(i, p)| p.winner.map(|w| (i, &p.records[w])));
    (winner, touched)
}

/// The inspector text for cell `(cx, cy)`, detailing sub-sample `sub`: the cell's
/// glyph and colours and why, each listed sample's triangle, depth and shade, then
/// for the selected sample every object's overdraw list in draw order (depth carried
/// from object to object), each object with its pipeline's varyings.
#[must_use]
pub fn inspector_text(vp: &Viewport, s: &SceneState, cx: u16, cy: u16, sub: usize) -> PanelText {
    let Some((mut t, _, n)) = cell_header(vp, cx, cy) else {
        let mut t = PanelText::default();
        t.prose(0, "cursor outside the view");
        return t;
    };
    let scene = &s.scene;
    // A scene file's objects are named; a model's default scene is the model, or its
    // parts by material.
    let named = !scene.is_model() || scene.objects.len() > 1;
    let rows = listed(vp, n, sub);
    if rows.len() < n {
        t.fields(
            0,
            [
                format!("samples {}–{} of {n}", rows.start, rows.end - 1),
                "(Tab moves):".into(),
            ],
        );
    } else {
        t.fields(0, [format!("samples ({n} per cell):")]);
    }
    // The selected sample's probes are kept for the overdraw lists below.
    let mut selected = None;
    for k in rows {
        let (x, y) = sample_pixel(vp, cx, cy, k);
        let (fx, fy) = scene_pixel(vp, s, cx, cy, k);
        let probes = s.frame.probe(scene, fx, fy);
        let (winner, touched) = seen(&probes);
        let mark = if k == sub % n { '>' } else { ' ' };
        let at = format!("{mark}s{k} ({x},{y})");
        match winner {
            Some((i, r)) => {
                let of = if named {
                    format!(" of {}", scene.objects[i].desc.name)
                } else {
                    String::new()
                };
                let shade = r.varying.map_or(0.0, luminance);
                // Colour where there is any (materials, vertex colours, textures).
                let shade = match r.varying {
                    Some(c) if c.max_element() - c.min_element() > 1e-3 => {
                        format!("shade {shade:.3} rgb {:.2} {:.2} {:.2}", c.x, c.y, c.z)
                    }
                    _ => format!("shade {shade:.3}"),
                };
                t.fields_or(
                    0,
                    [
                        at.clone(),
                        format!("covered by t{}{of}", r.triangle),
                        format!("depth {:.5}", r.eval.depth),
                        shade.clone(),
                        format!("({touched} touched)"),
                    ],
                    [
                        at,
                        format!("t{}{of}", r.triangle),
                        format!("z {:.5}", r.eval.depth),
                        shade,
                        format!("{touched} touched"),
                    ],
                );
            }
            None => t.fields(
                0,
                [at, "not covered".into(), format!("({touched} touched)")],
            ),
        }
        if k == sub % n {
            selected = Some(probes);
        }
    }
    let (x, y) = sample_pixel(vp, cx, cy, sub);
    let Some(probes) = selected else { return t };
    let side = grid_side(scene.plan.samples);
    if side > 1 {
        let (fx, fy) = scene_pixel(vp, s, cx, cy, sub);
        t.fields(
            0,
            [
                "supersampled:".to_string(),
                format!("probing sample ({fx},{fy})"),
                format!("of its {side}×{side} grid"),
            ],
        );
    }
    t.fields(
        0,
        [
            format!("sample ({x},{y})"),
            "overdraw in draw order:".into(),
        ],
    );
    for ((p, obj), op) in probes.iter().zip(&scene.objects).zip(&scene.plan.objects) {
        if named || op.varyings.color || op.varyings.uv {
            t.fields(
                0,
                [
                    format!("object {}", obj.desc.name),
                    format!(
                        "({})",
                        if op.writes_depth() {
                            "depth test"
                        } else {
                            "no depth test"
                        }
                    ),
                    format!("varyings {}:", op.varyings),
                ],
            );
        }
        overdraw_text(&mut t, p, op.writes_depth());
    }
    t
}

/// The overdraw list of a probe: every triangle whose box holds the pixel, in draw
/// order, with its edge values, barycentrics, depth and depth test.
fn overdraw_text<V>(t: &mut PanelText, p: &Probe<V>, depth_test: bool) {
    if p.records.is_empty() {
        t.prose(2, "no triangle's box holds this sample");
    }
    for (i, r) in p.records.iter().enumerate() {
        let star = if p.winner == Some(i) { "*" } else { " " };
        let e = &r.eval;
        let test = match r.depth {
            DepthOutcome::NotCovered => "not covered".to_string(),
            DepthOutcome::Passed { .. } if !depth_test => "drawn (no depth test)".to_string(),
            DepthOutcome::Passed { against } => format!("passed {:.5} < {:.5}", e.depth, against),
            DepthOutcome::Failed { against } => format!("failed {:.5} >= {:.5}", e.depth, against),
        };
        let piece = if r.clipped {
            format!(".{}", r.piece)
        } else {
            String::new()
        };
        t.fields(
            0,
            [
                format!("{star}t{}{piece}", r.triangle),
                format!("block {}", r.block.name()),
                test,
            ],
        );
        t.fields(
            3,
            [
                format!("F01 {}", e.f[0] + r.setup.bias[0]),
                format!("F02 {}", e.f[1] + r.setup.bias[1]),
                format!("F03 {}", e.f[2] + r.setup.bias[2]),
                format!("area2 {}", r.setup.area2),
            ],
        );
        t.fields(
            3,
            [
                format!("u {:.4}", e.bary[0]),
                format!("v {:.4}", e.bary[1]),
                format!("w {:.4}", e.bary[2]),
                format!(
                    "persp {:.4} {:.4} {:.4}",
                    e.persp[0], e.persp[1], e.persp[2]
                ),
            ],
        );
        t.fields(
            3,
            [
                format!("1/w {:.5}", e.inv_w),
                format!("depth {:.6}", e.depth),
            ],
        );
    }
}

/// The pixel of the scene's (possibly supersampled) frame that stands for sub-sample
/// `sub` of cell `(cx, cy)`: the middle of its grid.
#[must_use]
pub fn scene_pixel(vp: &Viewport, s: &SceneState, cx: u16, cy: u16, sub: usize) -> (u32, u32) {
    let (x, y) = sample_pixel(vp, cx, cy, sub);
    let side = grid_side(s.scene.plan.samples);
    (x * side + side / 2, y * side + side / 2)
}

/// The line the line panel shows: an edge of one of the scene's objects, and the
/// step along it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineFocus {
    /// The object, named for a scene file's (a model's default scene has one).
    pub object: Option<usize>,
    pub edge: [u32; 2],
    pub k: i64,
}

/// The line under sub-sample `sub` of cell `(cx, cy)` (see
/// [`SceneFrame::line_under`](crate::scene::render::SceneFrame::line_under)), with its
/// screen line in the frame's (supersampled) pixel grid.
#[must_use]
pub fn line_at_sample(
    vp: &Viewport,
    s: &SceneState,
    (cx, cy, sub): (u16, u16, usize),
) -> Option<(LineFocus, ScreenLine)> {
    let (fx, fy) = scene_pixel(vp, s, cx, cy, sub);
    let (object, edge, sl, k) = s.frame.line_under(&s.scene, fx, fy)?;
    let object = (!s.scene.is_model()).then_some(object);
    Some((LineFocus { object, edge, k }, sl))
}

/// The screen line of a focus, this frame.
#[must_use]
pub fn project_focus(s: &SceneState, f: LineFocus) -> Option<ScreenLine> {
    s.frame.project_edge(f.object.unwrap_or(0), f.edge)
}

/// The line panel for a line and a step on it.
#[must_use]
pub fn line_text(f: LineFocus, sl: &ScreenLine) -> PanelText {
    let l = &sl.line;
    let k = f.k;
    let mut t = PanelText::default();
    let object = f.object.map_or(String::new(), |o| format!("object {o} "));
    t.fields(
        0,
        [
            format!("{object}edge v{}-v{}:", f.edge[0], f.edge[1]),
            format!("({},{}) -> ({},{})", l.a.0, l.a.1, l.b.0, l.b.1),
        ],
    );
    t.fields(
        0,
        [
            format!("octant {}", l.octant),
            format!("reflections: {}", l.reflections()),
        ],
    );
    t.fields(
        0,
        [
            format!("dx {}", l.dx),
            format!("dy {}", l.dy),
            format!("incrE {}", l.incr_e),
            format!("incrNE {}", l.incr_ne),
        ],
    );
    let (x, y) = l.pixel(k, l.minor_at(k));
    let d = l.d_at(k);
    let decision = if k < l.dx {
        let mv = if d <= 0 { Move::E } else { Move::NE };
        let after = d + if mv == Move::E { l.incr_e } else { l.incr_ne };
        format!("-> {} ({}), d' {after}", mv.name(), l.direction(mv))
    } else {
        "(last pixel)".into()
    };
    t.fields(
        0,
        [
            format!("step {k}/{}", l.dx),
            format!("pixel ({x},{y})"),
            format!("d {d}"),
            decision,
        ],
    );
    t.fields(0, [format!("line depth {:.5}", sl.depth_at(k))]);
    t
}
