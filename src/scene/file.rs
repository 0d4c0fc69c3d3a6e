//! The scene file: TOML read with serde, every key but `object.model` optional,
//! unknown keys and bad values rejected with the key, the file and the line.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;

use super::SceneError;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub render: RenderFile,
    /// Absent: the camera frames the objects' bounding sphere.
    pub camera: Option<CameraFile>,
    #[serde(default, rename = "light")]
    pub lights: Vec<LightFile>,
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectFile>,
}

/// `[render]`: scene-wide settings.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderFile {
    /// Samples per sub-sample: 1, 4 or 16.
    pub antialias: u32,
    pub background: [f32; 3],
}

impl Default for RenderFile {
    fn default() -> Self {
        Self {
            antialias: 1,
            background: [0.0; 3],
        }
    }
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraFile {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov: f32,
    pub near: f32,
    pub far: f32,
}

impl Default for CameraFile {
    fn default() -> Self {
        Self {
            eye: [0.0, 0.0, 2.6],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov: 45.0,
            near: 0.1,
            far: 10.0,
        }
    }
}

/// Kinds of light.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Ambient,
    Directional,
    Point,
}

/// `[[light]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightFile {
    pub kind: LightKind,
    #[serde(default)]
    pub color: Option<[f32; 3]>,
    #[serde(default)]
    pub intensity: Option<f32>,
    /// Directional: towards the light.
    #[serde(default)]
    pub direction: Option<[f32; 3]>,
    /// Point: where it is.
    #[serde(default)]
    pub position: Option<[f32; 3]>,
}

/// How a surface is lit.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "kebab-case")]
pub enum Lighting {
    /// The material colour, unlit.
    #[default]
    None,
    /// Lit once per face (face normal, at the face centre).
    Flat,
    /// Lit per vertex, the colour interpolated (Gouraud).
    Gouraud,
    /// Diffuse (Lambert) per pixel from interpolated normals.
    Lambert,
    /// Diffuse and Blinn–Phong specular per pixel.
    BlinnPhong,
}

impl Lighting {
    /// The name used in scene files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Lighting::None => "none",
            Lighting::Flat => "flat",
            Lighting::Gouraud => "gouraud",
            Lighting::Lambert => "lambert",
            Lighting::BlinnPhong => "blinn-phong",
        }
    }

    /// Lit per pixel (needs interpolated normals).
    #[must_use]
    pub fn per_pixel(self) -> bool {
        matches!(self, Lighting::Lambert | Lighting::BlinnPhong)
    }

    /// Lit per vertex or face (the result is an interpolated colour).
    #[must_use]
    pub fn per_vertex(self) -> bool {
        matches!(self, Lighting::Flat | Lighting::Gouraud)
    }
}

/// Texture filtering.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum TextureMode {
    #[default]
    Off,
    Nearest,
    Bilinear,
}

/// `[[object]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectFile {
    /// `teapot`, `bunny`, `sphere:N`, or a model file relative to the scene file.
    pub model: String,
    #[serde(default)]
    pub position: [f32; 3],
    /// Degrees about x, then y, then z.
    #[serde(default)]
    pub rotation: [f32; 3],
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub spin: Option<SpinFile>,
    #[serde(default)]
    pub material: MaterialFile,
    #[serde(default)]
    pub effects: EffectsFile,
}

fn one() -> f32 {
    1.0
}

/// `spin = { axis = [...], speed = ... }`: radians per second about an axis.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SpinFile {
    pub axis: [f32; 3],
    pub speed: f32,
}

impl Default for SpinFile {
    fn default() -> Self {
        Self {
            axis: [0.0, 1.0, 0.0],
            speed: 0.5,
        }
    }
}

/// `[object.material]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MaterialFile {
    pub color: [f32; 3],
    pub lighting: Lighting,
    /// Blinn–Phong specular strength and exponent.
    pub specular: f32,
    pub shininess: f32,
    /// Multiply by the model's vertex colours.
    pub vertex_colors: bool,
    /// Sample the texture (the OBJ material's `map_Kd`, or `image`).
    pub texture: TextureMode,
    /// A PNG to use instead of the OBJ material's `map_Kd` (relative to the scene), or
    /// `checker` for a built-in 64×64 checkerboard.
    pub image: Option<String>,
    /// Also use the model file's materials: `Kd` colours per `usemtl` (or glTF base
    /// colours), their textures and the vertex colours.
    pub from_model: bool,
}

impl Default for MaterialFile {
    fn default() -> Self {
        Self {
            color: [1.0; 3],
            lighting: Lighting::None,
            specular: 0.5,
            shininess: 32.0,
            vertex_colors: false,
            texture: TextureMode::Off,
            image: None,
            from_model: false,
        }
    }
}

/// `[object.effects]`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct EffectsFile {
    /// Draw the triangles (off: only the edges and silhouettes, as the viewer's
    /// wireframe mode shows a model).
    pub fill: bool,
    pub depth_test: bool,
    pub cull: bool,
    pub fog: Option<FogFile>,
    pub depth_shading: bool,
    pub wireframe: bool,
    pub silhouette: bool,
}

impl Default for EffectsFile {
    fn default() -> Self {
        Self {
            fill: true,
            depth_test: false,
            cull: false,
            fog: None,
            depth_shading: false,
            wireframe: false,
            silhouette: false,
        }
    }
}

/// `fog = { start = .., end = .., color = [..] }`: linear fog by view depth.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct FogFile {
    pub start: f32,
    pub end: f32,
    pub color: [f32; 3],
}

impl Default for FogFile {
    fn default() -> Self {
        Self {
            start: 2.0,
            end: 4.0,
            color: [0.0; 3],
        }
    }
}

/// Parses scene text; `path` names the file in errors.
pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        SceneError::Invalid {
            path: path.into(),
            line,
            problem: e.message().trim().to_string(),
        }
    })?;
    validate(&file, text, path)?;
    Ok(file)
}

/// Line (1-based) of the first line mentioning `key` at or after the `n`-th
/// `[[object]]` (or anywhere when `n` is `None`), for errors found after parsing.
fn line_of(text: &str, section: Option<(&str, usize)>, key: &str) -> Option<usize> {
    let mut start = 0;
    if let Some((header, n)) = section {
        start = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.trim() == header)
            .nth(n)
            .map(|(i, _)| i)?;
    }
    text.lines()
        .enumerate()
        .skip(start)
        .find(|(_, l)| {
            let l = l.trim_start();
            l.starts_with(key) && l[key.len()..].trim_start().starts_with('=')
        })
        .map(|(i, _)| i + 1)
        .or(section.map(|_| start + 1))
}

fn finite3(v: [f32; 3]) -> bool {
    v.iter().all(|c| c.is_finite())
}

/// Checks values serde cannot: ranges, finiteness, keys that do not apply.
fn validate(f: &SceneFile, text: &str, path: &Path) -> Result<(), SceneError> {
    let bad = |section: Option<(&str, usize)>, key: &str, problem: String| SceneError::Invalid {
        path: path.into(),
        line: line_of(text, section, key),
        problem,
    };
    if f.objects.is_empty() {
        return Err(SceneError::Invalid {
            path: path.into(),
            line: None,
            problem: "no objects: add at least one `[[object]]` with `model = \"...\"`".into(),
        });
    }
    let r = &f.render;
    if ![1, 4, 16].contains(&r.antialias) {
        return Err(bad(
            None,
            "antialias",
            format!(
                "render.antialias = {}: allowed values are 1, 4 and 16",
                r.antialias
            ),
        ));
    }
    if !finite3(r.background) {
        return Err(bad(
            None,
            "background",
            "render.background must be finite".into(),
        ));
    }
    if let Some(c) = &f.camera {
        if !(c.fov.is_finite() && c.fov > 1.0 && c.fov < 179.0) {
            return Err(bad(
                None,
                "fov",
                format!("camera.fov = {}: must be between 1 and 179 degrees", c.fov),
            ));
        }
        if !(c.near.is_finite() && c.far.is_finite() && c.near > 0.0 && c.far > c.near) {
            return Err(bad(
                None,
                "near",
                format!(
                    "camera.near = {} and far = {}: need 0 < near < far",
                    c.near, c.far
                ),
            ));
        }
        let eye = Vec3::from(c.eye);
        let dir = Vec3::from(c.target) - eye;
        if !(finite3(c.eye) && finite3(c.target) && finite3(c.up))
            || dir.length_squared() == 0.0
            || dir.cross(Vec3::from(c.up)).length_squared() == 0.0
        {
            return Err(bad(
                None,
                "eye",
                "camera: eye, target and up must be finite, eye ≠ target, and up not along the view"
                    .into(),
            ));
        }
    }
    for (i, l) in f.lights.iter().enumerate() {
        let sec = Some(("[[light]]", i));
        let name = |k: LightKind| match k {
            LightKind::Ambient => "an ambient",
            LightKind::Directional => "a directional",
            LightKind::Point => "a point",
        };
        if l.direction.is_some() && l.kind != LightKind::Directional {
            return Err(bad(
                sec,
                "direction",
                format!(
                    "light {}: `direction` does not apply to {} light",
                    i + 1,
                    name(l.kind)
                ),
            ));
        }
        if l.position.is_some() && l.kind != LightKind::Point {
            return Err(bad(
                sec,
                "position",
                format!(
                    "light {}: `position` does not apply to {} light",
                    i + 1,
                    name(l.kind)
                ),
            ));
        }
        let ok = l.color.is_none_or(finite3)
            && l.intensity.is_none_or(|v| v.is_finite() && v >= 0.0)
            && l.direction
                .is_none_or(|d| finite3(d) && Vec3::from(d).length_squared() > 0.0)
            && l.position.is_none_or(finite3);
        if !ok {
            return Err(bad(
                sec,
                "kind",
                format!(
                    "light {}: colour, direction and position must be finite, intensity ≥ 0, direction non-zero",
                    i + 1
                ),
            ));
        }
    }
    for (i, o) in f.objects.iter().enumerate() {
        let sec = Some(("[[object]]", i));
        let n = i + 1;
        if o.model.trim().is_empty() {
            return Err(bad(sec, "model", format!("object {n}: `model` is empty")));
        }
        if !(finite3(o.position) && finite3(o.rotation)) {
            return Err(bad(
                sec,
                "position",
                format!("object {n}: position and rotation must be finite"),
            ));
        }
        if !(o.scale.is_finite() && o.scale > 0.0) {
            return Err(bad(
                sec,
                "scale",
                format!("object {n}: scale = {} must be a positive number", o.scale),
            ));
        }
        let spin_ok = |s: &SpinFile| {
            finite3(s.axis) && Vec3::from(s.axis).length_squared() > 0.0 && s.speed.is_finite()
        };
        if !o.spin.as_ref().is_none_or(spin_ok) {
            return Err(bad(
                sec,
                "spin",
                format!("object {n}: spin needs a non-zero finite axis and a finite speed"),
            ));
        }
        let m = &o.material;
        let material_ok = finite3(m.color)
            && m.specular.is_finite()
            && m.specular >= 0.0
            && m.shininess.is_finite()
            && m.shininess >= 1.0;
        if !material_ok {
            return Err(bad(
                sec,
                "color",
                format!("object {n}: material colour must be finite, specular ≥ 0, shininess ≥ 1"),
            ));
        }
        if m.image.is_some() && m.texture == TextureMode::Off {
            return Err(bad(
                sec,
                "image",
                format!(
                    "object {n}: `image` given but texture = \"off\" (use \"nearest\" or \"bilinear\")"
                ),
            ));
        }
        let fog_ok = |f: &FogFile| {
            f.start.is_finite() && f.end.is_finite() && f.end > f.start && finite3(f.color)
        };
        if let Some(fog) = o.effects.fog.as_ref().filter(|f| !fog_ok(f)) {
            return Err(bad(
                sec,
                "fog",
                format!(
                    "object {n}: fog needs finite start < end (got {} and {})",
                    fog.start, fog.end
                ),
            ));
        }
    }
    Ok(())
}

/// Resolves a model spec: built-in names stay, anything else is relative to the
/// scene file's directory.
#[must_use]
pub fn resolve(spec: &str, scene: &Path) -> String {
    if spec == "teapot" || spec == "bunny" || spec.starts_with("sphere:") {
        return spec.to_string();
    }
    let p = Path::new(spec);
    if p.is_absolute() {
        return spec.to_string();
    }
    scene
        .parent()
        .unwrap_or_else(|| Path::new("."))
        .join(p)
        .to_string_lossy()
        .into_owned()
}

/// A path relative to the scene file.
#[must_use]
pub fn relative(spec: &str, scene: &Path) -> PathBuf {
    let p = Path::new(spec);
    if p.is_absolute() {
        p.into()
    } else {
        scene.parent().unwrap_or_else(|| Path::new(".")).join(p)
    }
}
