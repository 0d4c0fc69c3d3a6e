//! Model formats: STL (binary, ASCII), PLY (ASCII, binary of both byte orders), the
//! format told by content, and files that are not regular refused at once.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use proptest::prelude::*;
use termrast::mesh::{Format, Mesh, MeshError, ply, stl};

fn temp(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("termrast-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The 12 triangles of the cube [0, 1]³, counter-clockwise seen from outside.
fn cube() -> Vec<[[f32; 3]; 3]> {
    let c = |i: u32| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
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
        .flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]])
        .collect()
}

/// A binary STL whose header starts with `solid` (as many exporters write it).
fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut b = b"solid cube written as binary".to_vec();
    b.resize(80, b' ');
    b.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend([0f32; 3].iter().flat_map(|f| f.to_le_bytes()));
        b.extend(t.iter().flatten().flat_map(|f| f.to_le_bytes()));
        b.extend([0u8; 2]);
    }
    b
}

fn ascii_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut s = String::from("solid cube\n");
    for t in tris {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for v in t {
            s += &format!("      vertex {:?} {:?} {:?}\n", v[0], v[1], v[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid cube\n";
    s.into_bytes()
}

/// Five vertices (a unit square and an apex) with colours; a quad and a triangle.
const PLY_VERTS: [([f32; 3], [u8; 3]); 5] = [
    ([0.0, 0.0, 0.0], [255, 0, 0]),
    ([1.0, 0.0, 0.0], [0, 255, 0]),
    ([1.0, 1.0, 0.0], [0, 0, 255]),
    ([0.0, 1.0, 0.0], [255, 255, 255]),
    ([0.5, 0.5, 0.7], [10, 20, 30]),
];
const PLY_FACES: [&[u32]; 2] = [&[0, 1, 2, 3], &[0, 1, 4]];

fn ply_header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment test\nelement vertex 5\nproperty float x\n\
         property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n\
         property uchar blue\nelement face 2\nproperty list uchar int vertex_indices\n\
         end_header\n"
    )
}

fn ply_ascii() -> Vec<u8> {
    let mut s = ply_header("ascii");
    for (p, c) in PLY_VERTS {
        s += &format!(
            "{:?} {:?} {:?} {} {} {}\n",
            p[0], p[1], p[2], c[0], c[1], c[2]
        );
    }
    for f in PLY_FACES {
        s += &format!("{}", f.len());
        for i in f {
            s += &format!(" {i}");
        }
        s += "\n";
    }
    s.into_bytes()
}

fn ply_binary(big: bool) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut b = ply_header(format).into_bytes();
    let f = |x: f32| {
        if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let i = |x: u32| {
        if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for (p, c) in PLY_VERTS {
        b.extend(p.iter().flat_map(|&x| f(x)));
        b.extend(c);
    }
    for face in PLY_FACES {
        b.push(face.len() as u8);
        b.extend(face.iter().flat_map(|&x| i(x)));
    }
    b
}

#[test]
fn binary_and_ascii_stl_load_the_same_cube() {
    let bin = Mesh::load(&temp("cube.stl", &binary_stl(&cube()))).unwrap();
    let ascii = Mesh::load(&temp("cube-ascii.stl", &ascii_stl(&cube()))).unwrap();
    assert_eq!(bin.triangle_count(), 12);
    assert_eq!(bin.positions.len(), 8, "shared corners are merged");
    assert_eq!(bin.positions, ascii.positions);
    assert_eq!(bin.indices, ascii.indices);
    assert!(
        bin.normals.is_empty(),
        "STL normals are generated, as for OBJ"
    );
    let mut m = bin;
    m.ensure_normals();
    assert_eq!(m.normals.len(), 8);
}

#[test]
fn ply_ascii_and_binary_load_the_same_triangles_and_colours() {
    let a = Mesh::load(&temp("c.ply", &ply_ascii())).unwrap();
    assert_eq!(
        a.triangle_count(),
        3,
        "a quad fan-triangulated, and a triangle"
    );
    assert_eq!(a.indices, [0, 1, 2, 0, 2, 3, 0, 1, 4]);
    assert_eq!(a.colors.len(), 5);
    assert_eq!(a.colors[0], glam::Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(a.colors[3], glam::Vec3::ONE);
    assert!(
        a.colors[4].x < 10.0 / 255.0,
        "8-bit colours are sRGB, stored linear"
    );
    for big in [false, true] {
        let b = Mesh::load(&temp(&format!("b{big}.ply"), &ply_binary(big))).unwrap();
        assert_eq!(a.positions, b.positions, "big endian: {big}");
        assert_eq!(a.indices, b.indices);
        assert_eq!(a.colors, b.colors);
    }
}

#[test]
fn ply_normals_and_float_colours() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
                property float red\nproperty float green\nproperty float blue\n\
                property float alpha\nelement face 1\nproperty list uchar uint vertex_index\n\
                end_header\n0 0 0 0 0 1 1 0 0 1\n1 0 0 0 0 1 0 1 0 1\n0 1 0 0 0 1 0 0 1 1\n\
                3 0 1 2\n";
    let m = Mesh::load(&temp("n.ply", text.as_bytes())).unwrap();
    assert_eq!(m.normals, vec![glam::Vec3::Z; 3]);
    assert_eq!(m.colors[1], glam::Vec3::Y);
}

#[test]
fn ply_face_out_of_range_names_file_and_line() {
    let text = String::from_utf8(ply_ascii())
        .unwrap()
        .replace("3 0 1 4", "3 0 1 9");
    let e = Mesh::load(&temp("bad.ply", text.as_bytes()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.ply:20:") && e.contains("vertex 9"), "{e}");
    let mut bin = ply_binary(false);
    let n = bin.len();
    bin[n - 4..].copy_from_slice(&99u32.to_le_bytes());
    let e = Mesh::load(&temp("badbin.ply", &bin))
        .unwrap_err()
        .to_string();
    assert!(e.contains("badbin.ply") && e.contains("vertex 99"), "{e}");
}

#[test]
fn format_is_told_by_content_before_extension() {
    let stl = binary_stl(&cube());
    assert_eq!(Format::detect(&stl, Path::new("x.obj")), Format::Stl);
    assert_eq!(
        Format::detect(&ascii_stl(&cube()), Path::new("x")),
        Format::Stl
    );
    assert_eq!(
        Format::detect(&ply_ascii(), Path::new("x.stl")),
        Format::Ply
    );
    assert_eq!(
        Format::detect(b"glTF\x02\0\0\0", Path::new("x.obj")),
        Format::Gltf
    );
    assert_eq!(
        Format::detect(b"v 0 0 0\n", Path::new("x.ply")),
        Format::Ply
    );
    assert_eq!(Format::detect(b"v 0 0 0\n", Path::new("x")), Format::Obj);
    // An OBJ whose first line is `solid` is still OBJ.
    assert_eq!(
        Format::detect(b"solid\nv 0 0 0\n", Path::new("x.obj")),
        Format::Obj
    );
    assert_eq!(
        Mesh::load(&temp("noext", &stl)).unwrap().triangle_count(),
        12
    );
    assert_eq!(
        Mesh::load(&temp("wrong.obj", &ply_binary(true)))
            .unwrap()
            .triangle_count(),
        3
    );
    let e = Mesh::load(&temp("m.glb", b"glTF\x02\0\0\0\0\0\0\0"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.glb") && e.contains("GLB"), "{e}");
}

#[test]
fn truncated_files_are_errors() {
    let stl = binary_stl(&cube());
    for cut in [0, 10, 83, 84, 100, stl.len() - 1] {
        let e = Mesh::load(&temp("cut.stl", &stl[..cut])).unwrap_err();
        assert!(e.to_string().contains("cut.stl"), "{e}");
    }
    let ascii = ascii_stl(&cube());
    let e = Mesh::load(&temp("cut-ascii.stl", &ascii[..ascii.len() / 2]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cut-ascii.stl:"),
        "ASCII errors give a line: {e}"
    );
    for data in [ply_ascii(), ply_binary(false), ply_binary(true)] {
        for cut in [3, data.len() / 2, data.len() - 3] {
            assert!(Mesh::load(&temp("cut.ply", &data[..cut])).is_err());
        }
    }
}

/// Loads `path` on another thread, failing the test if that takes more than 10 s.
fn load_within(path: &Path) -> Result<Mesh, MeshError> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = tx.send(Mesh::load(&p));
    });
    rx.recv_timeout(Duration::from_secs(10))
        .unwrap_or_else(|_| panic!("loading {} did not return", path.display()))
}

#[test]
fn non_regular_files_are_refused_at_once() {
    let dir = std::env::temp_dir().join(format!("termrast-formats-dir-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe.stl");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let mut paths = vec![dir.clone(), PathBuf::from("/dev/zero")];
    if made.is_ok_and(|s| s.success()) {
        paths.push(fifo.clone());
    }
    for p in &paths {
        let e = load_within(p).unwrap_err();
        assert!(matches!(e, MeshError::NotRegular { .. }), "{e}");
        assert!(e.to_string().contains(&p.display().to_string()), "{e}");
    }
    assert!(paths.len() == 3, "mkfifo is available on the test machines");
    // A material library that is a FIFO does not block the OBJ either.
    let obj = dir.join("m.obj");
    std::fs::write(
        &obj,
        "mtllib pipe.stl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let m = load_within(&obj).unwrap();
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("m.obj:1") && w.contains("FIFO")),
        "{:?}",
        m.warnings
    );
}

#[test]
fn render_draws_an_stl_to_png() {
    let stl = temp("render.stl", &binary_stl(&cube()));
    let png = stl.with_extension("png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args([
            "render",
            stl.to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ])
        .args(["--size", "64x48"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let p = Path::new("fuzz");
        let _ = stl::parse(&bytes, p);
        let _ = ply::parse(&bytes, p);
    }

    #[test]
    fn mutated_files_never_panic(
        which in 0usize..5,
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
        cut in any::<usize>(),
    ) {
        let mut data = match which {
            0 => binary_stl(&cube()),
            1 => ascii_stl(&cube()),
            2 => ply_ascii(),
            3 => ply_binary(false),
            _ => ply_binary(true),
        };
        for (at, b) in edits {
            let n = data.len();
            data[at % n] = b;
        }
        data.truncate(cut % (data.len() + 1) + data.len() / 2);
        let p = Path::new("fuzz");
        let _ = stl::parse(&data, p);
        let _ = ply::parse(&data, p);
    }
}

/// The cube's eight corners and twelve triangles as an indexed mesh (the same
/// triangles, in the same order and winding, as [`cube`]).
fn indexed_cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut corners: Vec<[f32; 3]> = Vec::new();
    let mut faces = Vec::new();
    for t in cube() {
        faces.push(t.map(|v| {
            let i = corners.iter().position(|c| *c == v).unwrap_or_else(|| {
                corners.push(v);
                corners.len() - 1
            });
            i as u32
        }));
    }
    (corners, faces)
}

/// The coverage (which pixels are drawn) and colours of a model's default scene.
fn frame_of(path: &Path) -> (Vec<bool>, Vec<[u8; 4]>) {
    use termrast::raster::Target;
    use termrast::scene::Scene;
    use termrast::scene::render::{SceneFrame, SceneView};
    let scene = Scene::for_model(path.to_str().unwrap()).unwrap();
    let mut frame = SceneFrame::new(&scene);
    let view = SceneView {
        yaw: 0.6,
        pitch: 0.4,
        pixel_aspect: 1.0,
        ..SceneView::default()
    };
    frame.draw(&scene, Target::new(96, 72), &view);
    let bg = frame.color.0[0];
    (
        frame.color.0.iter().map(|p| *p != bg).collect(),
        frame.color.0.clone(),
    )
}

#[test]
fn the_same_cube_in_every_format_draws_the_same_frame() {
    let (corners, faces) = indexed_cube();
    let mut obj = String::new();
    for c in &corners {
        obj += &format!("v {:?} {:?} {:?}\n", c[0], c[1], c[2]);
    }
    for f in &faces {
        obj += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            corners.len(),
            faces.len()
        )
    };
    let mut ply_text = header("ascii");
    for c in &corners {
        ply_text += &format!("{:?} {:?} {:?}\n", c[0], c[1], c[2]);
    }
    for f in &faces {
        ply_text += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    let mut ply_bin = header("binary_big_endian").into_bytes();
    for c in &corners {
        ply_bin.extend(c.iter().flat_map(|x| x.to_be_bytes()));
    }
    for f in &faces {
        ply_bin.push(3);
        ply_bin.extend(f.iter().flat_map(|i| i.to_be_bytes()));
    }
    let files = [
        temp("same.obj", obj.as_bytes()),
        temp("same.stl", &binary_stl(&cube())),
        temp("same-ascii.stl", &ascii_stl(&cube())),
        temp("same.ply", ply_text.as_bytes()),
        temp("same-bin.ply", &ply_bin),
    ];
    let (coverage, colours) = frame_of(&files[0]);
    assert!(coverage.iter().filter(|&&c| c).count() > 500);
    for f in &files[1..] {
        let (c, rgb) = frame_of(f);
        assert_eq!(c, coverage, "{}: coverage", f.display());
        // Normals are generated from the same corners; the sums may round apart.
        let worst = rgb
            .iter()
            .zip(&colours)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)))
            .max();
        assert!(
            worst <= Some(1),
            "{}: colours differ by {worst:?}",
            f.display()
        );
    }
}
