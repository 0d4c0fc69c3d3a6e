//! OBJ models, parsed here: from bytes (names decoded lossily), with the line
//! structure of [`super::text`], `v` (with optional `r g b`), `vt`, `vn`, polygons of
//! any size (fan-triangulated) with absolute or relative indices, `usemtl` per face
//! and `mtllib` libraries read once each. Everything else is skipped; `l` and `p`
//! elements are counted and reported, never drawn as faces. Coordinates are read as
//! f64 so that finite but huge or tiny models survive until they are normalised.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::material::{MeshMaterial, NO_MATERIAL, Warnings};
use super::text::{self, number, words};
use super::{Mesh, MeshError, mtl, read};

/// No index (a face corner without `vt` or `vn`).
const NONE: u32 = u32::MAX;

/// An attribute list a face refers to.
#[derive(Clone, Copy, PartialEq)]
enum List {
    Position,
    Uv,
    Normal,
}

/// Everything read so far.
#[derive(Default)]
struct Obj {
    positions: Vec<[f64; 3]>,
    colors: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Vec<Vec3>,
    /// The (position, uv, normal) of each output vertex.
    keys: Vec<[u32; 3]>,
    /// Per position, its first output vertex; per output vertex, the next with the
    /// same position (a chain instead of a hash map: most positions have one).
    first: Vec<u32>,
    next: Vec<u32>,
    indices: Vec<u32>,
    triangle_materials: Vec<u32>,
    material: u32,
    material_names: Vec<String>,
    /// References past the end of a list at the time they were read: checked at the
    /// end, since some exporters write vertices after the faces that use them.
    forward: Vec<(usize, List, u32)>,
    libraries: Vec<PathBuf>,
    materials: Vec<MeshMaterial>,
    polylines: (usize, usize),
    points: (usize, usize),
    /// The file, for warnings.
    file: String,
    /// More vertices than this cannot be in a file of its size: an index beyond is
    /// refused before anything is sized by it.
    max_vertices: u64,
}

/// Parses OBJ bytes; `path` names the file and anchors `mtllib`.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let malformed = |line: usize, problem: String| MeshError::Malformed {
        path: path.into(),
        line: Some(line),
        problem,
    };
    let at = |line: usize| format!("{}:{line}", path.display());
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut o = Obj {
        material: NO_MATERIAL,
        file: path.display().to_string(),
        max_vertices: bytes.len() as u64 / 6 + 1,
        ..Obj::default()
    };
    let mut w = Warnings::default();
    let mut corners: Vec<u32> = Vec::new();
    for (line, l) in text::lines(bytes) {
        let mut ws = words(&l);
        let Some(key) = ws.next() else { continue };
        match key {
            b"v" => {
                let mut xs = [0.0f64; 7];
                let mut n = 0;
                for word in ws {
                    let x = number(word)
                        .ok_or_else(|| malformed(line, "bad vertex position (`v x y z`)".into()))?;
                    if n < xs.len() {
                        xs[n] = x;
                    }
                    n += 1;
                }
                if n < 3 {
                    return Err(malformed(line, "bad vertex position (`v x y z`)".into()));
                }
                if !xs[..3].iter().all(|x| x.is_finite()) {
                    return Err(malformed(
                        line,
                        "vertex position is not a finite number".into(),
                    ));
                }
                o.positions.push([xs[0], xs[1], xs[2]]);
                // `v x y z r g b` (a seventh number is an alpha some tools write).
                if n == 6 || n == 7 {
                    let c = Vec3::new(xs[3] as f32, xs[4] as f32, xs[5] as f32);
                    o.colors.resize(o.positions.len() - 1, Vec3::ONE);
                    o.colors.push(if c.is_finite() { c } else { Vec3::ONE });
                }
            }
            b"vt" => {
                let xs: Vec<Option<f64>> = ws.take(3).map(number).collect();
                let u = xs.first().copied().flatten();
                let v = xs.get(1).copied().flatten().or(u.map(|_| 0.0));
                match (u, v) {
                    (Some(u), Some(v)) if xs.iter().all(Option::is_some) => {
                        o.uvs.push(Vec2::new(u as f32, v as f32));
                    }
                    _ => {
                        return Err(malformed(line, "bad texture coordinate (`vt u v`)".into()));
                    }
                }
            }
            b"vn" => {
                let xs: Vec<Option<f64>> = ws.map(number).collect();
                match xs[..] {
                    [Some(x), Some(y), Some(z)] => {
                        o.normals.push(Vec3::new(x as f32, y as f32, z as f32));
                    }
                    _ => return Err(malformed(line, "bad normal (`vn x y z`)".into())),
                }
            }
            b"f" => {
                corners.clear();
                for word in ws {
                    let i = o
                        .corner(word, line, &mut w)
                        .map_err(|p| malformed(line, p))?;
                    corners.push(i);
                }
                if corners.len() < 3 {
                    w.add("short-face", || {
                        format!(
                            "{}: a face needs 3 vertices; faces with fewer are skipped",
                            at(line)
                        )
                    });
                    continue;
                }
                for k in 1..corners.len() - 1 {
                    o.indices.extend([corners[0], corners[k], corners[k + 1]]);
                    o.triangle_materials.push(o.material);
                }
            }
            b"l" => note(&mut o.polylines, line),
            b"p" => note(&mut o.points, line),
            b"usemtl" => {
                let name = text::rest_after_keyword(&l);
                o.material = match o.material_names.iter().position(|n| *n == name) {
                    Some(i) => i as u32,
                    None => {
                        o.material_names.push(name);
                        (o.material_names.len() - 1) as u32
                    }
                };
            }
            b"mtllib" => o.library(&l, dir, &at(line), &mut w),
            _ => {}
        }
    }
    o.finish(bytes, path, w)
}

/// Counts an element that is not drawn, keeping the first line.
fn note(count: &mut (usize, usize), line: usize) {
    if count.0 == 0 {
        count.1 = line;
    }
    count.0 += 1;
}

impl Obj {
    /// The output vertex of one face corner (`v`, `v/vt`, `v//vn`, `v/vt/vn`).
    fn corner(&mut self, word: &[u8], line: usize, w: &mut Warnings) -> Result<u32, String> {
        let mut parts = word.split(|&b| b == b'/');
        let v = parts.next().unwrap_or_default();
        let v = self
            .resolve(v, List::Position, line)?
            .ok_or_else(|| "bad face (`f i j k ...`)".to_string())?;
        let vt = self.attribute(List::Uv, parts.next(), line, w);
        let vn = self.attribute(List::Normal, parts.next(), line, w);
        let key = [v, vt, vn];
        let slot = v as usize;
        if slot >= self.first.len() {
            self.first.resize(slot + 1, NONE);
        }
        let mut at = self.first[slot];
        while at != NONE {
            if self.keys[at as usize] == key {
                return Ok(at);
            }
            at = self.next[at as usize];
        }
        let new = self.keys.len() as u32;
        self.keys.push(key);
        self.next.push(self.first[slot]);
        self.first[slot] = new;
        Ok(new)
    }

    /// A corner's `vt` or `vn` index, or [`NONE`] (with a warning if it is bad).
    fn attribute(&mut self, list: List, part: Option<&[u8]>, line: usize, w: &mut Warnings) -> u32 {
        match part {
            None | Some(b"") => NONE,
            Some(p) => match self.resolve(p, list, line) {
                Ok(Some(i)) => i,
                _ => {
                    self.bad_attribute(w, list, line);
                    NONE
                }
            },
        }
    }

    fn bad_attribute(&self, w: &mut Warnings, list: List, line: usize) {
        let (kind, what) = match list {
            List::Uv => ("bad-vt", "texture coordinate"),
            _ => ("bad-vn", "normal"),
        };
        w.add(kind, || {
            format!(
                "{}:{line}: a face's {what} index refers to nothing; ignored",
                self.file
            )
        });
    }

    /// A 1-based or negative (relative) index into `list`; `None` if it is not a
    /// number. Positions must exist by the end of the file; uvs and normals that
    /// do not are warnings.
    fn resolve(&mut self, word: &[u8], list: List, line: usize) -> Result<Option<u32>, String> {
        let Some(i) = std::str::from_utf8(word)
            .ok()
            .and_then(|s| s.parse::<i64>().ok())
        else {
            return Ok(None);
        };
        let len = match list {
            List::Position => self.positions.len(),
            List::Uv => self.uvs.len(),
            List::Normal => self.normals.len(),
        } as i64;
        let index = match i {
            0 => return Err("face index 0 (OBJ indices start at 1)".into()),
            i if i > 0 => i - 1,
            i => len + i,
        };
        if !(0..self.max_vertices as i64).contains(&index) {
            return if list == List::Position {
                Err(format!(
                    "face refers to a vertex that does not exist (there are {len})"
                ))
            } else {
                Ok(None)
            };
        }
        if index >= len {
            self.forward.push((line, list, index as u32));
        }
        Ok(Some(index as u32))
    }

    /// Reads each library a `mtllib` line names, once.
    fn library(&mut self, line: &[u8], dir: &Path, at: &str, w: &mut Warnings) {
        let whole = text::rest_after_keyword(line);
        let names: Vec<String> = if whole.contains(' ') && dir.join(&whole).is_file() {
            vec![whole]
        } else {
            words(line)
                .skip(1)
                .map(|n| String::from_utf8_lossy(n).into_owned())
                .collect()
        };
        for name in names {
            let Some(file) = mtl::find_file(dir, &name, at, w) else {
                continue;
            };
            if self.libraries.contains(&file) {
                continue;
            }
            self.libraries.push(file.clone());
            match read::read_regular(&file, read::model_limit()) {
                Ok(bytes) => {
                    let mats = mtl::parse(&bytes, &file, w);
                    self.materials.extend(mats);
                }
                Err(e) => w.add("mtl-read", || format!("{at}: material library: {e}")),
            }
        }
    }

    /// Checks what was left for the end and builds the mesh.
    fn finish(mut self, bytes: &[u8], path: &Path, mut w: Warnings) -> Result<Mesh, MeshError> {
        for &(line, list, index) in &self.forward {
            match list {
                List::Position if index as usize >= self.positions.len() => {
                    return Err(MeshError::Malformed {
                        path: path.into(),
                        line: Some(line),
                        problem: format!(
                            "face refers to a vertex that does not exist (there are {})",
                            self.positions.len()
                        ),
                    });
                }
                List::Uv if index as usize >= self.uvs.len() => {
                    self.bad_attribute(&mut w, list, line)
                }
                List::Normal if index as usize >= self.normals.len() => {
                    self.bad_attribute(&mut w, list, line);
                }
                _ => {}
            }
        }
        let at = |line: usize| format!("{}:{line}", path.display());
        for (kind, count, what) in [
            ("not-drawn-l", self.polylines, "polyline (`l`)"),
            ("not-drawn-p", self.points, "point (`p`)"),
        ] {
            if count.0 > 0 {
                w.add(kind, || {
                    format!(
                        "{}: {} {what} element{} not drawn: only faces are",
                        at(count.1),
                        count.0,
                        if count.0 == 1 { "" } else { "s" }
                    )
                });
            }
        }
        if self.indices.is_empty() {
            if let Err(e) = std::str::from_utf8(bytes) {
                return Err(MeshError::NotObj {
                    path: path.into(),
                    why: format!("it is not text (byte {} is not UTF-8)", e.valid_up_to()),
                });
            }
            let note = if self.polylines.0 + self.points.0 > 0 {
                " (only lines or points, which are not drawn)"
            } else {
                ""
            };
            return Err(MeshError::Empty {
                path: path.into(),
                note: note.into(),
            });
        }
        let mut m = Mesh {
            name: path.display().to_string(),
            ..Mesh::default()
        };
        let scale = super::power_of_two_scale(&self.positions);
        m.positions = self
            .keys
            .iter()
            .map(|k| {
                let p = self.positions[k[0] as usize];
                Vec3::new(
                    (p[0] * scale) as f32,
                    (p[1] * scale) as f32,
                    (p[2] * scale) as f32,
                )
            })
            .collect();
        let get = |list: &[Vec3], i: u32| list.get(i as usize).copied();
        let uv = |i: u32| self.uvs.get(i as usize).copied();
        if self.keys.iter().all(|k| get(&self.normals, k[2]).is_some()) {
            m.normals = self
                .keys
                .iter()
                .map(|k| self.normals[k[2] as usize])
                .collect();
        } else if self.keys.iter().any(|k| get(&self.normals, k[2]).is_some()) {
            w.add("some-normals", || {
                format!(
                    "{}: only some face corners have normals; all are generated instead",
                    path.display()
                )
            });
        }
        // Untextured corners beside textured ones (an untextured material) get (0, 0).
        if self.keys.iter().any(|k| uv(k[1]).is_some()) {
            m.uvs = self
                .keys
                .iter()
                .map(|k| uv(k[1]).unwrap_or(Vec2::ZERO))
                .collect();
        }
        if !self.colors.is_empty() {
            if self.colors.len() == self.positions.len() {
                let max = self
                    .colors
                    .iter()
                    .map(|c| c.max_element())
                    .fold(0.0, f32::max);
                let to_unit = if max > 1.0 && max <= 255.0 {
                    w.add("colors-255", || {
                        format!(
                            "{}: vertex colours above 1 are taken as 0..255",
                            path.display()
                        )
                    });
                    1.0 / 255.0
                } else {
                    1.0
                };
                m.colors = self
                    .keys
                    .iter()
                    .map(|k| (self.colors[k[0] as usize] * to_unit).clamp(Vec3::ZERO, Vec3::ONE))
                    .collect();
            } else {
                w.add("some-colors", || {
                    format!(
                        "{}: only some vertices have colours (`v x y z r g b`); colours are ignored",
                        path.display()
                    )
                });
            }
        }
        m.indices = std::mem::take(&mut self.indices);
        if !self.material_names.is_empty() {
            let libraries = self.libraries.len();
            m.materials = self
                .material_names
                .iter()
                .map(|name| {
                    self.materials.iter().rev().find(|m| m.name == *name).cloned().unwrap_or_else(|| {
                        w.add("material-missing", || {
                            format!(
                                "{}: material `{name}` is in no material library ({libraries} read); it is drawn white",
                                path.display()
                            )
                        });
                        MeshMaterial::plain(name)
                    })
                })
                .collect();
            m.triangle_materials = std::mem::take(&mut self.triangle_materials);
        }
        m.warnings = w.into_lines();
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_library_is_read_once_however_often_it_is_named() {
        let dir = std::env::temp_dir().join(format!("termrast-obj-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("a.mtl"), "newmtl a\nKd 1 0 0\n").unwrap();
        let mut o = Obj::default();
        let mut w = Warnings::default();
        for _ in 0..100 {
            o.library(b"mtllib a.mtl a.mtl", &dir, "x.obj:1", &mut w);
        }
        assert_eq!((o.libraries.len(), o.materials.len()), (1, 1));
        assert!(w.into_lines().is_empty());
    }
}
