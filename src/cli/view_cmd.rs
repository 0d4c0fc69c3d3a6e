//! `termrast [view] [MODEL]`: the viewer, and `termrast render` as ANSI text.

use std::io::{self, Write};

use clap::Args;

use crate::render::wire::Mode;
use crate::scene::{Scene, SceneError, is_scene_path};
use crate::terminal::glyphs::FitSpace;
use crate::terminal::{ColorMode, GlyphMode, locale};
use crate::tui::app::App;
use crate::tui::viewport::{ViewSettings, Viewport};

/// How the model is shown in the terminal (shared by `view` and text `render`).
#[derive(Debug, Args, Clone)]
pub struct LookArgs {
    /// Glyphs and sub-samples per cell; by default the best for the colour depth
    /// (`ascii` when the locale is not UTF-8).
    #[arg(long, value_enum)]
    pub glyphs: Option<GlyphMode>,
    /// Colour depth; detected from NO_COLOR, COLORTERM and TERM when not given.
    #[arg(long, value_enum)]
    pub color: Option<ColorMode>,
    /// Where the shape-fitted glyph modes (wedges, blocks, ascii) measure colour error.
    #[arg(long, value_enum, default_value_t = FitSpace::Srgb)]
    pub fit_space: FitSpace,
    /// The 16 colours a 16-colour frame is fitted to: `auto` asks the terminal (xterm's
    /// until it answers; `render` cannot ask and takes xterm's).
    #[arg(long, value_enum, default_value_t = PaletteArg::Auto)]
    pub palette: PaletteArg,
    /// Cell width / height (terminal cells are about twice as tall as wide).
    #[arg(long, default_value_t = 0.5, value_parser = parse_aspect)]
    pub cell_aspect: f32,
}

/// Where the 16 ANSI colours come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PaletteArg {
    /// Ask the terminal (OSC 4).
    Auto,
    /// xterm's default colours.
    Xterm,
}

fn parse_aspect(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && (0.1..=10.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("cell aspect {v} must be between 0.1 and 10"))
    }
}

impl LookArgs {
    /// The view settings these arguments ask for in this environment.
    #[must_use]
    pub fn settings(&self) -> ViewSettings {
        self.settings_in(|k| std::env::var(k).ok())
    }

    /// The view settings in an environment whose variables `get` returns.
    #[must_use]
    pub fn settings_in(&self, get: impl Fn(&str) -> Option<String>) -> ViewSettings {
        let colors = self.color.unwrap_or_else(|| ColorMode::detect(&get));
        let utf8 = locale::is_utf8(locale::locale(&get).as_deref());
        let glyphs = match self.glyphs {
            Some(g) => g,
            None if !utf8 => GlyphMode::Ascii,
            None => GlyphMode::default_for(locale::draws_wedges(&get)),
        };
        ViewSettings {
            glyphs,
            colors,
            cell_aspect: self.cell_aspect,
            fit_space: self.fit_space,
            ..ViewSettings::default()
        }
    }

    /// What to tell the user once about the settings: that a non-UTF-8 locale chose
    /// ASCII glyphs.
    #[must_use]
    pub fn notice_in(&self, get: impl Fn(&str) -> Option<String>) -> Option<String> {
        let name = locale::locale(&get);
        (self.glyphs.is_none() && !locale::is_utf8(name.as_deref())).then(|| {
            format!(
                "locale {} is not UTF-8: ascii glyphs (--glyphs overrides)",
                name.as_deref().unwrap_or("C")
            )
        })
    }
}

/// Arguments of the viewer.
#[derive(Debug, Args, Clone)]
pub struct ViewArgs {
    /// `teapot` or `bunny` (built in), `sphere:N`, a model file (OBJ, STL, PLY,
    /// glTF), or a scene file `SCENE.toml`.
    #[arg(default_value = "teapot")]
    pub model: String,
    #[command(flatten)]
    pub look: LookArgs,
    /// Filled, wireframe, or filled with visible edges (a model; a scene file's
    /// effects say, and `w` changes it).
    #[arg(long, value_enum, default_value_t = Mode::Fill)]
    pub mode: Mode,
    /// Skip back faces (a model; a scene file's effects say, and `b` changes it).
    #[arg(long)]
    pub cull: bool,
    /// Frame rate cap.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,
    /// Output rate cap in bytes per second (frames wait for it), on top of pacing by
    /// the terminal's answers.
    #[arg(long, value_name = "BYTES/S", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_rate: Option<u64>,
    /// Send frames without waiting for the terminal's answers.
    #[arg(long)]
    pub no_pacing: bool,
    /// Drawing threads (default: the machine's cores); 1 draws on the viewer's thread.
    /// With more, each frame goes to them or stays on the viewer's thread, whichever
    /// recent frames were faster on (the status line says which).
    #[arg(long, value_parser = super::parse_threads)]
    pub threads: Option<usize>,
}

/// A scene file (`SCENE.toml`), or a model's default scene drawn in `mode`, culled
/// with `cull` (a scene file's effects say how it is drawn).
/// What the loaders warned of goes to stderr (it stays on the terminal's main screen,
/// under the viewer's alternate screen, for after it).
pub fn load(spec: &str, mode: Mode, cull: bool) -> Result<Scene, SceneError> {
    let scene = if is_scene_path(spec) {
        Scene::load(std::path::Path::new(spec))?
    } else {
        let mut scene = Scene::for_model(spec)?;
        scene.set_mode(mode);
        scene.set_cull(cull);
        scene
    };
    print_warnings(&scene.warnings, &mut io::stderr().lock());
    Ok(scene)
}

/// The most warnings printed; the rest are counted.
const MAX_WARNINGS: usize = 20;

/// Prints loader warnings, one per line.
pub fn print_warnings(warnings: &[String], out: &mut impl Write) {
    for w in warnings.iter().take(MAX_WARNINGS) {
        let _ = writeln!(out, "termrast: warning: {w}");
    }
    if warnings.len() > MAX_WARNINGS {
        let _ = writeln!(
            out,
            "termrast: warning: … and {} more",
            warnings.len() - MAX_WARNINGS
        );
    }
}

/// Runs the viewer.
pub fn view(args: &ViewArgs) -> Result<(), super::CliError> {
    let env = |k: &str| std::env::var(k).ok();
    if let Some(why) = locale::no_full_screen(env("TERM").as_deref()) {
        return Err(crate::tui::ViewError::Unsupported(why).into());
    }
    let scene = load(&args.model, args.mode, args.cull)?;
    let warned = scene.warnings.len();
    let mut app = App::new(scene, args.look.settings());
    let renderer = &mut app.scene.frame.renderer;
    renderer.set_threads(super::threads_or_cores(args.threads));
    // Frames 30 times a second leave the threads idle in between: each frame goes the
    // way (the threads or this one) that has been faster.
    renderer.set_measured(true);
    app.notice = args.look.notice_in(env).or_else(|| {
        (warned > 0).then(|| {
            format!(
                "the model loaded with {warned} warning{}: printed under the viewer, seen after q",
                if warned == 1 { "" } else { "s" }
            )
        })
    });
    let options = crate::tui::RunOptions {
        fps: args.fps,
        max_rate: args.max_rate,
        paced: !args.no_pacing,
        ask_palette: args.look.palette == PaletteArg::Auto,
    };
    // The viewer's loop on the drawing threads: no frame is handed from thread to
    // thread, and small frames can be shared too (`Renderer::plan_frame`).
    match app.scene.frame.renderer.thread_pool().cloned() {
        Some(pool) => pool.install(|| crate::tui::run(app, options))?,
        None => crate::tui::run(app, options)?,
    }
    Ok(())
}

/// Writes the viewport's cells as ANSI text (see [`crate::terminal::ansi`]).
pub fn write_ansi(vp: &Viewport, out: &mut impl Write) -> io::Result<()> {
    crate::terminal::ansi::write_frame(
        &vp.cells,
        usize::from(vp.cols),
        vp.settings.colors,
        &vp.settings.palette,
        false,
        out,
    )
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    /// `LookArgs` as the command line parses them.
    #[derive(Parser)]
    struct Look {
        #[command(flatten)]
        look: LookArgs,
    }

    fn look(args: &[&str]) -> LookArgs {
        Look::parse_from(std::iter::once("termrast").chain(args.iter().copied())).look
    }

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| (*v).to_string())
        }
    }

    #[test]
    fn glyphs_given_override_the_ascii_of_a_non_utf8_locale() {
        for vars in [
            &[("LANG", "C"), ("TERM", "xterm-256color")][..],
            &[("LC_ALL", "C"), ("LANG", "en_US.UTF-8")][..],
            &[("LC_ALL", "POSIX"), ("TERM", "xterm-kitty")][..],
        ] {
            // Without --glyphs: ascii, and the status line says why, once.
            let plain = look(&[]);
            let s = plain.settings_in(env(vars));
            assert_eq!(s.glyphs, GlyphMode::Ascii, "{vars:?}");
            let notice = plain.notice_in(env(vars)).expect("a notice");
            assert!(
                notice.contains("not UTF-8") && notice.contains("--glyphs"),
                "{notice}"
            );
            // With --glyphs blocks: blocks, and nothing to tell.
            let given = look(&["--glyphs", "blocks"]);
            let s = given.settings_in(env(vars));
            assert_eq!(s.glyphs, GlyphMode::Blocks, "{vars:?}");
            assert_eq!(given.notice_in(env(vars)), None, "{vars:?}");
        }
        // A UTF-8 locale keeps the default for the terminal and says nothing.
        let utf8 = [("LANG", "en_US.UTF-8"), ("TERM", "xterm-256color")];
        let plain = look(&[]);
        assert_eq!(
            plain.settings_in(env(&utf8)).glyphs,
            GlyphMode::default_for(false)
        );
        assert_eq!(plain.notice_in(env(&utf8)), None);
    }
}
