//! PLY models, ASCII and binary of either byte order, read with `ply-rs-bw`:
//! positions, faces of any size (fan-triangulated), vertex normals (`nx ny nz`),
//! texture coordinates (`s t`, `u v` or `texture_u texture_v`) and vertex colours
//! (`red green blue`, 8-bit sRGB or float; alpha is ignored).

use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use super::{Mesh, MeshError};

/// Whether `bytes` start with the PLY magic line.
#[must_use]
pub fn is_ply(bytes: &[u8]) -> bool {
    bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")
}

/// A vertex as read: position (NaN where a coordinate is missing), normal, colour
/// (sRGB-encoded fractions) and texture coordinates. Typed elements instead of the
/// crate's map per element keep a million-vertex file to tens of megabytes.
#[derive(Clone, Copy)]
struct Vertex {
    p: [f32; 3],
    n: [f32; 3],
    c: [f32; 3],
    uv: [f32; 2],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self {
            p: [f32::NAN; 3],
            n: [0.0; 3],
            c: [0.0; 3],
            uv: [0.0; 2],
        }
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        let slot = match name {
            "x" => &mut self.p[0],
            "y" => &mut self.p[1],
            "z" => &mut self.p[2],
            "nx" => &mut self.n[0],
            "ny" => &mut self.n[1],
            "nz" => &mut self.n[2],
            "s" | "u" | "texture_u" => &mut self.uv[0],
            "t" | "v" | "texture_v" => &mut self.uv[1],
            "red" | "green" | "blue" => {
                let i = match name {
                    "red" => 0,
                    "green" => 1,
                    _ => 2,
                };
                self.c[i] = encoded_colour(&p).unwrap_or(0.0);
                return PropertyAccessResult::Set;
            }
            _ => return PropertyAccessResult::Ignored,
        };
        *slot = p.to_f32_lossy().unwrap_or(f32::NAN);
        PropertyAccessResult::Set
    }
}

/// A face's vertex indices: up to four inline, more in `spill`.
struct Face {
    len: usize,
    inline: [i64; 4],
    spill: Vec<i64>,
}

impl Face {
    fn get(&self, i: usize) -> i64 {
        if self.len <= 4 {
            self.inline[i]
        } else {
            self.spill[i]
        }
    }
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Self {
            len: usize::MAX,
            inline: [0; 4],
            spill: Vec::new(),
        }
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        if name != "vertex_indices" && name != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        let Some(list) = indices(&p) else {
            return PropertyAccessResult::UnsupportedType;
        };
        self.len = list.len();
        if list.len() <= 4 {
            self.inline[..list.len()].copy_from_slice(&list);
        } else {
            self.spill = list;
        }
        PropertyAccessResult::Set
    }
}

/// Any other element, read past.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Self
    }
}

/// Parses a PLY file's bytes.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    std::panic::catch_unwind(|| parse_unguarded(bytes, path)).unwrap_or_else(|_| {
        Err(MeshError::Malformed {
            path: path.into(),
            line: None,
            problem: "the PLY reader failed on this file".into(),
        })
    })
}

fn parse_unguarded(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let malformed = |line, problem: String| MeshError::Malformed {
        path: path.into(),
        line,
        problem,
    };
    let head = &bytes[..bytes.len().min(4096)];
    let ascii = head.windows(12).any(|w| w == b"format ascii");
    let header_end = header_lines(bytes);
    let ply_error = |e: ply_rs_bw::parser::ParseError| {
        let text = e.to_string();
        match e.line() {
            Some(l) => {
                let problem = text
                    .strip_prefix(&format!("Line {l}: "))
                    .unwrap_or(&text)
                    .to_string();
                // Binary payload errors carry no useful line.
                let header_only = !ascii && l > header_end.unwrap_or(usize::MAX);
                malformed((!header_only).then_some(l), problem)
            }
            None => malformed(None, text),
        }
    };
    let mut reader = Reader::new(bytes);
    let vertex_parser = Parser::<Vertex>::new();
    let face_parser = Parser::<Face>::new();
    let skip_parser = Parser::<Skip>::new();
    let header = vertex_parser.read_header(&mut reader).map_err(ply_error)?;
    let def = header
        .elements
        .get("vertex")
        .ok_or_else(|| malformed(None, "no `element vertex` in the header".into()))?;
    let has = |names: &[&str]| names.iter().all(|n| def.properties.contains_key(*n));
    let (mut verts, mut faces) = (Vec::new(), Vec::new());
    // Elements are read in header order; where the faces start, for ASCII lines.
    let mut lines_before_faces = 0;
    let mut seen_faces = false;
    for (name, element) in &header.elements {
        match name.as_str() {
            "vertex" => {
                verts = vertex_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(ply_error)?;
            }
            "face" => {
                seen_faces = true;
                faces = face_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(ply_error)?;
            }
            _ => {
                skip_parser
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(ply_error)?;
            }
        }
        if !seen_faces {
            lines_before_faces += element.count;
        }
    }
    let mut m = Mesh::default();
    m.positions.reserve_exact(verts.len());
    for (i, v) in verts.iter().enumerate() {
        let p = Vec3::from_array(v.p);
        if !p.is_finite() {
            return Err(malformed(
                None,
                format!("vertex {i}: position x y z missing or not a finite number"),
            ));
        }
        m.positions.push(p);
    }
    if has(&["nx", "ny", "nz"]) {
        m.normals = verts.iter().map(|v| Vec3::from_array(v.n)).collect();
        if m.normals.iter().any(|n| !n.is_finite()) {
            m.normals.clear();
        }
    }
    if has(&["red", "green", "blue"]) {
        m.colors = verts
            .iter()
            .map(|v| Vec3::from_array(v.c.map(to_linear)))
            .collect();
    }
    if [["s", "t"], ["u", "v"], ["texture_u", "texture_v"]]
        .iter()
        .any(|uv| has(uv))
    {
        m.uvs = verts
            .iter()
            .map(|v| Vec2::from_array(v.uv.map(|c| if c.is_finite() { c } else { 0.0 })))
            .collect();
    }
    drop(verts);
    let n = m.positions.len();
    // Where face k's line is in an ASCII file: after the header and the elements before.
    let face_line = |k: usize| -> Option<usize> {
        ascii.then_some(())?;
        Some(header_end? + lines_before_faces + k + 1)
    };
    m.indices.reserve(faces.len() * 3);
    for (k, f) in faces.iter().enumerate() {
        if f.len == usize::MAX {
            return Err(malformed(
                face_line(k),
                format!("face {k} has no integer list `vertex_indices`"),
            ));
        }
        if let Some(bad) = (0..f.len)
            .map(|i| f.get(i))
            .find(|&i| i < 0 || i >= n as i64)
        {
            return Err(malformed(
                face_line(k),
                format!("face {k} refers to vertex {bad}, but there are {n} vertices"),
            ));
        }
        for j in 1..f.len.saturating_sub(1) {
            m.indices
                .extend([f.get(0), f.get(j), f.get(j + 1)].map(|i| i as u32));
        }
    }
    if m.indices.is_empty() {
        return Err(MeshError::Empty {
            path: path.into(),
            note: String::new(),
        });
    }
    m.name = path.display().to_string();
    Ok(m)
}

/// Number of lines up to and including `end_header`.
fn header_lines(bytes: &[u8]) -> Option<usize> {
    let at = bytes.windows(10).position(|w| w == b"end_header")?;
    Some(bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1)
}

/// A colour channel as an sRGB-encoded fraction: 8-bit and 16-bit integers of their
/// maximum, floats as they are, clamped to 0..1.
fn encoded_colour(p: &Property) -> Option<f32> {
    let encoded = match *p {
        Property::UChar(v) => f32::from(v) / 255.0,
        Property::Char(v) => f32::from(v.max(0)) / 127.0,
        Property::UShort(v) => f32::from(v) / 65535.0,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => p.to_f32_lossy()? / 255.0,
    };
    Some(if encoded.is_finite() {
        encoded.clamp(0.0, 1.0)
    } else {
        0.0
    })
}

/// An sRGB-encoded fraction as linear light.
fn to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// An integer list property as i64 indices.
fn indices(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUChar(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUShort(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        Property::ListUInt(v) => v.iter().map(|&i| i64::from(i)).collect(),
        _ => return None,
    })
}
