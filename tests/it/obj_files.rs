//! OBJ and MTL files as exporters write them: every defect the loader once had, each
//! with a file of its own, and the model drawn as its file describes it (colours per
//! material, textures, vertex colours).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use termrast::mesh::{Mesh, MeshError};
use termrast::raster::Target;
use termrast::scene::Scene;
use termrast::scene::render::{SceneFrame, SceneView};

/// A fresh directory per test, so libraries and textures do not meet.
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("termrast-obj-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn latin1_bom_cr_comments_and_continuations_load() {
    let d = dir("lines");
    let cases: [(&str, &[u8], usize); 6] = [
        (
            "latin1.obj",
            b"# caf\xe9 from 3ds Max\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            1,
        ),
        (
            "bom.obj",
            b"\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            1,
        ),
        ("cr.obj", b"v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", 1),
        (
            "crlf.obj",
            b"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
            1,
        ),
        (
            "comment.obj",
            b"v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3 # the face\n",
            1,
        ),
        (
            "cont.obj",
            b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 \\\n3 4\n",
            2,
        ),
    ];
    for (name, bytes, triangles) in cases {
        let m = Mesh::load(&write(&d, name, bytes)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangle_count(), triangles, "{name}");
        assert_eq!(
            m.positions[0],
            glam::Vec3::ZERO,
            "{name}: first vertex kept"
        );
        assert!(m.warnings.is_empty(), "{name}: {:?}", m.warnings);
    }
}

#[test]
fn material_problems_are_warnings_and_the_geometry_loads() {
    let d = dir("mtl");
    write(
        &d,
        "bad.mtl",
        b"newmtl\nKd 1 2\nnewmtl red\nKd 1 0 0\nKs 0.5\nnewmtl bare\nKd\nnewmtl l\xe9\nKd 0 0 1\n",
    );
    let obj = format!("mtllib bad.mtl\n{QUAD}usemtl red\nf 1 2 3\nusemtl bare\nf 1 3 4\n");
    let m = Mesh::load(&write(&d, "m.obj", obj.as_bytes())).unwrap();
    assert_eq!(m.triangle_count(), 2);
    assert_eq!(m.materials.len(), 2);
    assert_eq!(m.materials[0].diffuse, glam::Vec3::X);
    assert_eq!(m.materials[1].diffuse, glam::Vec3::ONE);
    let w = m.warnings.join("\n");
    assert!(w.contains("bad.mtl:2:") && w.contains("Kd"), "{w}");
    // The bare `Kd` on line 7 is the same kind: counted with the first.
    assert!(w.contains("once more"), "{w}");
    // Through the command line: warnings on stderr, a frame, exit 0.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args([
            "render",
            d.join("m.obj").to_str().unwrap(),
            "--size",
            "20x10",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains("bad.mtl:2:"),
        "{err}"
    );
}

#[test]
fn a_library_named_on_many_lines_is_read_once() {
    let d = dir("mtllib");
    write(&d, "a.mtl", b"newmtl a\nKd 0.5 0.5 0.5\n");
    let mut obj = "mtllib a.mtl\n".repeat(2000);
    obj += &format!("{QUAD}usemtl a\nf 1 2 3\n");
    let m = Mesh::load(&write(&d, "m.obj", obj.as_bytes())).unwrap();
    assert_eq!(m.materials.len(), 1);
    assert_eq!(m.materials[0].diffuse, glam::Vec3::splat(0.5));
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
}

#[test]
fn lines_points_and_short_faces_are_never_faces() {
    let d = dir("lines-points");
    let m = Mesh::load(&write(
        &d,
        "l.obj",
        format!("{QUAD}f 1 2 3\nl 1 2 3 4\nl 4 1\np 2\n").as_bytes(),
    ))
    .unwrap();
    assert_eq!(m.triangle_count(), 1);
    let w = m.warnings.join("\n");
    assert!(w.contains("l.obj:6: 2 polyline"), "{w}");
    assert!(w.contains("l.obj:8: 1 point"), "{w}");
    for (name, text, want) in [
        (
            "only-l.obj",
            format!("{QUAD}l 1 2 3\n"),
            "no triangles (only lines",
        ),
        ("short.obj", format!("{QUAD}f 1\nf 1 2\n"), "no triangles"),
    ] {
        let e = Mesh::load(&write(&d, name, text.as_bytes()))
            .unwrap_err()
            .to_string();
        assert!(e.contains(name) && e.contains(want), "{e}");
    }
}

#[test]
fn bad_attribute_indices_are_reported_once_with_the_line() {
    let d = dir("indices");
    let text = format!("{QUAD}vt 0 0\nvn 0 0 1\nf 1/1/1 2/7/1 3/1/9\nf 1/8 3/9 4/1\n");
    let m = Mesh::load(&write(&d, "i.obj", text.as_bytes())).unwrap();
    assert_eq!(m.triangle_count(), 2);
    let w = m.warnings.join("\n");
    assert!(
        w.contains("i.obj:7: a face's texture coordinate index"),
        "{w}"
    );
    assert!(w.contains("2 more times"), "{w}");
    assert!(w.contains("i.obj:7: a face's normal index"), "{w}");
    // Position indices are errors: nothing can stand in for a vertex.
    for (f, want) in [("f 1 2 0", "index 0"), ("f 1 2 -9", "does not exist")] {
        let e = Mesh::load(&write(&d, "e.obj", format!("{QUAD}{f}\n").as_bytes()))
            .unwrap_err()
            .to_string();
        assert!(e.contains("e.obj:5:") && e.contains(want), "{e}");
    }
    // Vertices after the faces that use them are accepted.
    let late = Mesh::load(&write(
        &d,
        "late.obj",
        b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
    ))
    .unwrap();
    assert_eq!(late.triangle_count(), 1);
    // An index no file of this size could reach is refused before anything is sized.
    let huge = Mesh::load(&write(&d, "huge.obj", b"v 0 0 0\nf 1 1 4000000000\n")).unwrap_err();
    assert!(huge.to_string().contains("does not exist"), "{huge}");
}

/// The share of a frame's pixels that are not the background.
fn covered(scene: &Scene) -> f64 {
    let mut frame = SceneFrame::new(scene);
    let view = SceneView {
        time: 0.0,
        pixel_aspect: 1.0,
        ..SceneView::default()
    };
    frame.draw(scene, Target::new(64, 64), &view);
    let bg = frame.color.0[0];
    frame.color.0.iter().filter(|p| **p != bg).count() as f64 / 4096.0
}

#[test]
fn huge_and_tiny_models_are_normalised_and_drawn() {
    let d = dir("scale");
    let shape = |s: f64| {
        format!(
            "v {} {} 0\nv {} {} 0\nv {} {} 0\nv {} {} 0\nf 1 2 3 4\n",
            -s, -s, s, -s, s, s, -s, s
        )
    };
    let reference = covered(
        &Scene::for_model(
            write(&d, "one.obj", shape(1.0).as_bytes())
                .to_str()
                .unwrap(),
        )
        .unwrap(),
    );
    assert!(reference > 0.1, "{reference}");
    for (name, s) in [
        ("huge.obj", 2e38),
        ("tiny.obj", 1e-40),
        ("beyond.obj", 1e300),
    ] {
        let p = write(&d, name, shape(s).as_bytes());
        let mut m = Mesh::from_spec(p.to_str().unwrap()).unwrap();
        m.normalize();
        let max = m
            .positions
            .iter()
            .map(|p| p.abs().max_element())
            .fold(0.0, f32::max);
        assert_eq!(max, 1.0, "{name}");
        let c = covered(&Scene::for_model(p.to_str().unwrap()).unwrap());
        assert_eq!(c, reference, "{name}: the same square as at scale 1");
    }
}

/// A 2×2 JPEG (or PNG) image of one colour.
fn image_file(dir: &Path, name: &str, rgb: [u8; 3], format: image::ImageFormat) -> PathBuf {
    let img = image::RgbImage::from_pixel(8, 8, image::Rgb(rgb));
    let p = dir.join(name);
    img.save_with_format(&p, format).unwrap();
    p
}

/// The mean colour of the drawn pixels.
fn mean_color(scene: &Scene) -> [f64; 3] {
    let mut frame = SceneFrame::new(scene);
    frame.draw(
        scene,
        Target::new(64, 64),
        &SceneView {
            pixel_aspect: 1.0,
            ..SceneView::default()
        },
    );
    let bg = frame.color.0[0];
    let drawn: Vec<_> = frame.color.0.iter().filter(|p| **p != bg).collect();
    assert!(!drawn.is_empty());
    let mut sum = [0.0; 3];
    for p in &drawn {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    sum.map(|s| s / drawn.len() as f64)
}

/// A square facing the camera, textured, with its material in `mtl`.
fn textured_square(d: &Path, mtl: &str) -> PathBuf {
    write(d, "t.mtl", mtl.as_bytes());
    write(
        d,
        "t.obj",
        format!(
            "mtllib t.mtl\n{QUAD}vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3 4/4\n"
        )
        .as_bytes(),
    )
}

#[test]
fn a_jpeg_texture_behind_windows_separators_is_drawn() {
    let d = dir("jpeg");
    std::fs::create_dir_all(d.join("maps")).unwrap();
    image_file(
        &d.join("maps"),
        "Red.JPG",
        [230, 20, 20],
        image::ImageFormat::Jpeg,
    );
    let obj = textured_square(&d, "newmtl t\nKd 1 1 1\nmap_Kd -s 1 1 1 .\\maps\\red.jpg\n");
    let m = Mesh::load(&obj).unwrap();
    let w = m.warnings.join("\n");
    assert!(
        w.contains("t.mtl:3:") && w.contains("Red.JPG"),
        "case fallback said: {w}"
    );
    let scene = Scene::for_model(obj.to_str().unwrap()).unwrap();
    let [r, g, b] = mean_color(&scene);
    assert!(
        r > 2.0 * g && r > 2.0 * b && r > 60.0,
        "red texture: {r} {g} {b}"
    );
    // A texture that is not there: the square, white, and a warning.
    let obj = textured_square(&d, "newmtl t\nmap_Kd C:\\Users\\me\\nothere.png\n");
    let scene = Scene::for_model(obj.to_str().unwrap()).unwrap();
    assert!(
        scene.warnings.join("\n").contains("nothere.png"),
        "{:?}",
        scene.warnings
    );
    let [r, g, b] = mean_color(&scene);
    assert!(
        (r - g).abs() < 1.0 && (g - b).abs() < 1.0,
        "white: {r} {g} {b}"
    );
}

#[test]
fn each_material_keeps_its_colour_and_vertex_colours_are_lit() {
    let d = dir("kd");
    write(
        &d,
        "c.mtl",
        b"newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n",
    );
    // Two groups side by side, each with its material.
    let obj = "mtllib c.mtl\nv -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\nv 0 -1 0\nv 1 -1 0\nv 1 1 0\nv 0 1 0\n\
               g left\nusemtl red\nf 1 2 3 4\ng right\nusemtl blue\nf 5 6 7 8\n";
    let p = write(&d, "two.obj", obj.as_bytes());
    let scene = Scene::for_model(p.to_str().unwrap()).unwrap();
    assert_eq!(scene.objects.len(), 2);
    let mut frame = SceneFrame::new(&scene);
    frame.draw(
        &scene,
        Target::new(64, 64),
        &SceneView {
            pixel_aspect: 1.0,
            ..SceneView::default()
        },
    );
    let px = |x: usize, y: usize| frame.color.0[y * 64 + x];
    let (left, right) = (px(20, 32), px(44, 32));
    assert!(left[0] > 100 && left[1] < 10 && left[2] < 10, "{left:?}");
    assert!(
        right[2] > 100 && right[0] < 10 && right[1] < 10,
        "{right:?}"
    );
    // The same file through a scene without from_model: white, as declared.
    let toml = format!(
        "[[object]]\nmodel = {:?}\n[object.material]\nlighting = \"lambert\"\n",
        p.to_str().unwrap()
    );
    let plain = Scene::from_text(&toml, &d.join("s.toml")).unwrap();
    assert_eq!(plain.objects.len(), 1);
    let [r, g, b] = mean_color(&plain);
    assert!((r - g).abs() < 1.0 && (g - b).abs() < 1.0, "{r} {g} {b}");
    // Vertex colours (`v x y z r g b`), lit by default.
    let green = write(
        &d,
        "vc.obj",
        b"v 0 0 0 0 1 0\nv 1 0 0 0 1 0\nv 1 1 0 0 1 0\nv 0 1 0 0 1 0\nf 1 2 3 4\n",
    );
    let [r, g, b] = mean_color(&Scene::for_model(green.to_str().unwrap()).unwrap());
    assert!(g > 60.0 && r < 5.0 && b < 5.0, "{r} {g} {b}");
}

#[test]
fn limits_are_clear_and_overridable() {
    let d = dir("limits");
    let p = write(&d, "m.obj", format!("{QUAD}f 1 2 3\n").as_bytes());
    let run = |limit: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
            .args(["render", p.to_str().unwrap(), "--size", "8x8"])
            .env("TERMRAST_MAX_MODEL_BYTES", limit)
            .output()
            .unwrap()
    };
    let small = run("20");
    let err = String::from_utf8_lossy(&small.stderr);
    assert!(
        !small.status.success() && err.contains("TERMRAST_MAX_MODEL_BYTES"),
        "{err}"
    );
    assert!(run("1K").status.success());
    // Eighty of the largest spheres: refused before any is generated.
    let toml = "[[object]]\nmodel = \"sphere:4194304\"\n".repeat(80);
    let e = Scene::from_text(&toml, Path::new("many.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("many.toml") && e.contains("triangles in all"),
        "{e}"
    );
    // A texture or library that is a FIFO or a directory: a warning, never a wait.
    std::fs::create_dir_all(d.join("dir.mtl")).unwrap();
    let m = Mesh::load(&write(
        &d,
        "dir.obj",
        format!("mtllib dir.mtl\n{QUAD}f 1 2 3\n").as_bytes(),
    ))
    .unwrap();
    assert!(
        m.warnings.join("\n").contains("a directory"),
        "{:?}",
        m.warnings
    );
}

fn obj_with_materials() -> Vec<u8> {
    format!(
        "mtllib fuzz.mtl\n# c\n{QUAD}vt 0 0\nvt 1 1\nvn 0 0 1\no a\nusemtl red\nf 1/1/1 2/2/1 3/1/1\ng b\nusemtl blue\nf -4//1 -2//1 -1//1\nl 1 2\nf 1 2 3 4 \\\n 1\n"
    )
    .into_bytes()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Mutated OBJ and MTL bytes: a model or an error, never a panic.
    #[test]
    fn mutated_obj_and_mtl_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
        mtl_edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..8),
        cut in any::<usize>(),
    ) {
        let d = std::env::temp_dir().join(format!("termrast-obj-{}-fuzz", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let mut obj = obj_with_materials();
        for (at, b) in edits {
            let i = at % obj.len();
            obj[i] = b;
        }
        obj.truncate(cut % (obj.len() + 1));
        let mut mtl = b"newmtl red\nKd 1 0 0\nmap_Kd -s 1 1 1 r.png\nnewmtl blue\nKd 0 0 1\n".to_vec();
        for (at, b) in mtl_edits {
            let i = at % mtl.len();
            mtl[i] = b;
        }
        write(&d, "fuzz.mtl", &mtl);
        let p = write(&d, "fuzz.obj", &obj);
        match Mesh::load(&p) {
            Ok(m) => {
                prop_assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
                prop_assert!(m.triangle_materials.is_empty() || m.triangle_materials.len() == m.triangle_count());
                let _ = m.split_by_material();
            }
            Err(e) => prop_assert!(e.to_string().contains("fuzz.obj"), "{}", e),
        }
    }
}

#[test]
fn errors_still_name_the_line() {
    let d = dir("errors");
    for (text, line) in [
        ("v 0 0\n", ":1:"),
        ("v 0 0 0\nvt x\n", ":2:"),
        ("vn 1 2\n", ":1:"),
    ] {
        let e = Mesh::load(&write(&d, "e.obj", text.as_bytes())).unwrap_err();
        assert!(matches!(e, MeshError::Malformed { .. }), "{e}");
        assert!(e.to_string().contains(line), "{e}");
    }
}

#[test]
fn a_scene_file_that_is_not_a_regular_file_is_refused_at_once() {
    let d = dir("scene-fifo");
    let fifo = d.join("s.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(
        made.is_ok_and(|s| s.success()),
        "mkfifo is available on the test machines"
    );
    let (tx, rx) = std::sync::mpsc::channel();
    let p = fifo.clone();
    std::thread::spawn(move || tx.send(Scene::load(&p).map(|_| ()).map_err(|e| e.to_string())));
    let e = rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("refused at once, not blocked")
        .unwrap_err();
    assert!(e.contains("s.toml") && e.contains("FIFO"), "{e}");
    let e = Scene::load(&d).map(|_| ()).unwrap_err().to_string();
    assert!(e.contains("a directory"), "{e}");
}
