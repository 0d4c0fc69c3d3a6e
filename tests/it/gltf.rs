//! glTF 2.0 models: the same cube as `.glb`, as `.gltf` with a data-URI buffer and
//! with an external `.bin`; node transforms, vertex colours, materials, an embedded
//! PNG, skipped line primitives, errors by JSON path, and mutated files. Every file is
//! written by the test: JSON by hand, buffers with the helpers of `doc`.

use std::path::Path;

use base64::Engine;
use glam::{Vec2, Vec3};
use proptest::prelude::*;
use termrast::mesh::{Format, Mesh, MeshError, NO_MATERIAL, TextureSource, gltf};

mod doc;

use doc::{
    Doc, corner, cube_doc, cube_indices, cube_obj, f32_bytes, frame, one_node, png, temp, temp_path,
};

fn load_err(name: &str, bytes: &[u8]) -> String {
    let e = Mesh::load(&temp(name, bytes)).unwrap_err();
    assert!(
        matches!(e, MeshError::Malformed { .. } | MeshError::Empty { .. }),
        "{e}"
    );
    e.to_string()
}

#[test]
fn the_cube_loads_alike_from_glb_data_uri_and_external_bin() {
    let (d, rest) = cube_doc();
    let glb = Mesh::load(&temp("cube.glb", &d.glb(&rest))).unwrap();
    let data = Mesh::load(&temp(
        "cube-data.gltf",
        d.json(Some(&d.data_uri()), &rest).as_bytes(),
    ))
    .unwrap();
    temp("cube buffer.bin", &d.bin);
    let external = Mesh::load(&temp(
        "cube-ext.gltf",
        d.json(Some("cube%20buffer.bin"), &rest).as_bytes(),
    ))
    .unwrap();
    assert_eq!(glb.triangle_count(), 12);
    assert_eq!(
        glb.positions,
        (0..8).map(|i| Vec3::from(corner(i))).collect::<Vec<_>>()
    );
    let want: Vec<u32> = cube_indices().into_iter().map(u32::from).collect();
    assert_eq!(glb.indices, want);
    assert!(glb.normals.is_empty() && glb.uvs.is_empty() && glb.colors.is_empty());
    assert!(glb.materials.is_empty() && glb.triangle_materials.is_empty());
    assert!(glb.warnings.is_empty(), "{:?}", glb.warnings);
    for m in [&data, &external] {
        assert_eq!(m.positions, glb.positions);
        assert_eq!(m.indices, glb.indices);
    }
}

#[test]
fn gltf_json_is_told_by_content() {
    let (d, rest) = cube_doc();
    let json = d.json(Some(&d.data_uri()), &rest);
    assert_eq!(
        Format::detect(json.as_bytes(), Path::new("model")),
        Format::Gltf
    );
    assert_eq!(
        Format::detect(json.as_bytes(), Path::new("model.obj")),
        Format::Gltf
    );
    assert_eq!(
        Format::detect(&d.glb(&rest), Path::new("m.stl")),
        Format::Gltf
    );
    assert_eq!(Format::detect(b"{\"x\":1}", Path::new("m")), Format::Obj);
    assert_eq!(
        Format::detect(b"# \"asset\"\nv 0 0 0\n", Path::new("m")),
        Format::Obj
    );
    assert_eq!(
        Mesh::load(&temp("noext", json.as_bytes()))
            .unwrap()
            .triangle_count(),
        12
    );
}

#[test]
fn node_transforms_are_applied_down_the_hierarchy() {
    let mut d = Doc::default();
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let p = d.positions(&tri);
    let n = d.accessor(&f32_bytes([0.0, 0.0, 1.0].repeat(3)), 5126, "VEC3", 3, "");
    // Node 0 moves by +10 x and holds node 1, which scales by 2 and turns 90° about
    // z (quaternion [0, 0, sin 45°, cos 45°]); node 2, a root too, mirrors x by a matrix.
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let rest = format!(
        r#","meshes":[{{"primitives":[{{"attributes":{{"POSITION":{p},"NORMAL":{n}}}}}]}}],
        "nodes":[{{"translation":[10,0,0],"children":[1]}},
                 {{"mesh":0,"scale":[2,2,2],"rotation":[0,0,{h},{h}]}},
                 {{"mesh":0,"matrix":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}}],
        "scenes":[{{"nodes":[0,2]}}]"#
    );
    let m = Mesh::load(&temp(
        "nodes.gltf",
        d.json(Some(&d.data_uri()), &rest).as_bytes(),
    ))
    .unwrap();
    assert_eq!(m.triangle_count(), 2);
    let near = |a: Vec3, b: [f32; 3]| (a - Vec3::from(b)).length() < 1e-5;
    let want = [
        [10.0, 0.0, 0.0],
        [10.0, 2.0, 0.0],
        [8.0, 0.0, 0.0],
        [0.0, 0.0, 5.0],
        [-1.0, 0.0, 5.0],
        [0.0, 1.0, 5.0],
    ];
    for (got, want) in m.positions.iter().zip(want) {
        assert!(near(*got, want), "{got} vs {want:?}");
    }
    assert!(
        m.normals.iter().all(|n| near(*n, [0.0, 0.0, 1.0])),
        "{:?}",
        m.normals
    );
    // The mirrored copy keeps facing the same way: its winding is reversed.
    assert_eq!(m.indices, [0, 1, 2, 3, 5, 4]);
}

#[test]
fn vertex_colours_uvs_and_base_colour_factor() {
    let mut d = Doc::default();
    let p = d.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    // RGBA as normalised u8, and RGB as floats.
    let c8 = d.accessor(
        &[255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 51, 0],
        5121,
        "VEC4",
        3,
        r#","normalized":true"#,
    );
    let cf = d.accessor(&f32_bytes([0.5, 0.25, 1.0].repeat(3)), 5126, "VEC3", 3, "");
    let uv = d.accessor(
        &f32_bytes([0.0, 0.0, 1.0, 0.25, 0.5, 1.0]),
        5126,
        "VEC2",
        3,
        "",
    );
    let prims = format!(
        r#"{{"attributes":{{"POSITION":{p},"COLOR_0":{c8},"TEXCOORD_0":{uv}}},"material":0}},
           {{"attributes":{{"POSITION":{p},"COLOR_0":{cf}}}}}"#
    );
    let rest = format!(
        r#"{},"materials":[{{"name":"paint","pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.4,0.2,1]}}}}]"#,
        one_node(&prims, "")
    );
    let m = Mesh::load(&temp("colours.glb", &d.glb(&rest))).unwrap();
    assert_eq!(m.colors[..3], [Vec3::X, Vec3::Y, Vec3::new(0.0, 0.0, 0.2)]);
    assert_eq!(m.colors[3], Vec3::new(0.5, 0.25, 1.0));
    assert_eq!(
        m.uvs[..3],
        [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 0.75),
            Vec2::new(0.5, 0.0)
        ]
    );
    assert_eq!(m.uvs[3], Vec2::ZERO, "a primitive without UVs gets zeros");
    assert_eq!(m.materials.len(), 1);
    assert_eq!(m.materials[0].name, "paint");
    assert_eq!(m.materials[0].diffuse, Vec3::new(0.8, 0.4, 0.2));
    assert_eq!(m.materials[0].texture, None);
    assert_eq!(m.triangle_materials, [0, NO_MATERIAL]);
}

#[test]
fn base_colour_textures_embedded_and_beside_the_file() {
    let mut d = Doc::default();
    let p = d.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let uv = d.accessor(&f32_bytes([0.0; 6]), 5126, "VEC2", 3, "");
    let red = png([255, 0, 0]);
    let view = d.view(&red);
    let green_uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png([0, 255, 0]))
    );
    temp("blue tex.png", &png([0, 0, 255]));
    let prims: Vec<String> = (0..4)
        .map(|i| format!(r#"{{"attributes":{{"POSITION":{p},"TEXCOORD_0":{uv}}},"material":{i}}}"#))
        .collect();
    let mat =
        |t: usize| format!(r#"{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":{t}}}}}}}"#);
    let rest = format!(
        r#"{},"materials":[{},{},{},{}],"textures":[{{"source":0}},{{"source":1}},{{"source":2}},{{"source":3}}],
        "images":[{{"bufferView":{view},"mimeType":"image/png"}},{{"uri":"{green_uri}"}},{{"uri":"blue%20tex.png"}},{{"uri":"missing.png"}}]"#,
        one_node(&prims.join(","), ""),
        mat(0),
        mat(1),
        mat(2),
        mat(3)
    );
    let m = Mesh::load(&temp("tex.glb", &d.glb(&rest))).unwrap();
    let tex: Vec<_> = m.materials.iter().map(|m| m.texture.clone()).collect();
    let Some(TextureSource::Embedded { name, bytes }) = &tex[0] else {
        panic!("{tex:?}")
    };
    assert!(
        name.contains("tex.glb") && name.contains("images[0]"),
        "{name}"
    );
    assert_eq!(&bytes[..], &red[..]);
    let colour = |t: &TextureSource| {
        termrast::scene::texture::Texture::from_source(t)
            .unwrap()
            .texels[0]
    };
    assert_eq!(colour(tex[0].as_ref().unwrap()), Vec3::X);
    assert_eq!(colour(tex[1].as_ref().unwrap()), Vec3::Y);
    assert_eq!(tex[2], Some(TextureSource::File(temp_path("blue tex.png"))));
    assert_eq!(tex[3], None);
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("images[3].uri") && w.contains("missing.png")),
        "{:?}",
        m.warnings
    );
    assert_eq!(m.materials[0].name, "materials[0]");
    assert_eq!(
        m.materials[0].diffuse,
        Vec3::ONE,
        "the default base colour is white"
    );
}

#[test]
fn an_embedded_texture_and_vertex_colours_show_in_the_frame() {
    let mut d = Doc::default();
    let p = d.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let n = d.accessor(&f32_bytes([0.0, 0.0, 1.0].repeat(3)), 5126, "VEC3", 3, "");
    let uv = d.accessor(&f32_bytes([0.0; 6]), 5126, "VEC2", 3, "");
    let view = d.view(&png([0, 255, 0]));
    let green = |c: &[u8; 4]| c[1] > 40 && c[0] < c[1] / 4 && c[2] < c[1] / 4;
    let rest = format!(
        r#"{},"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
        "textures":[{{"source":0}}],"images":[{{"bufferView":{view},"mimeType":"image/png"}}]"#,
        one_node(
            &format!(
                r#"{{"attributes":{{"POSITION":{p},"NORMAL":{n},"TEXCOORD_0":{uv}}},"material":0}}"#
            ),
            ""
        )
    );
    let (_, colour) = frame(&temp("green.glb", &d.glb(&rest)));
    assert!(
        colour.iter().filter(|c| green(c)).count() > 50,
        "the texture is drawn"
    );
    let c = d.accessor(&f32_bytes([0.0, 1.0, 0.0].repeat(3)), 5126, "VEC3", 3, "");
    let rest = one_node(
        &format!(r#"{{"attributes":{{"POSITION":{p},"NORMAL":{n},"COLOR_0":{c}}}}}"#),
        "",
    );
    let (_, colour) = frame(&temp("green-vertices.glb", &d.glb(&rest)));
    assert!(
        colour.iter().filter(|c| green(c)).count() > 50,
        "the colours are drawn"
    );
}

#[test]
fn the_cube_as_gltf_covers_what_the_cube_as_obj_does() {
    let (d, rest) = cube_doc();
    let depth = frame;
    let (obj_depth, obj_colour) = depth(&temp("cube.obj", cube_obj().as_bytes()));
    let (glb_depth, glb_colour) = depth(&temp("render-cube.glb", &d.glb(&rest)));
    assert!(
        obj_depth.iter().filter(|&&b| b != obj_depth[0]).count() > 100,
        "the cube is drawn"
    );
    assert_eq!(glb_depth, obj_depth);
    assert_eq!(glb_colour, obj_colour);
}

#[test]
fn strips_and_fans_become_triangles_and_lines_are_skipped_once() {
    let mut d = Doc::default();
    let p = d.positions(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let prims = format!(
        r#"{{"attributes":{{"POSITION":{p}}},"mode":5}},{{"attributes":{{"POSITION":{p}}},"mode":6}},
           {{"attributes":{{"POSITION":{p}}},"mode":1}},{{"attributes":{{"POSITION":{p}}},"mode":3}},
           {{"attributes":{{"POSITION":{p}}},"mode":0}}"#
    );
    let m = Mesh::load(&temp(
        "modes.gltf",
        d.json(Some(&d.data_uri()), &one_node(&prims, ""))
            .as_bytes(),
    ))
    .unwrap();
    assert_eq!(m.indices, [0, 1, 2, 2, 1, 3, 4, 5, 6, 4, 6, 7]);
    assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
    assert!(
        m.warnings[0].contains("meshes[0].primitives[2]") && m.warnings[0].contains("once more")
    );
    assert!(m.warnings[1].contains("primitives[4]") && m.warnings[1].contains("Points"));
    let only_lines = one_node(
        &format!(r#"{{"attributes":{{"POSITION":{p}}},"mode":1}}"#),
        "",
    );
    let e = load_err(
        "lines.gltf",
        d.json(Some(&d.data_uri()), &only_lines).as_bytes(),
    );
    assert!(e.contains("no triangles") && e.contains("lines"), "{e}");
}

#[test]
fn sparse_accessors_replace_their_elements() {
    let mut d = Doc::default();
    let p = d.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let idx = d.view(&[2, 0]);
    let vals = d.view(&f32_bytes([0.0, 3.0, 0.0]));
    d.accessors[p].pop();
    d.accessors[p] += &format!(
        r#","sparse":{{"count":1,"indices":{{"bufferView":{idx},"componentType":5121}},"values":{{"bufferView":{vals}}}}}}}"#
    );
    let rest = one_node(&format!(r#"{{"attributes":{{"POSITION":{p}}}}}"#), "");
    let m = Mesh::load(&temp("sparse.glb", &d.glb(&rest))).unwrap();
    assert_eq!(m.positions[2], Vec3::new(0.0, 3.0, 0.0));
    // A sparse index past the accessor is an error naming it.
    d.bin[36] = 7; // the sparse index, after the 36 bytes of positions
    let e = load_err("sparse-bad.glb", &d.glb(&rest));
    assert!(
        e.contains("accessors[0].sparse.indices") && e.contains("index 7"),
        "{e}"
    );
}

#[test]
fn errors_name_the_file_and_the_json_path() {
    let (d, rest) = cube_doc();
    // An index beyond the 8 vertices.
    let mut bad = d.clone();
    let n = bad.bin.len();
    bad.bin[n - 2..].copy_from_slice(&9u16.to_le_bytes());
    let e = load_err("badindex.glb", &bad.glb(&rest));
    assert!(
        e.starts_with(&format!("{}: ", temp_path("badindex.glb").display())),
        "{e}"
    );
    assert!(
        e.contains("meshes[0].primitives[0].indices") && e.contains("vertex 9"),
        "{e}"
    );
    // A non-finite position.
    let mut nan = d.clone();
    nan.bin[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = load_err("nan.glb", &nan.glb(&rest));
    assert!(
        e.contains("attributes.POSITION") && e.contains("vertex 1"),
        "{e}"
    );
    // An accessor past its buffer view.
    let mut long = d.clone();
    long.accessors[0] = long.accessors[0].replace(r#""count":8"#, r#""count":9"#);
    let e = load_err("long.glb", &long.glb(&rest));
    assert!(
        e.contains("attributes.POSITION") && e.contains("accessors[0]") && e.contains("108 bytes"),
        "{e}"
    );
    // A view past its buffer.
    let e = load_err(
        "short.gltf",
        d.json(Some(&d.data_uri()), &rest)
            .replace(r#""byteLength":96"#, r#""byteLength":960"#)
            .as_bytes(),
    );
    assert!(
        e.contains("bufferViews[0]") && e.contains("past the end of buffers[0]"),
        "{e}"
    );
    // A reference to nothing, from the document's own checks.
    let e = load_err(
        "dangling.glb",
        &d.glb(&rest.replace(r#""indices":1"#, r#""indices":5"#)),
    );
    assert!(e.contains("meshes[0].primitives[0].indices"), "{e}");
    // Buffers: no network, a missing file, a truncated GLB.
    let e = load_err(
        "net.gltf",
        d.json(Some("https://example.com/cube.bin"), &rest)
            .as_bytes(),
    );
    assert!(e.contains("buffers[0]") && e.contains("https"), "{e}");
    let e = load_err("nofile.gltf", d.json(Some("nowhere.bin"), &rest).as_bytes());
    assert!(e.contains("buffers[0]") && e.contains("nowhere.bin"), "{e}");
    let glb = d.glb(&rest);
    let e = load_err("cut.glb", &glb[..glb.len() - 10]);
    assert!(e.contains("cut.glb") && e.contains("bytes"), "{e}");
    let e = load_err("json.gltf", b"{\"asset\": [");
    assert!(e.contains("json.gltf") && e.contains("JSON"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn mutated_gltf_files_never_panic(
        glb in any::<bool>(),
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
        cut in any::<usize>(),
    ) {
        let (d, rest) = cube_doc();
        let mut data = if glb {
            d.glb(&rest)
        } else {
            d.json(Some(&d.data_uri()), &rest).into_bytes()
        };
        // Edits land in the JSON more often than not: most of a GLB's bytes are JSON.
        for (at, b) in edits {
            let n = data.len();
            let b = if b < 128 { b"0123456789,:[]{}\"-."[usize::from(b) % 19] } else { b };
            data[at % n] = b;
        }
        data.truncate(cut % (data.len() + 1) + data.len() / 2);
        let _ = gltf::parse(&data, Path::new("fuzz.gltf"));
    }
}
