//! `termrast bench effects`: what each scene effect costs per frame.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use clap::Args;

use crate::raster::Target;
use crate::scene::Scene;
use crate::scene::render::{SceneFrame, SceneView};

/// Arguments of `termrast bench effects`.
#[derive(Debug, Args)]
pub struct EffectsArgs {
    /// Frames per measurement (the median is reported).
    #[arg(long, default_value_t = 40, value_parser = clap::value_parser!(u32).range(3..))]
    pub frames: u32,
    /// Target sizes in samples.
    #[arg(long, value_delimiter = ',', value_parser = super::parse_size, default_value = "400x240,1920x1080")]
    pub sizes: Vec<Target>,
}

/// The model every row draws: the standard camera on a sphere, which has texture
/// coordinates and vertex colours.
pub const EFFECTS_MODEL: &str = "sphere:8192";

/// Each row: a name and the scene keys it adds. Every row but the first has the
/// depth test on, so it shows the cost of its one effect on top of that.
pub const EFFECTS: [(&str, &str, &str); 17] = [
    ("nothing (flat colour, no depth buffer)", "", ""),
    ("depth test", "", ""),
    ("back-face culling", "", "cull = true"),
    ("lighting: flat", "lighting = \"flat\"", ""),
    ("lighting: Gouraud", "lighting = \"gouraud\"", ""),
    ("lighting: Lambert per pixel", "lighting = \"lambert\"", ""),
    ("lighting: Blinn-Phong", "lighting = \"blinn-phong\"", ""),
    (
        "Lambert + a point light",
        "lighting = \"lambert\"\n[[light]]\nkind = \"point\"\nposition = [1.5, 1.0, 2.0]\nintensity = 4.0",
        "",
    ),
    ("vertex colours", "vertex_colors = true", ""),
    (
        "texture, nearest",
        "texture = \"nearest\"\nimage = \"checker\"",
        "",
    ),
    (
        "texture, bilinear",
        "texture = \"bilinear\"\nimage = \"checker\"",
        "",
    ),
    ("fog", "", "fog = { start = 2.0, end = 3.5 }"),
    ("depth shading", "", "depth_shading = true"),
    ("wireframe, hidden lines removed", "", "wireframe = true"),
    ("silhouettes", "", "silhouette = true"),
    ("antialias 4", "", "@4"),
    ("antialias 16", "", "@16"),
];

/// The scene text of a row.
#[must_use]
pub fn effect_scene(row: usize) -> String {
    let (_, material, effects) = EFFECTS[row];
    let (antialias, effects) = match effects.strip_prefix('@') {
        Some(n) => (n, ""),
        None => ("1", effects),
    };
    // Lights declared by a row come after the object in TOML only as a table array
    // of their own: split them off the material keys.
    let (material, lights) = match material.find("[[light]]") {
        Some(i) => (&material[..i], &material[i..]),
        None => (material, ""),
    };
    let depth = if row == 0 { "false" } else { "true" };
    let ambient = if lights.is_empty() {
        ""
    } else {
        "[[light]]\nkind = \"ambient\"\nintensity = 0.1\n"
    };
    format!(
        "[render]\nantialias = {antialias}\n{ambient}{lights}\n[[object]]\nmodel = \"{EFFECTS_MODEL}\"\nrotation = [20, 0, 0]\nspin = {{ speed = 0.5 }}\n[object.material]\n{material}\n[object.effects]\ndepth_test = {depth}\n{effects}\n"
    )
}

/// Median milliseconds per frame of a scene at a size.
fn median_ms(scene: &Scene, target: Target, frames: u32) -> f64 {
    let mut frame = SceneFrame::new(scene);
    let mut times: Vec<f64> = (0..frames)
        .map(|n| {
            let view = SceneView {
                time: n as f32 * 0.05,
                ..SceneView::default()
            };
            let start = Instant::now();
            frame.draw(scene, target, &view);
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Runs every row at every size and prints the table.
pub fn run(args: &EffectsArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    write!(out, "effect on {EFFECTS_MODEL}, median ms/frame")?;
    for s in &args.sizes {
        write!(out, " | {}x{} | +ms", s.width, s.height)?;
    }
    writeln!(out)?;
    let mut base = vec![0.0; args.sizes.len()];
    for (row, (name, _, _)) in EFFECTS.iter().enumerate() {
        let scene = Scene::from_text(&effect_scene(row), Path::new("bench effects"))?;
        write!(out, "{name:<40}")?;
        for (k, &size) in args.sizes.iter().enumerate() {
            let ms = median_ms(&scene, size, args.frames);
            if row == 1 {
                base[k] = ms;
            }
            if row <= 1 {
                write!(out, " | {ms:8.3} |       ")?;
            } else {
                write!(out, " | {ms:8.3} | {:+6.3}", ms - base[k])?;
            }
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_is_a_valid_scene_with_its_effect_on() {
        for row in 0..EFFECTS.len() {
            let scene = Scene::from_text(&effect_scene(row), Path::new("bench effects"))
                .unwrap_or_else(|e| panic!("row {row}: {e}"));
            let plan = &scene.plan;
            assert_eq!(plan.depth_buffer, row != 0, "row {row}");
            let on: Vec<&str> = plan.objects[0]
                .lines
                .iter()
                .filter(|l| l.on)
                .map(|l| l.stage)
                .collect();
            // Each row past the depth test turns on something the depth-test row has not.
            if row > 1 {
                let base = Scene::from_text(&effect_scene(1), Path::new("b")).unwrap();
                let base_on = base.plan.objects[0].lines.iter().filter(|l| l.on).count();
                assert!(on.len() > base_on || plan.samples > 1, "row {row}: {on:?}");
            }
        }
    }
}
