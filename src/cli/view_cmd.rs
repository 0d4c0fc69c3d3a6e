//! `termrast [view] [MODEL]`: the viewer, and `termrast render` as ANSI text.

use std::io::{self, Write};

use clap::Args;

use crate::mesh::Mesh;
use crate::render::standard::Model;
use crate::render::wire::Mode;
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
    /// Cell width / height (terminal cells are about twice as tall as wide).
    #[arg(long, default_value_t = 0.5, value_parser = parse_aspect)]
    pub cell_aspect: f32,
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
    pub fn settings(&self, mode: Mode, cull: bool) -> ViewSettings {
        self.settings_in(mode, cull, |k| std::env::var(k).ok())
    }

    /// The view settings in an environment whose variables `get` returns.
    #[must_use]
    pub fn settings_in(
        &self,
        mode: Mode,
        cull: bool,
        get: impl Fn(&str) -> Option<String>,
    ) -> ViewSettings {
        let colors = self.color.unwrap_or_else(|| ColorMode::detect(&get));
        let utf8 = locale::is_utf8(locale::locale(&get).as_deref());
        let glyphs = match self.glyphs {
            Some(g) => g,
            None if !utf8 => GlyphMode::Ascii,
            None => GlyphMode::default_for(colors),
        };
        ViewSettings {
            glyphs,
            colors,
            mode,
            cell_aspect: self.cell_aspect,
            cull,
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
    /// `teapot` or `bunny` (built in), `sphere:N`, an OBJ path, or a scene file
    /// `SCENE.toml`.
    #[arg(default_value = "teapot")]
    pub model: String,
    #[command(flatten)]
    pub look: LookArgs,
    /// Filled, wireframe, or filled with visible edges.
    #[arg(long, value_enum, default_value_t = Mode::Fill)]
    pub mode: Mode,
    /// Skip back faces.
    #[arg(long)]
    pub cull: bool,
    /// Frame rate cap.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,
}

/// Loads a model with normals and edges.
pub fn load_model(spec: &str) -> Result<Model, crate::mesh::MeshError> {
    let mut m = Mesh::from_spec(spec)?;
    m.ensure_normals();
    Ok(Model::new(m))
}

/// Runs the viewer.
pub fn view(args: &ViewArgs) -> Result<(), super::CliError> {
    let env = |k: &str| std::env::var(k).ok();
    if let Some(why) = locale::no_full_screen(env("TERM").as_deref()) {
        return Err(crate::tui::ViewError::Unsupported(why).into());
    }
    let settings = args.look.settings(args.mode, args.cull);
    let mut app = if crate::scene::is_scene_path(&args.model) {
        let scene = crate::scene::Scene::load(std::path::Path::new(&args.model))?;
        App::with_scene(scene, settings)
    } else {
        App::new(load_model(&args.model)?, settings)
    };
    app.notice = args.look.notice_in(env);
    crate::tui::run(app, args.fps)?;
    Ok(())
}

fn sgr(c: ratatui::style::Color, fg: bool) -> String {
    use ratatui::style::Color as C;
    let base = if fg { 30 } else { 40 };
    match c {
        C::Rgb(r, g, b) => format!("{};2;{r};{g};{b}", base + 8),
        C::Indexed(n) => format!("{};5;{n}", base + 8),
        C::Reset => format!("{}", base + 9),
        named => {
            let order = [
                C::Black,
                C::Red,
                C::Green,
                C::Yellow,
                C::Blue,
                C::Magenta,
                C::Cyan,
                C::Gray,
                C::DarkGray,
                C::LightRed,
                C::LightGreen,
                C::LightYellow,
                C::LightBlue,
                C::LightMagenta,
                C::LightCyan,
                C::White,
            ];
            let i = order.iter().position(|x| *x == named).unwrap_or(7) as u16;
            let code = if i < 8 { base + i } else { base + 60 + i - 8 };
            code.to_string()
        }
    }
}

/// Writes the viewport's cells as ANSI text: colours as SGR sequences only where they
/// change, a reset at the end of each line.
pub fn write_ansi(vp: &Viewport, out: &mut impl Write) -> io::Result<()> {
    let mode = vp.settings.colors;
    let to = |c: Option<[u8; 3]>| match (c, mode) {
        (Some(c), m) if m != ColorMode::None => m.color(c),
        _ => ratatui::style::Color::Reset,
    };
    let mut line = String::new();
    for cy in 0..vp.rows {
        line.clear();
        let mut cur = (ratatui::style::Color::Reset, ratatui::style::Color::Reset);
        for cx in 0..vp.cols {
            let Some(g) = vp.cell(cx, cy) else { continue };
            let want = (to(g.fg), to(g.bg));
            if want != cur && mode != ColorMode::None {
                line.push_str(&format!(
                    "\x1b[{};{}m",
                    sgr(want.0, true),
                    sgr(want.1, false)
                ));
                cur = want;
            }
            line.push(g.ch);
        }
        if mode != ColorMode::None {
            line.push_str("\x1b[0m");
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}
