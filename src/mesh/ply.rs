//! PLY models, ASCII and binary of either byte order, read with `ply-rs-bw`:
//! positions, faces of any size (fan-triangulated), vertex normals (`nx ny nz`),
//! texture coordinates (`s t`, `u v` or `texture_u texture_v`) and vertex colours
//! (`red green blue`, 8-bit sRGB or float; alpha is ignored).

use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{Mesh, MeshError};

/// Whether `bytes` start with the PLY magic line.
#[must_use]
pub fn is_ply(bytes: &[u8]) -> bool {
    bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")
}

/// Parses a PLY file's bytes.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let malformed = |line, problem: String| MeshError::Malformed {
        path: path.into(),
        line,
        problem,
    };
    let head = &bytes[..bytes.len().min(4096)];
    let ascii = head.windows(12).any(|w| w == b"format ascii");
    let parser = Parser::<DefaultElement>::new();
    let parsed = std::panic::catch_unwind(|| parser.read_ply(&mut &bytes[..]))
        .map_err(|_| malformed(None, "the PLY reader failed on this file".into()))?;
    let ply = parsed.map_err(|e| {
        let text = e.to_string();
        match e.line() {
            Some(l) => {
                let problem = text
                    .strip_prefix(&format!("Line {l}: "))
                    .unwrap_or(&text)
                    .to_string();
                // Binary payload errors carry no useful line.
                let header_only = !ascii && l > header_lines(bytes).unwrap_or(usize::MAX);
                malformed((!header_only).then_some(l), problem)
            }
            None => malformed(None, text),
        }
    })?;
    let def = ply
        .header
        .elements
        .get("vertex")
        .ok_or_else(|| malformed(None, "no `element vertex` in the header".into()))?;
    let has = |names: &[&str]| names.iter().all(|n| def.properties.contains_key(*n));
    let empty = Vec::new();
    let verts = ply.payload.get("vertex").unwrap_or(&empty);
    let scalar = |e: &DefaultElement, k: &str| e.get(k).and_then(Property::to_f32_lossy);
    let mut m = Mesh::default();
    for (i, v) in verts.iter().enumerate() {
        let p = Vec3::new(
            scalar(v, "x").unwrap_or(f32::NAN),
            scalar(v, "y").unwrap_or(f32::NAN),
            scalar(v, "z").unwrap_or(f32::NAN),
        );
        if !p.is_finite() {
            return Err(malformed(
                None,
                format!("vertex {i}: position x y z missing or not a finite number"),
            ));
        }
        m.positions.push(p);
    }
    let vec3 = |names: [&str; 3], f: &dyn Fn(&Property) -> Option<f32>| -> Vec<Vec3> {
        verts
            .iter()
            .map(|v| {
                let c = names.map(|n| v.get(n).and_then(f).unwrap_or(0.0));
                Vec3::from_array(c)
            })
            .collect()
    };
    if has(&["nx", "ny", "nz"]) {
        m.normals = vec3(["nx", "ny", "nz"], &Property::to_f32_lossy);
        if m.normals.iter().any(|n| !n.is_finite()) {
            m.normals.clear();
        }
    }
    if has(&["red", "green", "blue"]) {
        m.colors = vec3(["red", "green", "blue"], &colour);
    }
    for [u, v] in [["s", "t"], ["u", "v"], ["texture_u", "texture_v"]] {
        if has(&[u, v]) {
            m.uvs = verts
                .iter()
                .map(|e| Vec2::new(scalar(e, u).unwrap_or(0.0), scalar(e, v).unwrap_or(0.0)))
                .collect();
            break;
        }
    }
    let n = m.positions.len();
    // Where face k's line is in an ASCII file: after the header and the elements before.
    let face_line = |k: usize| -> Option<usize> {
        if !ascii {
            return None;
        }
        let before: usize = ply
            .header
            .elements
            .values()
            .take_while(|e| e.name != "face")
            .map(|e| e.count)
            .sum();
        Some(header_lines(bytes)? + before + k + 1)
    };
    let faces = ply.payload.get("face").unwrap_or(&empty);
    for (k, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(indices)
            .ok_or_else(|| {
                malformed(
                    face_line(k),
                    format!("face {k} has no integer list `vertex_indices`"),
                )
            })?;
        if let Some(&bad) = list.iter().find(|&&i| i < 0 || i >= n as i64) {
            return Err(malformed(
                face_line(k),
                format!("face {k} refers to vertex {bad}, but there are {n} vertices"),
            ));
        }
        for j in 1..list.len().saturating_sub(1) {
            m.indices
                .extend([list[0], list[j], list[j + 1]].map(|i| i as u32));
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

/// A colour channel as linear light: 8-bit and 16-bit integers are sRGB-encoded
/// fractions of their maximum, floats are taken as sRGB-encoded 0..1.
fn colour(p: &Property) -> Option<f32> {
    let encoded = match *p {
        Property::UChar(v) => f32::from(v) / 255.0,
        Property::Char(v) => f32::from(v.max(0)) / 127.0,
        Property::UShort(v) => f32::from(v) / 65535.0,
        Property::Float(v) => v,
        Property::Double(v) => v as f32,
        _ => p.to_f32_lossy()? / 255.0,
    };
    let c = if encoded.is_finite() {
        encoded.clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some(if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    })
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
