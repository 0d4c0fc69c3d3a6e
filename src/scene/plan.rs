//! The plan: what a scene's effects require, decided once when it is loaded.
//!
//! It fixes which vertex attributes are kept and transformed, which varyings each
//! object's pipeline interpolates (its compile-time varying set), which buffers exist
//! and are cleared, and which per-pixel stages run. The renderer follows it and does
//! nothing else; `termrast render SCENE --plan` prints it.

use std::fmt;

use super::file::{LightKind, Lighting, TextureMode};
use super::{LightDesc, ObjectDesc};

/// The varyings an object's pipeline interpolates (one monomorphized pipeline per
/// combination).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct VaryingSet {
    /// World-space normal (per-pixel lighting).
    pub normal: bool,
    /// World-space position (point lights, specular, fog, depth shading).
    pub position: bool,
    /// A colour (vertex colours and per-vertex or per-face lighting).
    pub color: bool,
    /// Texture coordinates.
    pub uv: bool,
}

impl VaryingSet {
    /// Floats interpolated per fragment.
    #[must_use]
    pub fn floats(self) -> usize {
        3 * usize::from(self.normal)
            + 3 * usize::from(self.position)
            + 3 * usize::from(self.color)
            + 2 * usize::from(self.uv)
    }
}

impl fmt::Display for VaryingSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = [
            (self.normal, "normal"),
            (self.position, "position"),
            (self.color, "colour"),
            (self.uv, "uv"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect();
        if names.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&names.join(", "))
        }
    }
}

/// One stage of the plan: on, or skipped and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StageLine {
    pub stage: &'static str,
    pub on: bool,
    /// Why it is on (what needs it), or why it is skipped.
    pub reason: String,
}

impl StageLine {
    fn new(stage: &'static str, on: bool, reason: impl Into<String>) -> Self {
        Self {
            stage,
            on,
            reason: reason.into(),
        }
    }
}

impl fmt::Display for StageLine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let state = if self.on { "on" } else { "skipped" };
        if self.reason.is_empty() {
            write!(f, "{}: {state}", self.stage)
        } else {
            write!(f, "{}: {state} ({})", self.stage, self.reason)
        }
    }
}

/// What one object needs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjectPlan {
    pub name: String,
    pub varyings: VaryingSet,
    /// Normals are needed (per-pixel, per-vertex or per-face lighting).
    pub normals: bool,
    /// Flat lighting: the mesh is split so each face has its own vertices.
    pub unweld: bool,
    /// World positions are computed in the vertex stage (for a varying, or for
    /// per-vertex lighting by point lights or specular).
    pub world_positions: bool,
    pub vertex_colors: bool,
    pub uvs: bool,
    pub texture: TextureMode,
    /// The triangles are drawn (else only edges and silhouettes).
    pub fill: bool,
    /// The triangles' depth test (with [`ObjectPlan::fill`]: see
    /// [`ObjectPlan::writes_depth`]).
    pub depth_test: bool,
    pub cull: bool,
    pub fog: bool,
    pub depth_shading: bool,
    pub wireframe: bool,
    /// Wireframe lines hidden behind surfaces (needs this object to write depth).
    pub hidden_lines: bool,
    pub silhouette: bool,
    /// Unique edges are computed (wireframe or silhouettes).
    pub edges: bool,
    pub lines: Vec<StageLine>,
}

impl ObjectPlan {
    /// Its triangles are drawn and depth-tested, so it needs the depth buffer and can
    /// hide lines.
    #[must_use]
    pub fn writes_depth(&self) -> bool {
        self.fill && self.depth_test
    }
}

/// The plan of a scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    pub depth_buffer: bool,
    /// Samples per sub-sample (1, 4 or 16).
    pub samples: u32,
    pub lines: Vec<StageLine>,
    pub objects: Vec<ObjectPlan>,
}

impl Plan {
    /// The plan for a scene's objects and lights.
    #[must_use]
    pub fn new(objects: &[ObjectDesc], lights: &[LightDesc], samples: u32) -> Self {
        let objects: Vec<ObjectPlan> = objects.iter().map(|o| object_plan(o, lights)).collect();
        let depth_users: Vec<String> = objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.writes_depth())
            .map(|(i, _)| (i + 1).to_string())
            .collect();
        let depth_buffer = !depth_users.is_empty();
        let mut lines = vec![
            StageLine::new(
                "colour buffer",
                true,
                "RGBA8, one sample per terminal sub-sample",
            ),
            if depth_buffer {
                StageLine::new(
                    "depth buffer",
                    true,
                    format!(
                        "f32, cleared each frame: object {} tests depth",
                        depth_users.join(", ")
                    ),
                )
            } else {
                StageLine::new(
                    "depth buffer",
                    false,
                    "no object tests depth: not allocated, not cleared",
                )
            },
        ];
        lines.push(if samples > 1 {
            let side = crate::raster::samples::grid_side(samples);
            StageLine::new(
                "supersampling",
                true,
                format!("{samples} samples per sub-sample ({side}×{side} grid), averaged"),
            )
        } else {
            StageLine::new("supersampling", false, "antialias = 1")
        });
        Self {
            depth_buffer,
            samples,
            lines,
            objects,
        }
    }
}

fn object_plan(o: &ObjectDesc, lights: &[LightDesc]) -> ObjectPlan {
    let m = &o.material;
    let e = &o.effects;
    let shading = e.depth_shading;
    // Depth shading shows depth alone: lighting, colours and textures do not run.
    let lighting = if shading { Lighting::None } else { m.lighting };
    let vertex_colors = m.vertex_colors && !shading;
    let texture = if shading { TextureMode::Off } else { m.texture };
    let points = lights.iter().any(|l| l.kind == LightKind::Point);
    let specular = lighting == Lighting::BlinnPhong;
    let fog = e.fog.is_some();
    let varyings = VaryingSet {
        normal: lighting.per_pixel(),
        position: (lighting.per_pixel() && (points || specular)) || fog || shading,
        color: lighting.per_vertex() || vertex_colors,
        uv: texture != TextureMode::Off,
    };
    let normals = lighting != Lighting::None;
    let world_positions = varyings.position || lighting.per_vertex();
    let hidden_lines = e.wireframe && e.depth_test && e.fill;
    let why_lighting_off = if shading {
        "depth shading replaces lighting"
    } else {
        "lighting = \"none\": the material colour"
    };
    let on = |s: &'static str, r: &str| StageLine::new(s, true, r);
    let off = |s: &'static str, r: &str| StageLine::new(s, false, r);
    let mut lines = vec![on("positions", "clip space, every vertex")];
    lines.push(match lighting {
        Lighting::None => off(
            "normals",
            if shading {
                why_lighting_off
            } else {
                "no lighting"
            },
        ),
        Lighting::Flat => on("normals", "face normals: the mesh is split per face"),
        Lighting::Gouraud => on(
            "normals",
            "per-vertex lighting; generated if the model has none",
        ),
        _ => on(
            "normals",
            "interpolated for per-pixel lighting; generated if the model has none",
        ),
    });
    lines.push(if world_positions {
        let mut needs = Vec::new();
        if lighting.per_pixel() && points {
            needs.push("point lights");
        }
        if specular {
            needs.push("specular");
        }
        if lighting.per_vertex() && !varyings.position {
            needs.push("per-vertex lighting");
        }
        if fog {
            needs.push("fog");
        }
        if shading {
            needs.push("depth shading");
        }
        on("world positions", &needs.join(", "))
    } else {
        off(
            "world positions",
            "no point lights, specular, fog or depth shading",
        )
    });
    lines.push(if vertex_colors {
        on("vertex colours", "material.vertex_colors")
    } else if m.vertex_colors {
        off("vertex colours", "depth shading")
    } else {
        off("vertex colours", "vertex_colors = false")
    });
    lines.push(if varyings.uv {
        on("texture coordinates", "texture")
    } else {
        off("texture coordinates", "no texture")
    });
    lines.push(if varyings.floats() == 0 {
        off("varyings", "nothing is interpolated")
    } else {
        StageLine::new(
            "varyings",
            true,
            format!("{varyings}: {} floats per fragment", varyings.floats()),
        )
    });
    lines.push(match lighting {
        Lighting::None => off("lighting", why_lighting_off),
        Lighting::Flat => on("lighting", "flat: once per face, at its centre"),
        Lighting::Gouraud => on("lighting", "Gouraud: per vertex, colour interpolated"),
        Lighting::Lambert => on("lighting", "Lambert per pixel"),
        Lighting::BlinnPhong => on("lighting", "Lambert + Blinn–Phong specular per pixel"),
    });
    lines.push(match texture {
        TextureMode::Off if m.texture != TextureMode::Off => {
            off("texture lookups", "depth shading")
        }
        TextureMode::Off => off("texture lookups", "no texture"),
        TextureMode::Nearest => on("texture lookups", "nearest, perspective-correct uv"),
        TextureMode::Bilinear => on("texture lookups", "bilinear, perspective-correct uv"),
    });
    lines.push(if e.depth_test {
        on("depth test", "less, writes depth")
    } else {
        off("depth test", "depth_test = false: drawn in order")
    });
    lines.push(if e.cull {
        on("back-face culling", "")
    } else {
        off("back-face culling", "cull = false")
    });
    lines.push(match e.fog {
        Some(f) => on(
            "fog",
            &format!("linear in view depth from {} to {}", f.start, f.end),
        ),
        None => off("fog", "no fog"),
    });
    lines.push(if shading {
        on("depth shading", "grey by view depth")
    } else {
        off("depth shading", "depth_shading = false")
    });
    lines.push(match (e.wireframe, hidden_lines) {
        (true, true) => on("wireframe", "hidden lines removed against the depth buffer"),
        (true, false) if !e.fill => on(
            "wireframe",
            "every edge: no triangles are filled to hide lines",
        ),
        (true, false) => on(
            "wireframe",
            "every edge: hidden-line removal needs depth_test",
        ),
        _ => off("wireframe", "wireframe = false"),
    });
    lines.push(if e.silhouette {
        on("silhouettes", "/ \\ | _ glyphs along silhouette edges")
    } else {
        off("silhouettes", "silhouette = false")
    });
    if !e.fill {
        // No fragments: the stages that run per pixel do nothing. The vertex stage
        // still runs for the edges.
        let per_pixel = [
            "lighting",
            "texture lookups",
            "depth test",
            "fog",
            "depth shading",
        ];
        for l in lines.iter_mut().filter(|l| per_pixel.contains(&l.stage)) {
            if l.on && (l.stage != "lighting" || lighting.per_pixel()) {
                *l = off(l.stage, "fill = false: no triangles are filled");
            }
        }
        let at = lines.iter().position(|l| l.stage == "depth test");
        let line = off(
            "triangles",
            "fill = false: only edges and silhouettes are drawn",
        );
        lines.insert(at.unwrap_or(lines.len()), line);
    }
    ObjectPlan {
        name: o.name.clone(),
        varyings,
        normals,
        unweld: lighting == Lighting::Flat,
        world_positions,
        vertex_colors,
        uvs: varyings.uv,
        texture,
        fill: e.fill,
        depth_test: e.depth_test,
        cull: e.cull,
        fog,
        depth_shading: shading,
        wireframe: e.wireframe,
        hidden_lines,
        silhouette: e.silhouette,
        edges: e.wireframe || e.silhouette,
        lines,
    }
}

impl Plan {
    /// One line for the status bar: the buffers, then per object its varyings and the
    /// stages that run.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut parts = vec![format!(
            "depth {}, {}x",
            if self.depth_buffer { "on" } else { "off" },
            self.samples
        )];
        for (i, o) in self.objects.iter().enumerate() {
            let stages: Vec<&str> = o
                .lines
                .iter()
                .filter(|l| l.on && !matches!(l.stage, "positions" | "varyings"))
                .map(|l| l.stage)
                .collect();
            parts.push(format!(
                "#{} varyings {} · {}",
                i + 1,
                o.varyings,
                if stages.is_empty() {
                    "nothing else".to_string()
                } else {
                    stages.join(", ")
                }
            ));
        }
        parts.join("; ")
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "frame")?;
        for l in &self.lines {
            writeln!(f, "  {l}")?;
        }
        for (i, o) in self.objects.iter().enumerate() {
            writeln!(f, "object {}: {}", i + 1, o.name)?;
            for l in &o.lines {
                writeln!(f, "  {l}")?;
            }
        }
        Ok(())
    }
}
