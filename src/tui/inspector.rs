//! The inspector and line panels: the raster state of one cell, from the probe, in
//! the seed notes' names (F01, F02, F03, u, v, w, depth, octant, dx, dy, incrE,
//! incrNE, d).

use std::fmt::Write as _;

use crate::accuracy::area::grid_side;
use crate::raster::line::Move;
use crate::raster::probe::{DepthOutcome, Probe, probe};
use crate::render::Shader;
use crate::render::standard::{Model, StandardFrame};
use crate::render::target::luminance;
use crate::render::wire::{ScreenLine, probe_lines, project_edge};
use crate::terminal::GlyphMode;
use crate::terminal::glyphs::{Sample, explain};

use super::app::SceneState;
use super::viewport::Viewport;

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
) -> Option<(String, [Sample; GlyphMode::MAX_SAMPLES], usize)> {
    let g = vp.cell(cx, cy)?;
    let (samples, n) = vp.samples(cx, cy);
    let mut t = String::new();
    let _ = writeln!(
        t,
        "cell ({cx},{cy})  glyph '{}'  fg {}  bg {}",
        g.ch,
        hex(g.fg),
        hex(g.bg)
    );
    let _ = writeln!(t, "  {}", explain(vp.settings.glyphs, &samples[..n], g));
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

/// The inspector text for cell `(cx, cy)`, detailing sub-sample `sub`.
#[must_use]
pub fn inspector_text(vp: &Viewport, model: &Model, cx: u16, cy: u16, sub: usize) -> String {
    let Some((mut t, _, n)) = cell_header(vp, cx, cy) else {
        return "cursor outside the view".into();
    };
    let opts = vp.settings.options();
    let indices = &model.mesh.indices;
    let view = vp.view;
    let shader = StandardFrame::shader(&model.mesh, &view, vp.target);
    let rows = listed(vp, n, sub);
    if rows.len() < n {
        let _ = writeln!(
            t,
            "samples {}–{} of {n} (Tab moves):",
            rows.start,
            rows.end - 1
        );
    } else {
        let _ = writeln!(t, "samples ({n} per cell):");
    }
    // The selected sample's probe is kept for the overdraw list below.
    let mut selected = None;
    for k in rows {
        let (x, y) = sample_pixel(vp, cx, cy, k);
        let p = probe(&vp.frame.cache, indices, vp.target, &opts, x, y);
        let mark = if k == sub % n { '>' } else { ' ' };
        match p.winner.map(|w| &p.records[w]) {
            Some(r) => {
                let shade = luminance(shader.fragment(&r.varying));
                let _ = writeln!(
                    t,
                    "{mark}s{k} ({x},{y}) covered by t{} depth {:.5} shade {shade:.3} ({} touched)",
                    r.triangle,
                    r.eval.depth,
                    p.records.len()
                );
            }
            None => {
                let _ = writeln!(
                    t,
                    "{mark}s{k} ({x},{y}) not covered ({} touched)",
                    p.records.len()
                );
            }
        }
        if k == sub % n {
            selected = Some(p);
        }
    }
    let (x, y) = sample_pixel(vp, cx, cy, sub);
    let Some(p) = selected else { return t };
    let _ = writeln!(t, "sample ({x},{y}), overdraw in draw order:");
    overdraw_text(&mut t, &p, opts.depth.uses_buffer());
    t
}

/// The overdraw list of a probe: every triangle whose box holds the pixel, in draw
/// order, with its edge values, barycentrics, depth and depth test.
fn overdraw_text<V>(t: &mut String, p: &Probe<V>, depth_test: bool) {
    if p.records.is_empty() {
        let _ = writeln!(t, "  no triangle's box holds this sample");
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
        let _ = writeln!(
            t,
            "{star}t{}{} block {}  {test}",
            r.triangle,
            if r.clipped {
                format!(".{}", r.piece)
            } else {
                String::new()
            },
            r.block.name()
        );
        let _ = writeln!(
            t,
            "   F01 {} F02 {} F03 {}  area2 {}",
            e.f[0] + r.setup.bias[0],
            e.f[1] + r.setup.bias[1],
            e.f[2] + r.setup.bias[2],
            r.setup.area2
        );
        let _ = writeln!(
            t,
            "   u {:.4} v {:.4} w {:.4}  persp {:.4} {:.4} {:.4}",
            e.bary[0], e.bary[1], e.bary[2], e.persp[0], e.persp[1], e.persp[2]
        );
        let _ = writeln!(t, "   1/w {:.5}  depth {:.6}", e.inv_w, e.depth);
    }
}

/// The inspector text for a scene: the cell's glyph and samples, then for the
/// selected sample each object's overdraw list in draw order (depth carried from
/// object to object), with the object's pipeline.
#[must_use]
pub fn scene_inspector_text(vp: &Viewport, s: &SceneState, cx: u16, cy: u16, sub: usize) -> String {
    let Some((mut t, samples, n)) = cell_header(vp, cx, cy) else {
        return "cursor outside the view".into();
    };
    for k in listed(vp, n, sub) {
        let smp = samples[k];
        let mark = if k == sub % n { '>' } else { ' ' };
        let (x, y) = sample_pixel(vp, cx, cy, k);
        let _ = writeln!(
            t,
            "{mark}s{k} ({x},{y}) {} {}",
            if smp.covered { "covered" } else { "empty" },
            hex(Some(smp.rgb))
        );
    }
    let (x, y) = sample_pixel(vp, cx, cy, sub);
    let side = grid_side(s.scene.plan.samples);
    let (fx, fy) = (x * side + side / 2, y * side + side / 2);
    if side > 1 {
        let _ = writeln!(
            t,
            "supersampled: probing sample ({fx},{fy}) of its {side}×{side} grid"
        );
    }
    for ((p, obj), op) in s
        .frame
        .probe(&s.scene, fx, fy)
        .iter()
        .zip(&s.scene.objects)
        .zip(&s.scene.plan.objects)
    {
        let _ = writeln!(
            t,
            "object {} ({}), varyings {}:",
            obj.desc.name,
            if op.depth_test {
                "depth test"
            } else {
                "no depth test"
            },
            op.varyings
        );
        overdraw_text(&mut t, p, op.depth_test);
    }
    let _ = writeln!(
        t,
        "(the line panel traces models only; scene wireframes are drawn, not traced)"
    );
    t
}

/// The line under a sample: a visible wireframe line through it, else the edge of the
/// covering triangle nearest to it. Returns the mesh edge, its screen line and step.
#[must_use]
pub fn line_at(
    vp: &Viewport,
    model: &Model,
    x: u32,
    y: u32,
) -> Option<([u32; 2], ScreenLine, i64)> {
    let depth = vp.settings.mode.fills().then_some(&vp.frame.renderer.depth);
    if vp.settings.mode.wires() {
        let hits = probe_lines(&vp.frame.cache, &model.edges, vp.target, depth, x, y);
        if let Some(h) = hits.iter().find(|h| h.visible) {
            return Some((h.edge, h.screen, h.step.k));
        }
    }
    let opts = vp.settings.options();
    let p = probe(&vp.frame.cache, &model.mesh.indices, vp.target, &opts, x, y);
    let t = p.records[p.winner?].triangle as usize;
    let tri = &model.mesh.indices[t * 3..t * 3 + 3];
    let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
    [[tri[0], tri[1]], [tri[1], tri[2]], [tri[2], tri[0]]]
        .into_iter()
        .filter_map(|e| {
            let sl = project_edge(&vp.frame.cache, [e[0].min(e[1]), e[0].max(e[1])], vp.target)?;
            let (a, b) = (sl.line.a, sl.line.b);
            let (dx, dy) = ((b.0 - a.0) as f64, (b.1 - a.1) as f64);
            let len = dx.hypot(dy).max(1e-9);
            let dist = ((px - a.0 as f64 - 0.5) * dy - (py - a.1 as f64 - 0.5) * dx).abs() / len;
            Some((dist, [e[0].min(e[1]), e[0].max(e[1])], sl))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, e, sl)| {
            let (sx, sy) = sl.line.start();
            let k = if sl.line.swap_xy {
                i64::from(y) - sy
            } else {
                i64::from(x) - sx
            };
            (e, sl, k.clamp(0, sl.line.dx))
        })
}

/// The line panel for a line and a step on it.
#[must_use]
pub fn line_text(edge: [u32; 2], sl: &ScreenLine, k: i64) -> String {
    let l = &sl.line;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "edge v{}-v{}: ({},{}) -> ({},{})",
        edge[0], edge[1], l.a.0, l.a.1, l.b.0, l.b.1
    );
    let _ = writeln!(t, "octant {}  reflections: {}", l.octant, l.reflections());
    let _ = writeln!(
        t,
        "dx {}  dy {}  incrE {}  incrNE {}",
        l.dx, l.dy, l.incr_e, l.incr_ne
    );
    let (x, y) = l.pixel(k, l.minor_at(k));
    let d = l.d_at(k);
    let _ = write!(t, "step {k}/{}  pixel ({x},{y})  d {d}", l.dx);
    if k < l.dx {
        let mv = if d <= 0 { Move::E } else { Move::NE };
        let after = d + if mv == Move::E { l.incr_e } else { l.incr_ne };
        let _ = writeln!(t, " -> {} ({}), d' {after}", mv.name(), l.direction(mv));
    } else {
        let _ = writeln!(t, " (last pixel)");
    }
    let _ = writeln!(t, "line depth {:.5}", sl.depth_at(k));
    t
}
