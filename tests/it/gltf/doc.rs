//! Writing small glTF and GLB files for the tests: a buffer with its views and
//! accessors, the JSON around them, the GLB container; and the cube.

use std::path::{Path, PathBuf};

use base64::Engine;

pub fn temp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("termrast-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

pub fn temp(name: &str, bytes: &[u8]) -> PathBuf {
    let path = temp_path(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Corner `i` of the cube [0, 1]³ (bit 0: x, bit 1: y, bit 2: z).
pub fn corner(i: u32) -> [f32; 3] {
    [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]
}

/// The cube's 12 triangles over its 8 corners, counter-clockwise seen from outside
/// (the quads of tests/it/formats.rs).
pub fn cube_indices() -> Vec<u16> {
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    quads
        .iter()
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect()
}

pub fn f32_bytes(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// A glTF document being written: one binary buffer, its views and accessors.
#[derive(Clone, Default)]
pub struct Doc {
    pub bin: Vec<u8>,
    pub views: Vec<String>,
    pub accessors: Vec<String>,
}

impl Doc {
    /// Appends `bytes` as a buffer view; its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Appends `bytes` as a view and an accessor of `count` elements; its index.
    /// `extra` is more JSON for the accessor (`"normalized":true`, min and max).
    pub fn accessor(
        &mut self,
        bytes: &[u8],
        component: u32,
        ty: &str,
        count: usize,
        extra: &str,
    ) -> usize {
        let view = self.view(bytes);
        self.accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":{component},"type":"{ty}","count":{count}{extra}}}"#
        ));
        self.accessors.len() - 1
    }

    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        self.accessor(
            &f32_bytes(p.iter().flatten().copied()),
            5126,
            "VEC3",
            p.len(),
            "",
        )
    }

    pub fn indices(&mut self, i: &[u16]) -> usize {
        let bytes: Vec<u8> = i.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.accessor(&bytes, 5123, "SCALAR", i.len(), "")
    }

    /// The JSON, with the buffer at `uri` (none: the GLB's BIN chunk) and `rest`
    /// (meshes, nodes, scenes, materials…) after the accessors.
    pub fn json(&self, uri: Option<&str>, rest: &str) -> String {
        let uri = uri.map(|u| format!(r#","uri":"{u}""#)).unwrap_or_default();
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{}{uri}}}],"bufferViews":[{}],"accessors":[{}]{rest}}}"#,
            self.bin.len(),
            self.views.join(","),
            self.accessors.join(",")
        )
    }

    pub fn data_uri(&self) -> String {
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        )
    }

    /// The document as a GLB: header, JSON chunk, BIN chunk.
    pub fn glb(&self, rest: &str) -> Vec<u8> {
        let mut json = self.json(None, rest).into_bytes();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }
}

/// One node with one mesh of the given primitives (JSON objects).
pub fn one_node(primitives: &str, node: &str) -> String {
    format!(
        r#","meshes":[{{"primitives":[{primitives}]}}],"nodes":[{{"mesh":0{node}}}],"scenes":[{{"nodes":[0]}}],"scene":0"#
    )
}

/// The cube document and the JSON after its accessors.
pub fn cube_doc() -> (Doc, String) {
    let mut d = Doc::default();
    let p = d.positions(&(0..8).map(corner).collect::<Vec<_>>());
    let i = d.indices(&cube_indices());
    let rest = one_node(
        &format!(r#"{{"attributes":{{"POSITION":{p}}},"indices":{i}}}"#),
        "",
    );
    (d, rest)
}

pub fn cube_obj() -> String {
    let mut s = String::new();
    for i in 0..8 {
        let [x, y, z] = corner(i);
        s += &format!("v {x} {y} {z}\n");
    }
    for t in cube_indices().chunks(3) {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

pub fn png(rgb: [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(2, 2, image::Rgb(rgb));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A frame of the model's default scene (its materials, lit): depth bits and colours.
pub fn frame(path: &Path) -> (Vec<u32>, Vec<[u8; 4]>) {
    use termrast::raster::Target;
    use termrast::scene::Scene;
    use termrast::scene::render::{SceneFrame, SceneView};
    let scene = Scene::for_model(path.to_str().unwrap()).unwrap();
    let mut frame = SceneFrame::new(&scene);
    let view = SceneView {
        time: 0.0,
        yaw: 0.6,
        pitch: 0.4,
        zoom: 1.0,
        pixel_aspect: 1.0,
    };
    frame.draw(&scene, Target::new(64, 48), &view);
    let bits: Vec<u32> = frame
        .renderer
        .depth
        .to_vec()
        .iter()
        .map(|d| d.to_bits())
        .collect();
    (bits, frame.color.0)
}
