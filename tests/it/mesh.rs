//! OBJ loading: good files, and clear errors (file and line) for bad ones.

use std::io::Write;
use std::path::PathBuf;

use termrast::mesh::{Mesh, MeshError};

fn temp_obj(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("termrast-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::File::create(&path)
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    path
}

#[test]
fn loads_triangulates_and_normalises() {
    let p = temp_obj(
        "quad.obj",
        "v 0 0 0\nv 4 0 0\nv 4 2 0\nv 0 2 0\nf 1 2 3 4\n",
    );
    let mut m = Mesh::from_spec(p.to_str().unwrap()).unwrap();
    assert_eq!(m.triangle_count(), 2);
    assert!(m.normals.is_empty(), "no normals in the file");
    let max = m
        .positions
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f32::max);
    assert_eq!(max, 1.0);
    m.ensure_normals();
    assert!(
        m.normals.iter().all(|n| (n.z - 1.0).abs() < 1e-6),
        "{:?}",
        m.normals
    );
}

#[test]
fn builtins() {
    let t = Mesh::teapot();
    assert_eq!((t.positions.len(), t.triangle_count()), (792, 992));
    let s = Mesh::uv_sphere(65_536);
    assert!(
        (60_000..70_000).contains(&s.triangle_count()),
        "{}",
        s.triangle_count()
    );
    assert!(
        s.normals
            .iter()
            .zip(&s.positions)
            .all(|(n, p)| (*n - *p).length() < 1e-6)
    );
    assert!(matches!(
        Mesh::from_spec("sphere:lots"),
        Err(MeshError::UnknownBuiltin(_))
    ));
}

#[test]
fn errors_name_the_file_and_line() {
    let cases = [
        (
            "badv.obj",
            "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
            ":2:",
            "vertex",
        ),
        (
            "badf.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n# c\nf 1 2 9\n",
            ":5:",
            "does not exist",
        ),
        (
            "nan.obj",
            "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
            ":2:",
            "finite",
        ),
    ];
    for (name, text, line, what) in cases {
        let p = temp_obj(name, text);
        let e = Mesh::load(&p).unwrap_err().to_string();
        assert!(
            e.contains(name) && e.contains(line) && e.contains(what),
            "{name}: {e}"
        );
    }
    let empty = temp_obj("empty.obj", "# nothing\nv 0 0 0\n");
    assert!(
        Mesh::load(&empty)
            .unwrap_err()
            .to_string()
            .contains("no triangles")
    );
    let missing = Mesh::load(std::path::Path::new("/nonexistent/model.obj")).unwrap_err();
    assert!(missing.to_string().contains("/nonexistent/model.obj"));
}

#[test]
fn render_command_reports_bad_models() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args([
            "render",
            "/nonexistent/x.obj",
            "--out",
            "/tmp/termrast-never.png",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/x.obj"), "{err}");
}

#[test]
fn render_writes_a_png() {
    let path = std::env::temp_dir().join(format!("termrast-{}.png", std::process::id()));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(["render", "--size", "64x48", "--out", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let _ = std::fs::remove_file(path);
}
