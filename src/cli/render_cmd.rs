//! `termrast render` (one frame to PNG) and `termrast bench render` (the standard
//! benchmark scene).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use crate::mesh::Mesh;
use crate::raster::interp::Interpolation;
use crate::raster::{Target, Traversal};
use crate::render::shaders::Lambert;
use crate::render::standard::{Model, RADIANS_PER_FRAME, StandardFrame, StandardView};
use crate::render::wire::Mode;
use crate::render::{Cull, DrawOptions, Isa, Rgba8};
use crate::scene::render::{SceneFrame, SceneView};
use crate::scene::{Scene, is_scene_path};

/// Options shared by the 3D commands.
#[derive(Debug, Args)]
pub struct SceneArgs {
    /// `teapot` or `bunny` (built in), `sphere:N` (UV sphere of about N triangles), an
    /// OBJ path, or (for `render`) a scene file `SCENE.toml`.
    #[arg(default_value = "teapot")]
    pub model: String,
    /// Skip back faces.
    #[arg(long)]
    pub cull: bool,
    /// Attribute interpolation.
    #[arg(long, value_enum, default_value_t = Interpolation::Perspective)]
    pub interpolation: Interpolation,
    /// Traversal (all give identical images).
    #[arg(long, value_enum, default_value_t = Traversal::Wide)]
    pub traversal: Traversal,
    /// Filled triangles, wireframe, or filled with visible edges.
    #[arg(long, value_enum, default_value_t = Mode::Fill)]
    pub mode: Mode,
}

impl SceneArgs {
    fn options(&self) -> DrawOptions {
        DrawOptions {
            cull: if self.cull { Cull::Back } else { Cull::None },
            interpolation: self.interpolation,
            traversal: self.traversal,
            ..DrawOptions::default()
        }
    }

    fn model(&self) -> Result<Model, crate::mesh::MeshError> {
        let mut m = Mesh::from_spec(&self.model)?;
        m.ensure_normals();
        Ok(Model::new(m))
    }
}

/// Arguments of `termrast render`: ANSI text frames to stdout, or a PNG with `--out`.
#[derive(Debug, Args)]
pub struct PngArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// PNG image size in pixels, WxH (with --out).
    #[arg(long, value_parser = super::parse_size, default_value = "640x480")]
    pub size: Target,
    /// Rotation about y in radians (of the first frame).
    #[arg(long, default_value_t = 0.6, allow_negative_numbers = true)]
    pub angle: f32,
    /// Write one frame as a PNG file instead of text (the name must end in `.png`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Text frames: number of frames (each turns the model by 0.05 rad).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Text frames: columns.
    #[arg(long, default_value_t = 80, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub cols: u16,
    /// Text frames: rows.
    #[arg(long, default_value_t = 24, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub rows: u16,
    /// Text frames: start each with cursor-home instead of separating them by a blank
    /// line, so a terminal shows an animation.
    #[arg(long)]
    pub animate: bool,
    /// Glyphs and colours of text frames.
    #[command(flatten)]
    pub look: super::view_cmd::LookArgs,
    /// Print the scene's plan (what runs and what is skipped, and why) and exit.
    /// A model is shorthand for its default scene.
    #[arg(long)]
    pub plan: bool,
}

/// Arguments of `termrast bench render`.
#[derive(Debug, Args)]
pub struct BenchRenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Target size in pixels, WxH.
    #[arg(long, value_parser = super::parse_size, default_value = "1920x1080")]
    pub size: Target,
    /// Frames to render (each turns the model by 0.05 rad).
    #[arg(long, default_value_t = 100)]
    pub frames: u32,
    /// Rendering threads: only 1 is accepted (the renderer is single-threaded).
    #[arg(long, default_value_t = 1, value_parser = parse_threads)]
    pub threads: u32,
    /// The draw loop's instruction set: baseline, avx2 or avx512 (default: the best
    /// this CPU has). All give identical images.
    #[arg(long, value_parser = super::parse_isa)]
    pub isa: Option<Isa>,
}

/// `--threads`: the renderer is single-threaded, so only 1 is meaningful.
fn parse_threads(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(1) => Ok(1),
        Ok(_) => Err("the renderer is single-threaded: only 1 is accepted".into()),
        Err(_) => Err(format!("`{s}` is not a whole number (only 1 is accepted)")),
    }
}

/// Refuses an `--out` path that is not a PNG, before anything is rendered or created
/// (only PNG is written; a failed save would leave an empty file behind).
fn check_png_path(path: &Path) -> Result<(), super::CliError> {
    let is_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        return Ok(());
    }
    let not = match path.extension() {
        Some(e) => format!(", not `.{}`", e.to_string_lossy()),
        None => String::new(),
    };
    Err(super::CliError::Usage(format!(
        "{}: --out writes PNG images only{not}; name the file `{}`",
        path.display(),
        path.with_extension("png").display()
    )))
}

/// Writes frames of the standard scene as ANSI text, or one as a PNG with `--out`.
pub fn png(args: &PngArgs) -> Result<(), super::CliError> {
    if let Some(out) = &args.out {
        check_png_path(out)?;
    }
    if args.plan {
        let scene = if is_scene_path(&args.scene.model) {
            Scene::load(Path::new(&args.scene.model))?
        } else {
            Scene::for_model(&args.scene.model)?
        };
        let mut out = std::io::stdout().lock();
        writeln!(out, "plan of {}", scene.source)?;
        write!(out, "{}", scene.plan)?;
        return Ok(());
    }
    if is_scene_path(&args.scene.model) {
        return scene_frames(args);
    }
    let model = args.scene.model()?;
    let Some(out_path) = &args.out else {
        let mut settings = args.look.settings(args.scene.mode, args.scene.cull);
        settings.angle = args.angle;
        settings.tilt = 0.0;
        return text_frames(args, |vp, n| {
            settings.angle = args.angle + n as f32 * RADIANS_PER_FRAME;
            vp.render(&model, &settings, args.cols, args.rows);
        });
    };
    let target = args.size;
    let mut frame = StandardFrame::new(target);
    let mut color = Rgba8::default();
    frame.draw(
        &model,
        &StandardView::framed(&model, 1.0, args.angle),
        target,
        &args.scene.options(),
        args.scene.mode,
        &mut color,
    );
    // Opaque PNG: the uncovered background (alpha 0 in the target) is black.
    let bytes: Vec<u8> = color
        .0
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    image::save_buffer(
        out_path,
        &bytes,
        target.width,
        target.height,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| super::CliError::Image(out_path.clone(), e))?;
    Ok(())
}

/// Seconds of scene time between text frames.
pub const SCENE_SECONDS_PER_FRAME: f32 = 0.1;

/// `termrast render SCENE.toml`: text frames, or one PNG with `--out`.
fn scene_frames(args: &PngArgs) -> Result<(), super::CliError> {
    let scene = Scene::load(Path::new(&args.scene.model))?;
    let mut frame = SceneFrame::new(&scene);
    if let Some(out_path) = &args.out {
        let target = args.size;
        frame.draw(&scene, target, &SceneView::default());
        return write_png(out_path, &frame.color, target);
    }
    let mut settings = args.look.settings(Mode::Fill, false);
    settings.angle = 0.0;
    settings.tilt = 0.0;
    text_frames(args, |vp, n| {
        let t = n as f32 * SCENE_SECONDS_PER_FRAME;
        vp.render_scene(&scene, &mut frame, &settings, (args.cols, args.rows), t);
    })
}

/// Writes `args.frames` frames as ANSI text to stdout; `render(vp, n)` draws frame
/// `n` into the viewport. Frames are separated by a blank line, or start with
/// cursor-home with `--animate`.
fn text_frames(
    args: &PngArgs,
    mut render: impl FnMut(&mut crate::tui::viewport::Viewport, u32),
) -> Result<(), super::CliError> {
    if let Some(n) = args.look.notice_in(|k| std::env::var(k).ok()) {
        eprintln!("termrast: {n}");
    }
    let mut vp = crate::tui::viewport::Viewport::default();
    let mut out = std::io::stdout().lock();
    for n in 0..args.frames {
        render(&mut vp, n);
        if args.animate {
            out.write_all(b"\x1b[H")?;
        } else if n > 0 {
            out.write_all(b"\n")?;
        }
        crate::terminal::ansi::write_frame(
            &vp.cells,
            usize::from(vp.cols),
            vp.settings.colors,
            &vp.settings.palette,
            args.animate,
            &mut out,
        )?;
    }
    out.flush()?;
    Ok(())
}

/// Writes an opaque PNG (the uncovered background, alpha 0 in the target, is black).
fn write_png(path: &Path, color: &Rgba8, target: Target) -> Result<(), super::CliError> {
    let bytes: Vec<u8> = color
        .0
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    image::save_buffer(
        path,
        &bytes,
        target.width,
        target.height,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| super::CliError::Image(path.into(), e))
}

/// The result of the standard benchmark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchReport {
    pub median_ms: f64,
    pub min_ms: f64,
    pub triangles: usize,
    /// Covered fragments per frame (mean), overdraw included.
    pub covered_px: u64,
    /// The instruction set the draw loop ran on (see [`crate::render::DrawCopy::choose`]).
    pub isa: Isa,
}

impl std::fmt::Display for BenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mpx = self.covered_px as f64 / (self.median_ms * 1e3);
        write!(
            f,
            "median_ms={:.3} min_ms={:.3} triangles={} covered_px={} mpx_per_s={:.1} isa={}",
            self.median_ms,
            self.min_ms,
            self.triangles,
            self.covered_px,
            mpx,
            self.isa.name()
        )
    }
}

/// Runs the standard benchmark: clear colour and depth, draw, per frame.
pub fn bench_render(args: &BenchRenderArgs) -> Result<BenchReport, super::CliError> {
    if is_scene_path(&args.scene.model) {
        return Err(super::CliError::Usage(format!(
            "{0}: bench render times a model (`teapot`, `bunny`, `sphere:N` or an OBJ file), \
             not a scene file; `termrast render {0}` draws the scene",
            args.scene.model
        )));
    }
    let model = args.scene.model()?;
    let target = args.size;
    let opts = args.scene.options();
    let mut frame = StandardFrame::new(target);
    if let Some(isa) = args.isa {
        frame.renderer.isa = isa;
    }
    let mut color = Rgba8::default();
    let frames = args.frames.max(1);
    let mut times = Vec::with_capacity(frames as usize);
    let mut covered = 0u64;
    for n in 0..frames {
        let start = Instant::now();
        frame.draw(
            &model,
            &StandardView::at(n as f32 * RADIANS_PER_FRAME),
            target,
            &opts,
            args.scene.mode,
            &mut color,
        );
        times.push(start.elapsed().as_secs_f64() * 1e3);
        covered += frame.renderer.stats.fragments;
    }
    times.sort_by(f64::total_cmp);
    Ok(BenchReport {
        median_ms: times[times.len() / 2],
        min_ms: times[0],
        triangles: model.mesh.triangle_count(),
        covered_px: covered / u64::from(frames),
        isa: frame.renderer.copy_for::<Lambert<'_>>(&opts).isa,
    })
}
