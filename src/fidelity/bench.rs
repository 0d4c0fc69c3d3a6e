//! The benchmark's run: every glyph mode × colour depth of every view, and chafa's
//! symbol sets on the same views, each through the emulator and painter and scored
//! against the view's reference.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use image::RgbImage;

use super::chafa::{Chafa, SYMBOL_SETS};
use super::config::{Config, View, file_name};
use super::metrics::{self, Score};
use super::reference::{self, ReferenceImages};
use super::{FidelityError, save_png};
use crate::scene::Scene;
use crate::scene::render::SceneView;
use crate::terminal::Palette;
use crate::terminal::glyphs::FitSpace;
use crate::terminal::paint;
use crate::terminal::{ColorMode, GlyphMode};
use crate::tui::viewport::{SceneState, ViewSettings, Viewport};

/// Who drew the cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Source {
    Termrast,
    Chafa,
}

impl Source {
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Source::Termrast => "termrast",
            Source::Chafa => "chafa",
        }
    }
}

/// One frame's scores.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    pub view: String,
    pub source: Source,
    /// termrast's glyph mode or chafa's symbol set.
    pub method: String,
    pub colors: ColorMode,
    /// The palette the frame was painted with (see [`palettes`]).
    pub palette: Palette,
    pub score: Score,
    /// Bytes of the frame's output.
    pub bytes: usize,
    /// Cells whose character the painter does not know.
    pub unpainted: usize,
    /// The size in cells of what the bytes print (columns, rows).
    pub printed: (u16, u16),
}

/// All measurements in view order, and notes on what was skipped or looked odd.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    pub measurements: Vec<Measurement>,
    pub notes: Vec<String>,
}

/// The terminal palettes of the benchmark: xterm's, and chafa's own.
pub const PALETTES: [Palette; 2] = [Palette::XTERM, Palette::CHAFA];

/// The palettes a frame at depth `colors` is painted with: xterm's always, and chafa's
/// too where the frame's colours depend on it (16 and 256 colours). chafa fits to its
/// own 16 ANSI colours ([`Palette::CHAFA`]; at 256 colours it picks indices 0–15 where
/// one is nearest) whatever the terminal has, so its frames are shown on the palette
/// it assumes and on xterm's. termrast fits to the palette the terminal reports (at 256
/// colours using 0–15 only then), so each of its indexed frames is fitted to the
/// palette it is painted on (`measure_view` renders one per palette).
#[must_use]
pub fn palettes(colors: ColorMode) -> &'static [Palette] {
    match colors {
        ColorMode::Ansi16 | ColorMode::Ansi256 => &PALETTES,
        _ => &[Palette::XTERM],
    }
}

/// termrast's frame as the bytes a terminal receives: the one place the encoder is
/// called, so a better one replaces it here.
pub fn encode(vp: &Viewport) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    crate::terminal::ansi::write_frame(
        &vp.cells,
        usize::from(vp.cols),
        vp.settings.colors,
        &vp.settings.palette,
        false,
        &mut bytes,
    )?;
    Ok(bytes)
}

/// Runs the benchmark: the views are shared out among the CPU's cores.
pub fn run(config: &Config) -> Result<Outcome, FidelityError> {
    config.check()?;
    let mut models = HashMap::new();
    for v in &config.views {
        if !models.contains_key(&v.model) {
            models.insert(v.model.clone(), Scene::for_model(&v.model)?);
        }
    }
    if let Some(dir) = &config.keep {
        std::fs::create_dir_all(dir).map_err(|e| FidelityError::Io(dir.clone(), e))?;
    }
    let mut notes = Vec::new();
    let chafa = if config.chafa {
        match Chafa::find() {
            Ok(c) => {
                notes.push(format!("compared with {}", c.version));
                Some(c)
            }
            Err(e) => {
                notes.push(format!("{e}: termrast rows only"));
                None
            }
        }
    } else {
        notes.push("chafa not run (--no-chafa)".into());
        None
    };
    let workers = std::thread::available_parallelism()
        .map_or(1, usize::from)
        .min(config.views.len());
    let next = AtomicUsize::new(0);
    let mut results: Vec<(usize, Result<Outcome, FidelityError>)> = Vec::new();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(view) = config.views.get(i) else {
                            break done;
                        };
                        let model = &models[&view.model];
                        done.push((i, measure_view(config, model, view, chafa.as_ref())));
                    }
                })
            })
            .collect();
        for h in handles {
            match h.join() {
                Ok(done) => results.extend(done),
                Err(_) => results.push((usize::MAX, Err(FidelityError::Worker))),
            }
        }
    });
    results.sort_by_key(|r| r.0);
    let mut measurements = Vec::new();
    for (_, r) in results {
        let o = r?;
        measurements.extend(o.measurements);
        notes.extend(o.notes);
    }
    notes.push(
        "palette: the 16 ANSI colours the indexed frames are painted with; `xterm` is \
         xterm's, `chafa` is chafa's own (what it always fits to: colour 7 #c0c0c0, \
         8 #404040, dim colours at #80/#70); termrast's 16- and 256-colour frames are \
         fitted to the palette they are painted on, as the viewer fits to the palette \
         the terminal reports; the rest of the 256 are the same in both"
            .into(),
    );
    notes.extend(size_notes(config, &measurements));
    Ok(Outcome {
        measurements,
        notes,
    })
}

/// Notes on outputs that do not print exactly the grid's size (the emulator's
/// screen is the grid's size, so a smaller output is padded with blank cells).
/// termrast leaves trailing blank cells unwritten by design, so only a frame that
/// prints beyond the grid is noted for it.
fn size_notes(config: &Config, ms: &[Measurement]) -> Vec<String> {
    let grid = (config.cols, config.rows);
    let mut notes = Vec::new();
    for source in [Source::Termrast, Source::Chafa] {
        let of: Vec<_> = ms
            .iter()
            .filter(|m| m.source == source && m.palette == Palette::XTERM)
            .collect();
        let wrong = |m: &&&Measurement| match source {
            Source::Termrast => m.printed.0 > grid.0 || m.printed.1 > grid.1,
            Source::Chafa => m.printed != grid,
        };
        let off: Vec<_> = of.iter().filter(wrong).collect();
        if of.is_empty() {
            continue;
        }
        if off.is_empty() {
            notes.push(match source {
                Source::Termrast => format!(
                    "no termrast frame printed beyond {}×{} cells (trailing blank cells are left unwritten)",
                    grid.0, grid.1
                ),
                Source::Chafa => format!(
                    "every chafa frame printed exactly {}×{} cells",
                    grid.0, grid.1
                ),
            });
        }
        for m in off {
            notes.push(format!(
                "{} {} {} on {} printed {}×{} cells, not {}×{} (blank cells pad it)",
                source.name(),
                m.method,
                m.colors.name(),
                m.view,
                m.printed.0,
                m.printed.1,
                grid.0,
                grid.1
            ));
        }
    }
    notes
}

/// The reference of one camera, rendered and prepared for scoring.
struct Prepared {
    camera: SceneView,
    images: ReferenceImages,
    metric: metrics::Reference,
}

/// Scores one frame's bytes on each palette of `on`: emulated, painted and compared
/// with the reference.
fn measure(
    config: &Config,
    reference: &Prepared,
    bytes: &[u8],
    id: (&View, Source, &str, ColorMode),
    on: &[Palette],
    out: &mut Vec<Measurement>,
) -> Result<(), FidelityError> {
    let (view, source, method, colors) = id;
    let printed = paint::printed_size(bytes, config.cols, config.rows)?;
    for &palette in on {
        let grid = paint::emulate_in(bytes, config.cols, config.rows, &palette)?;
        let painted = paint::paint(&grid)?;
        let score = reference.metric.score(&painted.image)?;
        if let Some(dir) = &config.keep {
            let on = if palette == Palette::XTERM {
                String::new()
            } else {
                format!("-{}-palette", palette.name)
            };
            let name = format!(
                "{}-{}-{method}-{}{on}",
                view.name(),
                source.name(),
                colors.name()
            );
            save_png(&dir.join(file_name(&name)), &painted.image)?;
        }
        out.push(Measurement {
            view: view.name(),
            source,
            method: method.to_owned(),
            colors,
            palette,
            score,
            bytes: bytes.len(),
            unpainted: painted.unpainted,
            printed,
        });
    }
    Ok(())
}

/// Every mode as the viewer draws it, and the shape-fitted ones with their error
/// measured in linear light too (what that choice costs).
pub fn variants() -> impl Iterator<Item = (GlyphMode, FitSpace)> {
    GlyphMode::ALL
        .map(|g| (g, FitSpace::Srgb))
        .into_iter()
        .chain([
            (GlyphMode::Ascii, FitSpace::Linear),
            (GlyphMode::Blocks, FitSpace::Linear),
            (GlyphMode::Wedges, FitSpace::Linear),
        ])
}

/// Every termrast mode and colour depth of one view, then chafa's.
fn measure_view(
    config: &Config,
    model: &Scene,
    view: &View,
    chafa: Option<&Chafa>,
) -> Result<Outcome, FidelityError> {
    let (cols, rows) = (config.cols, config.rows);
    let (w, h) = config.pixels();
    let mut vp = Viewport::default();
    let mut state = SceneState::new(model.clone());
    let mut prepared: Option<Prepared> = None;
    let mut out = Outcome::default();
    for (glyphs, fit_space) in variants() {
        let method = match fit_space {
            FitSpace::Srgb => glyphs.name().to_string(),
            FitSpace::Linear => format!("{}-linear", glyphs.name()),
        };
        let depths = ColorMode::ALL
            .into_iter()
            .flat_map(|c| palettes(c).iter().map(move |p| (c, *p)));
        for (colors, palette) in depths {
            let settings = ViewSettings {
                glyphs,
                colors,
                angle: view.angle,
                tilt: view.tilt,
                fit_space,
                // As the viewer has it once the terminal has answered.
                palette: palette.reported(),
                ..ViewSettings::default()
            };
            vp.render(&mut state, &settings, (cols, rows));
            let camera = SceneView {
                pixel_aspect: 1.0,
                ..vp.view
            };
            let reference = match prepared.take() {
                Some(p) if p.camera == camera => p,
                old => {
                    if old.is_some() {
                        out.notes.push(format!(
                            "{}: {} frames have a camera of their own; their reference \
                             was rendered again",
                            view.name(),
                            glyphs.name()
                        ));
                    }
                    let images = reference::render(model, &camera, w, h);
                    if let Some(dir) = &config.keep {
                        let name = format!("{}-reference", view.name());
                        save_png(&dir.join(file_name(&name)), &images.image)?;
                    }
                    let metric = metrics::Reference::new(&images.image)?;
                    Prepared {
                        camera,
                        images,
                        metric,
                    }
                }
            };
            let bytes = encode(&vp).map_err(FidelityError::Encode)?;
            let id = (view, Source::Termrast, method.as_str(), colors);
            measure(
                config,
                &reference,
                &bytes,
                id,
                &[palette],
                &mut out.measurements,
            )?;
            prepared = Some(reference);
        }
    }
    if let (Some(chafa), Some(reference)) = (chafa, &prepared) {
        measure_chafa(config, chafa, reference, view, &mut out)?;
    }
    Ok(out)
}

/// A PNG for chafa to read: in the keep directory, or a temporary file removed on drop.
struct ChafaInput {
    path: PathBuf,
    temporary: bool,
}

impl ChafaInput {
    fn write(config: &Config, view: &View, img: &RgbImage) -> Result<Self, FidelityError> {
        let (path, temporary) = match &config.keep {
            Some(dir) => (
                dir.join(file_name(&format!("{}-reference-full", view.name()))),
                false,
            ),
            None => {
                let name = format!("termrast-fidelity-{}-{}", std::process::id(), view.name());
                (std::env::temp_dir().join(file_name(&name)), true)
            }
        };
        save_png(&path, img)?;
        Ok(Self { path, temporary })
    }
}

impl Drop for ChafaInput {
    fn drop(&mut self) {
        if self.temporary {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// chafa's symbol sets at every colour depth on one view; a failed conversion is a
/// note, not an error.
fn measure_chafa(
    config: &Config,
    chafa: &Chafa,
    reference: &Prepared,
    view: &View,
    out: &mut Outcome,
) -> Result<(), FidelityError> {
    let input = match ChafaInput::write(config, view, &reference.images.full) {
        Ok(i) => i,
        Err(e) if config.keep.is_none() => {
            out.notes
                .push(format!("{}: no chafa rows: {e}", view.name()));
            return Ok(());
        }
        Err(e) => return Err(e),
    };
    for set in SYMBOL_SETS {
        for colors in ColorMode::ALL {
            match chafa.convert(&input.path, config.cols, config.rows, set, colors) {
                Ok(bytes) => {
                    let id = (view, Source::Chafa, set, colors);
                    let on = palettes(colors);
                    measure(config, reference, &bytes, id, on, &mut out.measurements)?;
                }
                Err(e) => out.notes.push(format!("{}: {e}", view.name())),
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indexed_frames_are_painted_on_every_palette() {
        assert_eq!(palettes(ColorMode::Truecolor), [Palette::XTERM]);
        assert_eq!(palettes(ColorMode::None), [Palette::XTERM]);
        assert_eq!(palettes(ColorMode::Ansi16), PALETTES);
        assert_eq!(palettes(ColorMode::Ansi256), PALETTES);
        // termrast's 256-colour frames use the indices the palettes differ in only
        // where the terminal reported its palette.
        let mut low = 0;
        for i in 0..=255u8 {
            let c = ColorMode::Ansi256.color([i, i / 2, 255 - i], &Palette::XTERM);
            let grey = ColorMode::Ansi256.color([i; 3], &Palette::XTERM);
            for c in [c, grey] {
                assert!(
                    matches!(c, ratatui::style::Color::Indexed(n) if n >= 16),
                    "{c:?}"
                );
            }
            let reported = ColorMode::Ansi256.color([i; 3], &Palette::CHAFA.reported());
            low += usize::from(matches!(reported, ratatui::style::Color::Indexed(n) if n < 16));
        }
        assert!(low > 0);
    }
}
