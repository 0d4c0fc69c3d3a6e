//! `termrast bench bytes`'s measurement on a small grid: through the cell cache the
//! spinning teapot costs fewer bytes than sending every changed cell, and what the
//! terminal shows scores within the cache's budget of SSIM.

use termrast::fidelity::spin::{SpinConfig, measure};
use termrast::scene::Scene;
use termrast::terminal::{ColorMode, GlyphMode};

#[test]
fn the_cache_sends_fewer_bytes_for_almost_the_same_picture() {
    let config = SpinConfig {
        cols: 48,
        rows: 16,
        frames: 5,
        ..SpinConfig::default()
    };
    let model = Scene::for_model("teapot").expect("built in");
    let r = measure(
        &config,
        "teapot",
        &model,
        GlyphMode::Braille,
        ColorMode::Truecolor,
    )
    .expect("measured");
    assert!(
        r.cached_bytes > 0.0 && r.cached_bytes < 0.8 * r.exact_bytes,
        "{r:?}"
    );
    let (cached, exact) = r.ssim.expect("scored");
    assert!(exact > 0.5 && (exact - cached).abs() < 0.01, "{r:?}");
    // Without colour every change is a change of glyph: both send the same.
    let r = measure(
        &config,
        "teapot",
        &model,
        GlyphMode::Braille,
        ColorMode::None,
    )
    .expect("measured");
    assert_eq!(r.cached_bytes, r.exact_bytes);
}
