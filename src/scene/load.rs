//! Loading a scene's objects: each model read once, split into one object per
//! material where the object takes the model's own materials
//! ([`Material::from_model`]), checked against the scene's triangle budget, and then
//! kept, derived and dropped exactly as its plan says.

use std::path::Path;

use glam::Vec3;

use super::file::TextureMode;
use super::plan::ObjectPlan;
use super::texture::Texture;
use super::topology::Topology;
use super::{BUILTIN_CHECKER, Material, ObjectDesc, SceneError, SceneObject};
use crate::mesh::{MAX_SPHERE_TRIANGLES, Mesh, MeshMaterial};

/// The most triangles a scene may hold in all: checked before a built-in sphere is
/// generated and after each file is read, so a scene of many large models is refused
/// with a message instead of exhausting memory (a triangle costs some 100 bytes once
/// loaded, transformed and set up).
pub const MAX_SCENE_TRIANGLES: usize = 1 << 25;

/// An object to load: its description (with the model's material applied), its
/// mesh, the texture the model's material gave it, and its number in the file.
pub(super) struct Part {
    pub desc: ObjectDesc,
    pub mesh: Mesh,
    pub texture: Option<Texture>,
    pub n: usize,
}

/// Reads every object's model, splitting models with several materials; returns the
/// parts and what the loaders warned of.
pub(super) fn read_models(
    descs: Vec<ObjectDesc>,
    scene: &Path,
) -> Result<(Vec<Part>, Vec<String>), SceneError> {
    let mut parts = Vec::new();
    let mut warnings = Vec::new();
    let mut total = 0usize;
    let over = |n: usize, total: usize| SceneError::Invalid {
        path: scene.into(),
        line: None,
        problem: format!(
            "object {n}: the scene's models have {total} triangles in all, more than the {MAX_SCENE_TRIANGLES} a scene may have"
        ),
    };
    for (i, desc) in descs.into_iter().enumerate() {
        let n = i + 1;
        let promised = desc
            .model
            .strip_prefix("sphere:")
            .and_then(|t| t.parse::<usize>().ok())
            .map_or(0, |t| t.min(MAX_SPHERE_TRIANGLES));
        if total + promised > MAX_SCENE_TRIANGLES {
            return Err(over(n, total + promised));
        }
        let mut mesh = Mesh::from_spec(&desc.model).map_err(|source| SceneError::Model {
            scene: scene.into(),
            object: n,
            source,
        })?;
        total += mesh.triangle_count();
        if total > MAX_SCENE_TRIANGLES {
            return Err(over(n, total));
        }
        warnings.append(&mut mesh.warnings);
        if !desc.material.from_model {
            parts.push(Part {
                desc,
                mesh,
                texture: None,
                n,
            });
            continue;
        }
        let split = mesh.split_by_material();
        let several = split.len() > 1;
        for (material, mesh) in split {
            let mut desc = desc.clone();
            let texture = apply_material(&mut desc, material.as_ref(), &mesh, &mut warnings);
            if several && let Some(m) = &material {
                desc.name = format!("{} · {}", desc.name, m.name);
            }
            parts.push(Part {
                desc,
                mesh,
                texture,
                n,
            });
        }
    }
    Ok((parts, warnings))
}

/// What a model's material adds to the scene's: its diffuse colour multiplies the
/// scene's, its texture is sampled (bilinear unless the scene says otherwise) and the
/// model's vertex colours are used. A texture that cannot be read is a warning.
fn apply_material(
    desc: &mut ObjectDesc,
    material: Option<&MeshMaterial>,
    mesh: &Mesh,
    warnings: &mut Vec<String>,
) -> Option<Texture> {
    let m: &mut Material = &mut desc.material;
    m.vertex_colors = !mesh.colors.is_empty();
    let material = material?;
    m.color *= material.diffuse;
    let source = material.texture.as_ref()?;
    if mesh.uvs.is_empty() {
        warnings.push(format!(
            "{}: material `{}` has a texture ({}), but the model has no texture coordinates: drawn without it",
            mesh.name,
            material.name,
            source.describe()
        ));
        return None;
    }
    match Texture::from_source(source) {
        Ok(t) => {
            if m.texture == TextureMode::Off {
                m.texture = TextureMode::Bilinear;
            }
            Some(t)
        }
        Err(e) => {
            warnings.push(format!("{}: {e}: drawn without it", mesh.name));
            None
        }
    }
}

/// Keeps, derives and drops exactly what an object's plan says.
pub(super) fn load_object(
    part: Part,
    op: &ObjectPlan,
    scene: &Path,
) -> Result<SceneObject, SceneError> {
    let Part {
        desc,
        mut mesh,
        texture: model_texture,
        n,
    } = part;
    let unsupported = |problem: String| SceneError::Unsupported {
        scene: scene.into(),
        object: n,
        model: desc.model.clone(),
        problem,
    };
    if op.vertex_colors && mesh.colors.is_empty() {
        return Err(unsupported(
            "material.vertex_colors = true, but the model has no vertex colours (`v x y z r g b`)"
                .into(),
        ));
    }
    if op.uvs && mesh.uvs.is_empty() {
        return Err(unsupported(
            "material.texture is on, but the model has no texture coordinates (`vt`)".into(),
        ));
    }
    let texture = if op.texture == TextureMode::Off {
        None
    } else if desc.material.from_model && desc.material.image.is_none() {
        model_texture
    } else {
        if desc
            .material
            .image
            .as_deref()
            .is_some_and(|i| i.ends_with(BUILTIN_CHECKER))
        {
            Some(Texture::checker(
                64,
                64,
                8,
                Vec3::new(0.9, 0.55, 0.16),
                Vec3::new(0.16, 0.35, 0.8),
            ))
        } else {
            match (&desc.material.image, mesh.first_texture()) {
                (Some(image), _) => Some(Texture::load(image)?),
                (None, Some(t)) => Some(Texture::from_source(t)?),
                (None, None) => {
                    return Err(unsupported(
                        "material.texture is on, but the model's material has no map_Kd: set material.image".into(),
                    ));
                }
            }
        }
    };
    // Drop what no stage reads: the mesh then holds exactly the attributes the plan
    // transforms.
    if !op.vertex_colors {
        mesh.colors = Vec::new();
    }
    if !op.uvs {
        mesh.uvs = Vec::new();
    }
    // Edge topology comes from the mesh as loaded, with vertices identified by
    // position (so texture seams and the per-face split below are not edges).
    let topology = op.edges.then(|| Topology::of(&mesh));
    let mut face_centres = Vec::new();
    if op.unweld {
        // Flat lighting: every face gets its own three vertices with the face normal.
        let mut flat = Mesh {
            name: mesh.name.clone(),
            ..Mesh::default()
        };
        for t in mesh.indices.chunks_exact(3) {
            let p = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            let normal = (p[1] - p[0])
                .cross(p[2] - p[0])
                .try_normalize()
                .unwrap_or(Vec3::Z);
            let centre = (p[0] + p[1] + p[2]) / 3.0;
            for &i in t {
                flat.indices.push(flat.positions.len() as u32);
                flat.positions.push(mesh.positions[i as usize]);
                flat.normals.push(normal);
                face_centres.push(centre);
                if let Some(c) = mesh.colors.get(i as usize) {
                    flat.colors.push(*c);
                }
                if let Some(uv) = mesh.uvs.get(i as usize) {
                    flat.uvs.push(*uv);
                }
            }
        }
        mesh = flat;
    } else if op.normals {
        mesh.ensure_normals();
    } else {
        mesh.normals = Vec::new();
    }
    let (edges, edge_faces) = match topology {
        Some(t) => {
            let edges = t.drawn_edges(&mesh.indices);
            (edges, if op.silhouette { t.faces } else { Vec::new() })
        }
        None => (Vec::new(), Vec::new()),
    };
    Ok(SceneObject {
        desc,
        mesh: std::sync::Arc::new(mesh),
        edges,
        edge_faces,
        face_centres,
        texture,
    })
}
