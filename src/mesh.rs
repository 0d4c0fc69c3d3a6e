//! Triangle meshes: loading OBJ, STL, PLY and glTF files, the built-in models, normalisation
//! and normals.
//!
//! Models are right-handed, y-up. [`Mesh::normalize`] centres a model on its bounding
//! box and scales it so the largest |coordinate| is 1, which is what the standard
//! camera (distance 2.6, 45° field of view) expects.

use std::fmt;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

pub mod gltf;
pub mod material;
mod mtl;
mod obj;
pub mod ply;
pub mod read;
pub mod stl;
mod text;

pub use material::{MeshMaterial, NO_MATERIAL, TextureSource};

pub use read::MAX_MODEL_BYTES;

/// The Utah teapot (Martin Newell, 1975; public domain), embedded so the viewer needs
/// no files.
const TEAPOT_OBJ: &str = include_str!("mesh/teapot.obj");

/// The Stanford bunny (Stanford 3D Scanning Repository; 3674 triangles), embedded for
/// the benchmarks, the accuracy table and the tests.
const BUNNY_OBJ: &str = include_str!("mesh/bunny.obj");

/// Most triangles a built-in sphere may have (`sphere:N`).
pub const MAX_SPHERE_TRIANGLES: usize = 1 << 22;

/// An indexed triangle mesh. Optional attributes are empty when absent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Where the mesh came from, for messages and the status line.
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Per-vertex normals, or empty.
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates, or empty.
    pub uvs: Vec<Vec2>,
    /// Per-vertex linear RGB colours, or empty.
    pub colors: Vec<Vec3>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    /// The materials the file declares, or empty.
    pub materials: Vec<MeshMaterial>,
    /// Per triangle, its index in `materials` (or [`NO_MATERIAL`]); empty when the
    /// file has no materials.
    pub triangle_materials: Vec<u32>,
    /// What the loader went past (a bad material line, a missing texture), each
    /// naming the file and line, for the user to see.
    pub warnings: Vec<String>,
}

/// Why a mesh could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}{}: {problem}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Malformed {
        path: PathBuf,
        line: Option<usize>,
        problem: String,
    },
    #[error("{path}: no triangles{note}")]
    Empty { path: PathBuf, note: String },
    #[error("{path}: not an OBJ file: {why}")]
    NotObj { path: PathBuf, why: String },
    #[error("{path}: {what}, not a regular file")]
    NotRegular { path: PathBuf, what: &'static str },
    #[error(
        "{path}: {size} bytes is more than the {limit} bytes a model file may have (set {} to allow more)",
        read::LIMIT_VAR
    )]
    TooLarge {
        path: PathBuf,
        size: u64,
        limit: u64,
    },
    #[error("{path}: {what} is not supported (convert it to OBJ, STL, PLY or glTF)")]
    Unsupported { path: PathBuf, what: &'static str },
    #[error(
        "unknown built-in model `{0}` (try `teapot`, `bunny`, `sphere:N` with N from 1 to 4194304, or an OBJ, STL, PLY or glTF path)"
    )]
    UnknownBuiltin(String),
}

impl Mesh {
    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The built-in Utah teapot, normalised, without normals.
    #[must_use]
    pub fn teapot() -> Self {
        let mut m =
            obj::parse(TEAPOT_OBJ.as_bytes(), Path::new("teapot")).expect("embedded teapot parses");
        m.name = "teapot".into();
        m.normalize();
        m
    }

    /// The built-in Stanford bunny, normalised, without normals.
    #[must_use]
    pub fn bunny() -> Self {
        let mut m =
            obj::parse(BUNNY_OBJ.as_bytes(), Path::new("bunny")).expect("embedded bunny parses");
        m.name = "bunny".into();
        m.normalize();
        m
    }

    /// A UV sphere of radius 1 with about `triangles` triangles (at least 8), with exact
    /// normals, texture coordinates and vertex colours (the normal mapped to 0..1).
    #[must_use]
    pub fn uv_sphere(triangles: usize) -> Self {
        // stacks × slices quads, 2 triangles each (the pole rows are fans of 1 each).
        let n = ((triangles.max(8) as f64 / 4.0).sqrt().round() as u32).max(2);
        let (stacks, slices) = (n, 2 * n);
        let mut m = Mesh {
            name: format!("sphere:{triangles}"),
            ..Mesh::default()
        };
        for i in 0..=stacks {
            let v = i as f32 / stacks as f32;
            let theta = v * std::f32::consts::PI;
            for j in 0..=slices {
                let u = j as f32 / slices as f32;
                let phi = u * std::f32::consts::TAU;
                let p = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                );
                m.positions.push(p);
                m.normals.push(p);
                m.uvs.push(Vec2::new(u, 1.0 - v));
                m.colors.push(p * 0.5 + 0.5);
            }
        }
        let at = |i: u32, j: u32| i * (slices + 1) + j;
        for i in 0..stacks {
            for j in 0..slices {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if i != 0 {
                    m.indices.extend([a, b, d]);
                }
                if i != stacks - 1 {
                    m.indices.extend([d, b, c]);
                }
            }
        }
        m
    }

    /// A model by name: `teapot`, `bunny`, `sphere:N`, or a path to a model file,
    /// normalised.
    pub fn from_spec(spec: &str) -> Result<Self, MeshError> {
        match spec {
            "teapot" => return Ok(Self::teapot()),
            "bunny" => return Ok(Self::bunny()),
            _ => {}
        }
        if let Some(n) = spec.strip_prefix("sphere:") {
            let n: usize = n
                .parse()
                .ok()
                .filter(|n| (1..=MAX_SPHERE_TRIANGLES).contains(n))
                .ok_or_else(|| MeshError::UnknownBuiltin(spec.into()))?;
            return Ok(Self::uv_sphere(n));
        }
        let mut m = Self::load(Path::new(spec))?;
        m.normalize();
        Ok(m)
    }

    /// Loads a model file, unnormalised: OBJ (triangulated, single index), STL, PLY or
    /// glTF (`.gltf`, `.glb`), told apart by content first and then by extension (see
    /// [`Format::detect`]).
    /// Only a regular file of at most [`MAX_MODEL_BYTES`] is read. A file that is not
    /// text, or does not parse as OBJ and starts like another format (see
    /// [`NOT_OBJ`]), is refused saying what it looks like.
    pub fn load(path: &Path) -> Result<Self, MeshError> {
        let bytes = read::read_regular(path, read::model_limit())?;
        match Format::detect(&bytes, path) {
            Format::Stl => return stl::parse(&bytes, path),
            Format::Ply => return ply::parse(&bytes, path),
            Format::Gltf => return gltf::parse(&bytes, path),
            Format::Obj => {}
        }
        obj::parse(&bytes, path).map_err(|e| match (&e, sniff(&bytes)) {
            (
                MeshError::Malformed { .. } | MeshError::Empty { .. } | MeshError::NotObj { .. },
                Some(what),
            ) => MeshError::NotObj {
                path: path.into(),
                why: format!("it looks like {what}"),
            },
            _ => e,
        })
    }

    /// Centres the mesh on its bounding box and scales it so max |coordinate| = 1,
    /// in f64 so that neither the centre of a huge model nor the scale of a tiny one
    /// overflows.
    pub fn normalize(&mut self) {
        let (lo, hi) = self.positions.iter().fold(
            (
                glam::DVec3::splat(f64::INFINITY),
                glam::DVec3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())),
        );
        let centre = (lo + hi) * 0.5;
        let extent = (hi - centre).max_element();
        let scale = if extent > 0.0 && extent.is_finite() {
            1.0 / extent
        } else {
            1.0
        };
        for p in &mut self.positions {
            *p = ((p.as_dvec3() - centre) * scale).as_vec3();
        }
    }

    /// The radius of the smallest sphere about the origin that holds every vertex
    /// (unchanged by any rotation about the origin, so a spinning model stays inside it).
    #[must_use]
    pub fn bounding_radius(&self) -> f32 {
        self.positions
            .iter()
            .map(|p| p.length())
            .filter(|l| l.is_finite())
            .fold(0.0, f32::max)
    }

    /// Generates smooth per-vertex normals (area-weighted face normals) if there are
    /// none. Degenerate neighbourhoods fall back to +z rather than NaN.
    pub fn ensure_normals(&mut self) {
        if self.normals.len() == self.positions.len() {
            return;
        }
        crate::counters::add(
            crate::counters::Stage::NormalsGenerated,
            self.positions.len() as u64,
        );
        let mut n = vec![Vec3::ZERO; self.positions.len()];
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
            // The cross product's length is twice the area: larger faces weigh more.
            let face = (b - a).cross(c - a);
            for &i in t {
                n[i as usize] += face;
            }
        }
        self.normals = n
            .into_iter()
            .map(|v| v.try_normalize().unwrap_or(Vec3::Z))
            .collect();
    }
}

impl fmt::Display for Mesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({} vertices, {} triangles)",
            self.name,
            self.positions.len(),
            self.triangle_count()
        )
    }
}

/// How common files that are not OBJ text start: (offset, bytes, what the file is).
/// Consulted only for a file that is not UTF-8 or does not parse as OBJ, so no OBJ
/// that loads is refused (not even one whose first line is `solid` or `ply`).
pub const NOT_OBJ: &[(usize, &[u8], &str)] = &[
    (0, b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (0, b"\xff\xd8\xff", "a JPEG image"),
    (0, b"GIF8", "a GIF image"),
    (8, b"WEBP", "a WebP image"),
    (0, b"II*\0", "a TIFF image"),
    (0, b"MM\0*", "a TIFF image"),
    (0, b"%PDF-", "a PDF document"),
    (0, b"PK\x03\x04", "a ZIP archive"),
    (0, b"\x1f\x8b", "a gzip file"),
    (0, b"\xfd7zXZ\0", "an xz file"),
    (0, b"\x28\xb5\x2f\xfd", "a zstd file"),
    (0, b"\x7fELF", "an ELF executable"),
    (0, b"glTF", "a binary glTF model"),
    (0, b"ply", "a PLY model"),
    (0, b"solid", "an STL model"),
];

/// The model formats [`Mesh::load`] tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Stl,
    Ply,
    /// `.gltf` (JSON) or `.glb` (binary).
    Gltf,
}

impl Format {
    /// The format of a file: by content first (the `ply` magic line, `solid` then
    /// `facet` for ASCII STL, 84 + 50·n bytes for binary STL, the `glTF` magic of
    /// GLB, a JSON object with an `"asset"` key for `.gltf`), then by extension
    /// (`.stl`, `.ply`, `.gltf`, `.glb`), else OBJ.
    #[must_use]
    pub fn detect(bytes: &[u8], path: &Path) -> Self {
        if ply::is_ply(bytes) {
            return Self::Ply;
        }
        if gltf::is_glb(bytes) || gltf::is_gltf_json(bytes) {
            return Self::Gltf;
        }
        if stl::is_ascii_stl(bytes) || stl::is_binary_stl(bytes) {
            return Self::Stl;
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Self::Stl,
            Some("ply") => Self::Ply,
            Some("gltf" | "glb") => Self::Gltf,
            _ => Self::Obj,
        }
    }
}

/// What a file that starts with `bytes` looks like, by [`NOT_OBJ`].
#[must_use]
pub fn sniff(bytes: &[u8]) -> Option<&'static str> {
    NOT_OBJ
        .iter()
        .find(|(at, magic, _)| bytes.get(*at..).is_some_and(|b| b.starts_with(magic)))
        .map(|(_, _, what)| *what)
}

/// A power of two that brings the largest |coordinate| of `positions` near 1 if it
/// is beyond what f32 holds comfortably (above 1e30 or below 1e-30, zero aside),
/// else 1: exact, so the model's shape is kept to the last bit.
fn power_of_two_scale(positions: &[[f64; 3]]) -> f64 {
    let max = positions
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    if max == 0.0 || !max.is_finite() || (1e-30..=1e30).contains(&max) {
        return 1.0;
    }
    2f64.powi(-(max.log2().round() as i32))
}
