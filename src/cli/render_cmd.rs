//! `termrast render` (text frames, or one frame to PNG) and `termrast bench render`
//! (the standard benchmark scene): a model is drawn as its default scene.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use crate::raster::interp::Interpolation;
use crate::raster::{Target, Traversal};
use crate::render::shaders::Lambert;
use crate::render::wire::Mode;
use crate::render::{Isa, Rgba8};
use crate::scene::render::{SceneFrame, SceneView};
use crate::scene::{Scene, is_scene_path};
use crate::tui::viewport::{SceneState, Viewport};

/// Rotation of a model per frame (of the benchmark and of text frames), radians
/// about y.
pub const RADIANS_PER_FRAME: f32 = 0.05;

/// Options shared by the 3D commands.
#[derive(Debug, Args)]
pub struct SceneArgs {
    /// `teapot` or `bunny` (built in), `sphere:N` (UV sphere of about N triangles), a
    /// model file (OBJ, STL, PLY, glTF), or (for `render`) a scene file `SCENE.toml`.
    #[arg(default_value = "teapot")]
    pub model: String,
    /// Skip back faces (a model; a scene file's effects say).
    #[arg(long)]
    pub cull: bool,
    /// Attribute interpolation.
    #[arg(long, value_enum, default_value_t = Interpolation::Perspective)]
    pub interpolation: Interpolation,
    /// Traversal (all give identical images).
    #[arg(long, value_enum, default_value_t = Traversal::Wide)]
    pub traversal: Traversal,
    /// Filled triangles, wireframe, or filled with visible edges (a model; a scene
    /// file's effects say).
    #[arg(long, value_enum, default_value_t = Mode::Fill)]
    pub mode: Mode,
    /// Drawing threads (default: the machine's cores). 1 draws on this thread alone;
    /// every count gives the same image, bit for bit.
    #[arg(long, value_parser = super::parse_threads)]
    pub threads: Option<usize>,
}

impl SceneArgs {
    /// The scene these arguments name: a scene file, or the model's default scene
    /// drawn in `--mode`, culled with `--cull`.
    fn scene(&self) -> Result<Scene, crate::scene::SceneError> {
        super::view_cmd::load(&self.model, self.mode, self.cull)
    }

    /// The buffers and pipelines for `scene`, with `--interpolation`, `--traversal`
    /// and `--threads`.
    fn frame(&self, scene: &Scene) -> SceneFrame {
        self.frame_on(scene, self.threads)
    }

    /// [`SceneArgs::frame`] on `threads` threads (the machine's cores when not given).
    fn frame_on(&self, scene: &Scene, threads: Option<usize>) -> SceneFrame {
        let mut frame = SceneFrame::new(scene);
        frame.interpolation = self.interpolation;
        frame.traversal = self.traversal;
        frame.renderer.set_threads(super::threads_or_cores(threads));
        frame
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
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// The draw loop's instruction set: baseline, avx2 or avx512 (default: the best
    /// this CPU has). All give identical images.
    #[arg(long, value_parser = super::parse_isa)]
    pub isa: Option<Isa>,
    /// Milliseconds to wait before each frame (untimed), as the viewer waits between
    /// its frames and its threads fall idle; 0 draws the frames back to back.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=1000))]
    pub pause_ms: u64,
    /// Draw each frame on the threads or on the calling thread, whichever frames have
    /// been faster on, as the viewer does (by default every frame uses the threads).
    #[arg(long)]
    pub measured: bool,
    /// Draw the model in its material's colour alone, without its vertex colours
    /// (`sphere:N` then is white): per-pixel Lambert without the colour's four
    /// varyings.
    #[arg(long)]
    pub no_vertex_colors: bool,
    /// Thread counts to compare in one run, e.g. `1,2`: each round draws `--frames`
    /// frames with each count in turn, back to back, so a machine's slow spells hit
    /// them alike; prints each round and each count's speed-up over the first (the
    /// median of the rounds' ratios).
    #[arg(long, value_delimiter = ',', value_parser = super::parse_threads, conflicts_with = "threads")]
    pub compare: Option<Vec<usize>>,
    /// Rounds of `--compare`.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100), requires = "compare")]
    pub rounds: u32,
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

/// Writes frames of a scene (a model's default scene) as ANSI text, or one as a PNG
/// with `--out`.
pub fn png(args: &PngArgs) -> Result<(), super::CliError> {
    if let Some(out) = &args.out {
        check_png_path(out)?;
    }
    let scene = args.scene.scene()?;
    if args.plan {
        let mut out = std::io::stdout().lock();
        writeln!(out, "plan of {}", scene.source)?;
        write!(out, "{}", scene.plan)?;
        return Ok(());
    }
    let mut frame = args.scene.frame(&scene);
    // A model turns by `--angle` and then a step per frame; a scene file's clock runs.
    let model = scene.is_model();
    let angle = |n: u32| {
        if model {
            args.angle + n as f32 * RADIANS_PER_FRAME
        } else {
            0.0
        }
    };
    let time = |n: u32| {
        if model {
            0.0
        } else {
            n as f32 * SCENE_SECONDS_PER_FRAME
        }
    };
    if let Some(out_path) = &args.out {
        let target = args.size;
        let view = SceneView {
            yaw: angle(0),
            ..SceneView::default()
        };
        frame.draw(&scene, target, &view);
        return write_png(out_path, &frame.color, target);
    }
    let mut settings = args.look.settings();
    settings.tilt = 0.0;
    let mut state = SceneState {
        scene,
        frame,
        time: 0.0,
    };
    let pool = state.frame.renderer.thread_pool().cloned();
    let mut run = || {
        text_frames(args, |vp, n| {
            settings.angle = angle(n);
            state.time = time(n);
            vp.render(&mut state, &settings, (args.cols, args.rows));
        })
    };
    // The frame loop on the drawing threads, as the viewer's (`Renderer::plan_frame`).
    match pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
}

/// Seconds of scene time between text frames.
pub const SCENE_SECONDS_PER_FRAME: f32 = 0.1;

/// Writes `args.frames` frames as ANSI text to stdout; `render(vp, n)` draws frame
/// `n` into the viewport. Frames are separated by a blank line, or start with
/// cursor-home with `--animate`.
fn text_frames(
    args: &PngArgs,
    mut render: impl FnMut(&mut Viewport, u32),
) -> Result<(), super::CliError> {
    if let Some(n) = args.look.notice_in(|k| std::env::var(k).ok()) {
        eprintln!("termrast: {n}");
    }
    let mut vp = Viewport::default();
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
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    pub median_ms: f64,
    pub min_ms: f64,
    pub triangles: usize,
    /// Covered fragments per frame (mean), overdraw included.
    pub covered_px: u64,
    /// The instruction set the draw loop ran on (see [`crate::render::DrawCopy::choose`]).
    pub isa: Isa,
    /// The threads it drew on.
    pub threads: usize,
    /// The shading each object was drawn with ([`SceneFrame::pipelines`]), joined by `+`.
    pub shading: String,
}

impl std::fmt::Display for BenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mpx = self.covered_px as f64 / (self.median_ms * 1e3);
        write!(
            f,
            "median_ms={:.3} min_ms={:.3} triangles={} covered_px={} mpx_per_s={:.1} isa={} \
             threads={} shading={}",
            self.median_ms,
            self.min_ms,
            self.triangles,
            self.covered_px,
            mpx,
            self.isa.name(),
            self.threads,
            self.shading
        )
    }
}

/// Runs the standard benchmark: the model's default scene seen from the fixed
/// camera ([`Scene::standard`]), turning; colour and depth cleared and drawn per frame.
pub fn bench_render(args: &BenchRenderArgs) -> Result<BenchReport, super::CliError> {
    let scene = bench_scene(args)?;
    let mut frame = bench_frame(args, &scene, args.scene.threads);
    let (times, covered) = time_frames(args, &scene, &mut frame);
    Ok(report(&scene, &frame, &times, covered))
}

/// The benchmark's scene: the model's default scene in `--mode`, culled with `--cull`.
fn bench_scene(args: &BenchRenderArgs) -> Result<Scene, super::CliError> {
    if is_scene_path(&args.scene.model) {
        return Err(super::CliError::Usage(format!(
            "{0}: bench render times a model (`teapot`, `bunny`, `sphere:N` or a model file), \
             not a scene file; `termrast render {0}` draws the scene",
            args.scene.model
        )));
    }
    let mut scene = Scene::standard(&args.scene.model)?;
    super::view_cmd::print_warnings(&scene.warnings, &mut std::io::stderr().lock());
    scene.set_mode(args.scene.mode);
    scene.set_cull(args.scene.cull);
    if args.no_vertex_colors {
        scene.drop_vertex_colors();
    }
    Ok(scene)
}

/// The buffers and pipelines for the benchmark on `threads` threads (the machine's
/// cores when not given), with `--isa` and `--measured`.
fn bench_frame(args: &BenchRenderArgs, scene: &Scene, threads: Option<usize>) -> SceneFrame {
    let mut frame = args.scene.frame_on(scene, threads);
    if let Some(isa) = args.isa {
        frame.renderer.isa = isa;
    }
    frame.renderer.set_measured(args.measured);
    frame
}

/// Draws `--frames` frames (clap admits at least one), each after `--pause-ms`; returns each
/// frame's time in ms, sorted, and the mean covered fragments per frame.
fn time_frames(args: &BenchRenderArgs, scene: &Scene, frame: &mut SceneFrame) -> (Vec<f64>, u64) {
    let pause = std::time::Duration::from_millis(args.pause_ms);
    let frames = args.frames.max(1);
    let mut times = Vec::with_capacity(frames as usize);
    let mut covered = 0u64;
    let pool = frame.renderer.thread_pool().cloned();
    let mut run = || {
        for n in 0..frames {
            let view = SceneView {
                yaw: n as f32 * RADIANS_PER_FRAME,
                ..SceneView::default()
            };
            if !pause.is_zero() {
                std::thread::sleep(pause);
            }
            let start = Instant::now();
            frame.draw(scene, args.size, &view);
            times.push(start.elapsed().as_secs_f64() * 1e3);
            covered += frame.stats.fragments;
        }
    };
    // The loop on the drawing threads, as the viewer runs it: no frame is handed from
    // thread to thread.
    match pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
    times.sort_by(f64::total_cmp);
    (times, covered / u64::from(frames))
}

/// The report of frames drawn by `frame`, their times sorted.
fn report(scene: &Scene, frame: &SceneFrame, times: &[f64], covered_px: u64) -> BenchReport {
    let opts = frame.draw_options(&scene.plan.objects[0]);
    BenchReport {
        median_ms: times[times.len() / 2],
        min_ms: times[0],
        triangles: scene.objects[0].mesh.triangle_count(),
        covered_px,
        isa: frame.renderer.copy_for::<Lambert<'_>>(&opts).isa,
        threads: frame.renderer.threads(),
        shading: frame.pipelines().join("+"),
    }
}

/// `bench render --compare`: the standard benchmark with each thread count in turn,
/// `--rounds` times; writes each round and then the summary to `out`.
pub fn bench_compare(
    args: &BenchRenderArgs,
    counts: &[usize],
    out: &mut impl Write,
) -> Result<(), super::CliError> {
    let scene = bench_scene(args)?;
    let mut frames: Vec<SceneFrame> = counts
        .iter()
        .map(|&t| bench_frame(args, &scene, Some(t)))
        .collect();
    // Per count, each round's median.
    let mut medians = vec![Vec::new(); counts.len()];
    for round in 1..=args.rounds {
        let mut line = format!("round {round}:");
        let mut first = None;
        for (k, frame) in frames.iter_mut().enumerate() {
            let (times, covered) = time_frames(args, &scene, frame);
            let r = report(&scene, frame, &times, covered);
            medians[k].push(r.median_ms);
            line.push_str(&format!(
                " threads={} median_ms={:.3}",
                r.threads, r.median_ms
            ));
            match first {
                None => first = Some(r.median_ms),
                Some(f) => line.push_str(&format!(" ({:.2}x)", f / r.median_ms)),
            }
        }
        writeln!(out, "{line}")?;
    }
    let mut line = String::from("all:");
    for (k, m) in medians.iter().enumerate() {
        let (lo, hi) = m
            .iter()
            .fold((f64::INFINITY, 0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        line.push_str(&format!(" threads={} median_ms={lo:.3}-{hi:.3}", counts[k]));
        if k > 0 {
            let mut ratios: Vec<f64> = medians[0].iter().zip(m).map(|(a, b)| a / b).collect();
            ratios.sort_by(f64::total_cmp);
            line.push_str(&format!(" speedup={:.2}x", ratios[ratios.len() / 2]));
        }
    }
    writeln!(out, "{line}")?;
    Ok(())
}
