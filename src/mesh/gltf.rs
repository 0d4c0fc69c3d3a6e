//! glTF 2.0 models, `.gltf` (JSON, with external or `data:` buffers) and `.glb`, read
//! with the `gltf` crate's document model; the bytes are found and checked here (see
//! `data`), never by `gltf::import`, so every file goes through the same guards as
//! the model itself.
//!
//! What is read: every primitive of triangle mode (strips and fans are converted) of
//! the nodes of the default scene (else the first scene, else every root node), each
//! under its node's world transform (normals by the inverse transpose, winding
//! reversed where the transform mirrors); `POSITION`, `NORMAL` (kept only if every
//! primitive has it), the base colour texture's `TEXCOORD_n` (v flipped: glTF's origin
//! is the image's top-left, termrast's its bottom-left), `COLOR_0` (RGB or RGBA, float
//! or normalised integers, linear already); indices of any unsigned type or none;
//! materials as base colour factor and base colour texture. Points and lines are
//! skipped with a warning. Errors name the file and the JSON path.

use std::path::Path;
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3, Vec2, Vec3};
use gltf::json::validation::Validate;
use gltf::mesh::{Mode, Semantic};
use gltf::{Document, Node, Primitive};

use super::material::Warnings;
use super::{Mesh, MeshError, MeshMaterial, NO_MATERIAL, TextureSource};

mod data;

use data::Buffers;

/// Most vertices, and most triangles, the nodes of a model may add up to (the
/// triangle limit of a scene).
const MAX_INSTANCED: usize = 1 << 25;

/// Whether `bytes` start with the GLB magic.
#[must_use]
pub fn is_glb(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

/// Whether `bytes` look like a glTF JSON document: an object (after an optional BOM
/// and white space) with an `"asset"` key in its first mebibyte. No OBJ starts
/// with `{`.
#[must_use]
pub fn is_gltf_json(bytes: &[u8]) -> bool {
    let b = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let start = b.iter().position(|c| !c.is_ascii_whitespace());
    start.is_some_and(|s| b[s] == b'{')
        && b[..b.len().min(1 << 20)]
            .windows(7)
            .any(|w| w == b"\"asset\"")
}

/// Parses a `.gltf` or `.glb` file's bytes; buffers and images outside it are
/// looked up beside `path`.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let malformed = |problem: String| MeshError::Malformed {
        path: path.into(),
        line: None,
        problem,
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load(bytes, path)))
        .map_err(|_| malformed("the glTF reader failed on this file".into()))?;
    match result {
        Ok(m) => Ok(m),
        Err(Failure::Malformed(problem)) => Err(malformed(problem)),
        Err(Failure::Empty(note)) => Err(MeshError::Empty {
            path: path.into(),
            note,
        }),
    }
}

enum Failure {
    Malformed(String),
    Empty(String),
}

impl From<String> for Failure {
    fn from(s: String) -> Self {
        Self::Malformed(s)
    }
}

fn load(bytes: &[u8], path: &Path) -> Result<Mesh, Failure> {
    let (json, bin) = if is_glb(bytes) {
        data::split_glb(bytes)?
    } else {
        (bytes, None)
    };
    let json = json.strip_prefix(b"\xef\xbb\xbf").unwrap_or(json);
    let root = gltf::json::deserialize::from_slice::<gltf::json::Root>(json)
        .map_err(|e| format!("not glTF JSON: {e}"))?;
    validate(&root)?;
    let doc = Document::from_json_without_validation(root);
    let buffers = Buffers::new(&doc, bin, path);
    let mut b = Builder {
        file: path.display().to_string(),
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        buffers: &buffers,
        warnings: Warnings::default(),
        material_slots: vec![None; doc.materials().len()],
        out: Out::default(),
    };
    let roots: Vec<Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut child = vec![false; doc.nodes().len()];
            for c in doc.nodes().flat_map(|n| n.children()) {
                child[c.index()] = true;
            }
            doc.nodes().filter(|n| !child[n.index()]).collect()
        }
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<(Node, DMat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, DMat4::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        let i = node.index();
        if std::mem::replace(&mut seen[i], true) {
            b.warnings.add("gltf-node-twice", || {
                format!(
                    "{}: nodes[{i}] is reached twice (the node hierarchy must be a tree); drawn once",
                    b.file
                )
            });
            continue;
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                let at = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
                b.primitive(&prim, &at, world, i)?;
            }
        }
        stack.extend(
            node.children()
                .map(|c| (c, world))
                .collect::<Vec<_>>()
                .into_iter()
                .rev(),
        );
    }
    b.finish(path)
}

/// The document's own checks (references in range, required fields), by JSON path.
/// `min`/`max` are not used here, so a file that lacks them still loads.
fn validate(root: &gltf::json::Root) -> Result<(), String> {
    // The crate's own check indexes the POSITION accessor unchecked: check it first.
    for (i, mesh) in root.meshes.iter().enumerate() {
        for (j, prim) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(Semantic::Positions);
            if let Some(a) = prim.attributes.get(&position)
                && a.value() >= root.accessors.len()
            {
                return Err(format!(
                    "meshes[{i}].primitives[{j}].attributes.POSITION: index out of bounds"
                ));
            }
        }
    }
    let mut first: Option<String> = None;
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let p = path().to_string();
        if first.is_none() && !p.ends_with(".min") && !p.ends_with(".max") {
            let what = match error {
                gltf::json::validation::Error::Unsupported => {
                    let name = p
                        .strip_prefix("extensionsRequired[")
                        .and_then(|s| s.strip_suffix(']'))
                        .and_then(|s| s.parse::<usize>().ok())
                        .and_then(|i| root.extensions_required.get(i));
                    match name {
                        Some(n) => format!("extension {n} is required but not supported"),
                        None => "unsupported".into(),
                    }
                }
                e => e.to_string().to_lowercase(),
            };
            first = Some(format!("{p}: {what}"));
        }
    });
    first.map_or(Ok(()), Err)
}

/// The mesh being built, in f64 until the end.
#[derive(Default)]
struct Out {
    positions: Vec<[f64; 3]>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    colors: Vec<Vec3>,
    indices: Vec<u32>,
    materials: Vec<MeshMaterial>,
    triangle_materials: Vec<u32>,
    missing_normals: bool,
    any_uv: bool,
    any_color: bool,
    any_material: bool,
    skipped: usize,
}

struct Builder<'a> {
    file: String,
    dir: std::path::PathBuf,
    buffers: &'a Buffers<'a>,
    warnings: Warnings,
    /// Per glTF material, its index in `out.materials` and its texture's UV set.
    material_slots: Vec<Option<(u32, u32)>>,
    out: Out,
}

impl Builder<'_> {
    fn primitive(
        &mut self,
        prim: &Primitive,
        at: &str,
        world: DMat4,
        node: usize,
    ) -> Result<(), Failure> {
        let mode = prim.mode();
        let kind = match mode {
            Mode::Points => Some("points"),
            Mode::Lines | Mode::LineLoop | Mode::LineStrip => Some("lines"),
            _ => None,
        };
        if let Some(kind) = kind {
            self.out.skipped += 1;
            let file = &self.file;
            self.warnings.add(kind, || {
                format!(
                    "{file}: {at}: a primitive of {mode:?} mode is not drawn (only triangles are)"
                )
            });
            return Ok(());
        }
        let attr = |semantic: Semantic,
                    name: &str,
                    dims: &[usize]|
         -> Result<Option<Vec<f32>>, String> {
            let Some(acc) = prim.get(&semantic) else {
                return Ok(None);
            };
            let n = data::components(&acc).filter(|n| dims.contains(n)).ok_or_else(|| {
                format!("{at}.attributes.{name} (accessors[{}]): {:?} elements, expected {dims:?} components", acc.index(), acc.dimensions())
            })?;
            let mut v = self
                .buffers
                .floats(&acc)
                .map_err(|e| format!("{at}.attributes.{name}: {e}"))?;
            if n == 4 && dims.contains(&3) {
                // RGBA colours: alpha is not drawn.
                v = v.chunks_exact(4).flat_map(|c| [c[0], c[1], c[2]]).collect();
            }
            Ok(Some(v))
        };
        let positions = attr(Semantic::Positions, "POSITION", &[3])?
            .ok_or_else(|| format!("{at}.attributes: no POSITION"))?;
        if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "{at}.attributes.POSITION: vertex {} is not a finite number",
                k / 3
            )
            .into());
        }
        let n = positions.len() / 3;
        let list = match prim.indices() {
            Some(acc) => {
                if data::components(&acc) != Some(1) {
                    return Err(format!("{at}.indices: indices must be scalars").into());
                }
                let list = self
                    .buffers
                    .uints(&acc)
                    .map_err(|e| format!("{at}.indices: {e}"))?;
                if let Some((k, &bad)) = list.iter().enumerate().find(|&(_, &i)| i as usize >= n) {
                    return Err(format!(
                        "{at}.indices: index {k} refers to vertex {bad}, but there are {n} vertices"
                    )
                    .into());
                }
                list
            }
            None => (0..n as u32).collect(),
        };
        let mut tris: Vec<[u32; 3]> = match mode {
            Mode::TriangleStrip => (2..list.len())
                .map(|k| {
                    let [a, b, c] = [list[k - 2], list[k - 1], list[k]];
                    if k % 2 == 0 { [a, b, c] } else { [b, a, c] }
                })
                .collect(),
            Mode::TriangleFan => (2..list.len())
                .map(|k| [list[0], list[k - 1], list[k]])
                .collect(),
            _ => {
                if list.len() % 3 != 0 {
                    let file = &self.file;
                    self.warnings.add("gltf-index-count", || {
                        format!(
                            "{file}: {at}: {} indices is not a multiple of 3; the last ones are not drawn",
                            list.len()
                        )
                    });
                }
                list.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
            }
        };
        if tris.is_empty() {
            return Ok(());
        }
        if world.determinant() < 0.0 {
            for t in &mut tris {
                t.swap(1, 2);
            }
        }
        let material = prim
            .material()
            .index()
            .map(|i| self.material(prim.material(), i));
        let uv_set = material.map_or(0, |(_, set)| set);
        let normals = attr(Semantic::Normals, "NORMAL", &[3])?;
        let uvs = attr(
            Semantic::TexCoords(uv_set),
            &format!("TEXCOORD_{uv_set}"),
            &[2],
        )?;
        let colors = attr(Semantic::Colors(0), "COLOR_0", &[3, 4])?;
        for (name, v, dims) in [
            ("NORMAL", &normals, 3),
            ("TEXCOORD", &uvs, 2),
            ("COLOR_0", &colors, 3),
        ] {
            if v.as_ref().is_some_and(|v| v.len() != n * dims) {
                return Err(format!(
                    "{at}.attributes.{name}: {} elements, but POSITION has {n}",
                    v.as_ref().map_or(0, Vec::len) / dims
                )
                .into());
            }
        }
        let o = &mut self.out;
        let base = o.positions.len();
        // Nodes may draw one mesh many times: bound what the instances add up to
        // before allocating it.
        if base + n > MAX_INSTANCED || o.indices.len() / 3 + tris.len() > MAX_INSTANCED {
            return Err(format!(
                "nodes[{node}]: with {at}, the scene's nodes draw more than {MAX_INSTANCED} \
                 vertices or triangles, more than are read"
            )
            .into());
        }
        o.missing_normals |= normals.is_none();
        o.any_uv |= uvs.is_some();
        o.any_color |= colors.is_some();
        for p in positions.chunks_exact(3) {
            let p = world.transform_point3(DVec3::new(p[0].into(), p[1].into(), p[2].into()));
            if !p.is_finite() {
                return Err(format!(
                    "nodes[{node}]: its transform takes {at}'s positions beyond finite numbers"
                )
                .into());
            }
            o.positions.push(p.to_array());
        }
        let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
        match normals {
            Some(v) => o.normals.extend(v.chunks_exact(3).map(|c| {
                let m = normal_matrix * Vec3::from_slice(c).as_dvec3();
                m.as_vec3().try_normalize().unwrap_or(Vec3::Z)
            })),
            None => o.normals.resize(base + n, Vec3::Z),
        }
        match uvs {
            Some(v) => o
                .uvs
                .extend(v.chunks_exact(2).map(|c| Vec2::new(c[0], 1.0 - c[1]))),
            None => o.uvs.resize(base + n, Vec2::ZERO),
        }
        match colors {
            Some(v) => o.colors.extend(v.chunks_exact(3).map(|c| {
                Vec3::from_slice(c).map(|x| {
                    if x.is_finite() {
                        x.clamp(0.0, 1.0)
                    } else {
                        0.0
                    }
                })
            })),
            None => o.colors.resize(base + n, Vec3::ONE),
        }
        let m = material.map_or(NO_MATERIAL, |(m, _)| m);
        o.any_material |= material.is_some();
        for t in tris {
            o.indices.extend(t.map(|i| i + base as u32));
            o.triangle_materials.push(m);
        }
        Ok(())
    }

    /// The index in the mesh's materials of glTF material `i`, and its UV set.
    fn material(&mut self, mat: gltf::Material, i: usize) -> (u32, u32) {
        if let Some(slot) = self.material_slots[i] {
            return slot;
        }
        let pbr = mat.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let info = pbr.base_color_texture();
        let texture = info.as_ref().and_then(|t| self.image(t.texture().source()));
        self.out.materials.push(MeshMaterial {
            name: mat
                .name()
                .map_or_else(|| format!("materials[{i}]"), str::to_owned),
            diffuse: Vec3::new(r, g, b),
            texture,
        });
        let slot = (
            self.out.materials.len() as u32 - 1,
            info.map_or(0, |t| t.tex_coord()),
        );
        self.material_slots[i] = Some(slot);
        slot
    }

    /// Where an image's encoded bytes are; a problem is a warning, and the material
    /// is drawn without its texture.
    fn image(&mut self, image: gltf::Image) -> Option<TextureSource> {
        let at = format!("{}: images[{}]", self.file, image.index());
        let found = match image.source() {
            gltf::image::Source::View { view, .. } => {
                self.buffers.view(&view).map(|b| TextureSource::Embedded {
                    name: at.clone(),
                    bytes: Arc::from(b),
                })
            }
            gltf::image::Source::Uri { uri, .. } => match data::scheme(uri) {
                Some("data") => data::decode_data_uri(uri).map(|b| TextureSource::Embedded {
                    name: at.clone(),
                    bytes: b.into(),
                }),
                Some(other) => Err(format!("`{other}:` URIs are not read")),
                None => {
                    let name = String::from_utf8_lossy(&data::percent_decode(uri)).into_owned();
                    let uri_at = format!("{at}.uri");
                    return super::mtl::find_file(&self.dir, &name, &uri_at, &mut self.warnings)
                        .map(TextureSource::File);
                }
            },
        };
        found
            .map_err(|e| {
                self.warnings.add("gltf-image", || {
                    format!("{at}: {e}; drawn without the texture")
                });
            })
            .ok()
    }

    fn finish(self, path: &Path) -> Result<Mesh, Failure> {
        let o = self.out;
        if o.indices.is_empty() {
            return Err(Failure::Empty(if o.skipped > 0 {
                " (only points or lines, which are not drawn)".into()
            } else {
                String::new()
            }));
        }
        let scale = super::power_of_two_scale(&o.positions);
        Ok(Mesh {
            name: path.display().to_string(),
            positions: o
                .positions
                .iter()
                .map(|p| (DVec3::from_array(*p) * scale).as_vec3())
                .collect(),
            normals: if o.missing_normals {
                Vec::new()
            } else {
                o.normals
            },
            uvs: if o.any_uv { o.uvs } else { Vec::new() },
            colors: if o.any_color { o.colors } else { Vec::new() },
            indices: o.indices,
            materials: o.materials,
            triangle_materials: if o.any_material {
                o.triangle_materials
            } else {
                Vec::new()
            },
            warnings: self.warnings.into_lines(),
        })
    }
}
