//! What a model file says about its surfaces (materials per triangle), what went
//! wrong without stopping the load (warnings), and splitting a mesh by material so
//! each part can be drawn with its own colour and texture.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;

use super::Mesh;

/// Triangles with no material (`f` before any `usemtl`, or a glTF primitive without
/// one) carry this index.
pub const NO_MATERIAL: u32 = u32::MAX;

/// A surface as the file describes it: a diffuse colour and texture.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshMaterial {
    pub name: String,
    /// Linear RGB (`Kd`, or glTF's base colour factor).
    pub diffuse: Vec3,
    pub texture: Option<TextureSource>,
}

impl MeshMaterial {
    /// A white material without texture, for names that no library defines.
    #[must_use]
    pub fn plain(name: &str) -> Self {
        Self {
            name: name.into(),
            diffuse: Vec3::ONE,
            texture: None,
        }
    }
}

/// Where a texture image comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// A file found on disk (OBJ's `map_Kd`, a glTF image's URI).
    File(PathBuf),
    /// Encoded image bytes inside the model (GLB buffers, data URIs); `name` says
    /// where, for messages.
    Embedded { name: String, bytes: Arc<[u8]> },
}

impl TextureSource {
    /// The file or the place in the model, for messages.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::File(p) => p.display().to_string(),
            Self::Embedded { name, .. } => name.clone(),
        }
    }
}

/// Problems a loader noticed and went past. Each kind is reported once, at the first
/// place it happened, with a count of the others, so a file with a million bad
/// indices gets one line.
#[derive(Debug, Default)]
pub struct Warnings {
    seen: Vec<Seen>,
}

#[derive(Debug)]
struct Seen {
    kind: &'static str,
    first: String,
    more: usize,
}

impl Warnings {
    /// Records a problem of `kind`; `message` is only built the first time.
    pub fn add(&mut self, kind: &'static str, message: impl FnOnce() -> String) {
        match self.seen.iter_mut().find(|s| s.kind == kind) {
            Some(s) => s.more += 1,
            None => self.seen.push(Seen {
                kind,
                first: message(),
                more: 0,
            }),
        }
    }

    /// One line per kind, in the order first seen.
    #[must_use]
    pub fn into_lines(self) -> Vec<String> {
        self.seen
            .into_iter()
            .map(|s| match s.more {
                0 => s.first,
                1 => format!("{} (and once more)", s.first),
                n => format!("{} (and {n} more times)", s.first),
            })
            .collect()
    }
}

impl Mesh {
    /// The material of each part, and the part: triangles grouped by material in the
    /// order the materials are first used, vertices renumbered so each part holds only
    /// its own. A mesh without materials is one part with `None`.
    #[must_use]
    pub fn split_by_material(mut self) -> Vec<(Option<MeshMaterial>, Mesh)> {
        let n = self.triangle_count();
        if self.triangle_materials.len() != n {
            self.triangle_materials.clear();
        }
        let first = self.triangle_materials.first().copied();
        if self.triangle_materials.iter().all(|&m| Some(m) == first) {
            let material = first.and_then(|m| self.materials.get(m as usize).cloned());
            self.materials.clear();
            self.triangle_materials.clear();
            return vec![(material, self)];
        }
        let mut order: Vec<u32> = Vec::new();
        for &m in &self.triangle_materials {
            if !order.contains(&m) {
                order.push(m);
            }
        }
        let mut remap = vec![u32::MAX; self.positions.len()];
        order
            .into_iter()
            .map(|mat| {
                let mut part = Mesh {
                    name: self.name.clone(),
                    ..Mesh::default()
                };
                let mut used = Vec::new();
                for (t, _) in self
                    .triangle_materials
                    .iter()
                    .enumerate()
                    .filter(|&(_, &m)| m == mat)
                {
                    for &i in &self.indices[3 * t..3 * t + 3] {
                        let slot = &mut remap[i as usize];
                        if *slot == u32::MAX {
                            *slot = used.len() as u32;
                            used.push(i);
                        }
                        part.indices.push(*slot);
                    }
                }
                let pick = |v: &[Vec3]| -> Vec<Vec3> {
                    if v.is_empty() {
                        Vec::new()
                    } else {
                        used.iter().map(|&i| v[i as usize]).collect()
                    }
                };
                part.positions = pick(&self.positions);
                part.normals = pick(&self.normals);
                part.colors = pick(&self.colors);
                if !self.uvs.is_empty() {
                    part.uvs = used.iter().map(|&i| self.uvs[i as usize]).collect();
                }
                for &i in &used {
                    remap[i as usize] = u32::MAX;
                }
                (self.materials.get(mat as usize).cloned(), part)
            })
            .collect()
    }

    /// The first material's texture, if any material has one.
    #[must_use]
    pub fn first_texture(&self) -> Option<&TextureSource> {
        self.materials.iter().find_map(|m| m.texture.as_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    fn two_materials() -> Mesh {
        // A quad of two triangles sharing an edge, each with its own material.
        Mesh {
            name: "q".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::Y],
            uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
            indices: vec![0, 1, 2, 0, 2, 3],
            materials: vec![MeshMaterial::plain("a"), MeshMaterial::plain("b")],
            triangle_materials: vec![1, 0],
            ..Mesh::default()
        }
    }

    #[test]
    fn split_keeps_each_triangle_with_its_material() {
        let parts = two_materials().split_by_material();
        let names: Vec<_> = parts
            .iter()
            .map(|(m, _)| m.as_ref().unwrap().name.as_str())
            .collect();
        assert_eq!(names, ["b", "a"]);
        let (_, b) = &parts[0];
        assert_eq!(b.positions, [Vec3::ZERO, Vec3::X, Vec3::ONE]);
        assert_eq!(b.indices, [0, 1, 2]);
        let (_, a) = &parts[1];
        assert_eq!(a.positions, [Vec3::ZERO, Vec3::ONE, Vec3::Y]);
        assert_eq!(a.uvs, [Vec2::ZERO, Vec2::ONE, Vec2::Y]);
        assert!(a.triangle_materials.is_empty() && a.materials.is_empty());
    }

    #[test]
    fn one_material_is_one_part_unchanged() {
        let mut m = two_materials();
        m.triangle_materials = vec![0, 0];
        let parts = m.clone().split_by_material();
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].0.as_ref().unwrap().name, "a");
        assert_eq!(parts[0].1.indices, m.indices);
    }

    #[test]
    fn warnings_are_counted_per_kind() {
        let mut w = Warnings::default();
        for i in 0..3 {
            w.add("index", || format!("line {i}"));
        }
        w.add("other", || "x".into());
        assert_eq!(w.into_lines(), ["line 0 (and 2 more times)", "x"]);
    }
}
