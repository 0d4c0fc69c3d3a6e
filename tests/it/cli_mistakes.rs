//! Mistakes on the command line get a message that says what is wrong, through the
//! real binary: a mistyped subcommand, a file that is not a model, an unsupported
//! `--out`, `--threads`, and lines too long to show.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// Runs the binary in `dir` (so relative names resolve there) with stdin closed and
/// a terminal type the viewer accepts (it then fails on its model, or on stdin).
fn run_in(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out: Output = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(args)
        .current_dir(dir)
        .env("TERM", "xterm")
        .stdin(std::process::Stdio::null())
        .output()
        .expect("binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("termrast-mistakes-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_mistyped_subcommand_is_suggested() {
    let dir = scratch("subcommand");
    // Nothing else on the line: it could have been a model file, so both are said.
    let (code, _, err) = run_in(&dir, &["rastr"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("no file `rastr`; did you mean the subcommand `raster`?"),
        "{err}"
    );
    assert!(!err.contains("No such file"), "{err}");
    assert!(err.contains("Usage:"), "clap-style: {err}");
    // Followed by what only a subcommand takes: a subcommand.
    let (code, _, err) = run_in(&dir, &["rendr", "--out", "x.png"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("unrecognized subcommand `rendr`; did you mean `render`?"),
        "{err}"
    );
    assert!(!dir.join("x.png").exists());
    let (code, _, err) = run_in(&dir, &["bnech", "render"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("did you mean `bench`?"), "{err}");
    // A prefix of two subcommands names both.
    let (code, _, err) = run_in(&dir, &["r"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("`raster` or `render`"), "{err}");
}

#[test]
fn a_file_or_model_that_resembles_a_subcommand_is_not_second_guessed() {
    let dir = scratch("files");
    // An existing file named like a subcommand is a model: it is read (and here
    // refused for having no triangles), not taken for `render`.
    std::fs::write(dir.join("rendr"), "# nothing\n").unwrap();
    let (code, _, err) = run_in(
        &dir,
        &["render", "rendr", "--size", "8x8", "--out", "o.png"],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("rendr: no triangles"), "{err}");
    let (code, _, err) = run_in(&dir, &["rendr", "--color", "none"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("rendr: no triangles"), "{err}");
    // A missing file far from every subcommand keeps the plain message.
    let (code, _, err) = run_in(&dir, &["missing-model.obj"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("missing-model.obj: No such file"), "{err}");
}

#[test]
fn a_file_that_is_not_a_model_says_what_it_looks_like() {
    let dir = scratch("not-obj");
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01";
    let cases: [(&str, &[u8], &str); 5] = [
        (
            "x.png",
            png,
            "x.png: not an OBJ file: it looks like a PNG image",
        ),
        (
            "x.gz",
            b"\x1f\x8b\x08\0\0\0\0\0",
            "it looks like a gzip file",
        ),
        (
            "x.zip",
            b"PK\x03\x04\x14\0\0\0",
            "it looks like a ZIP archive",
        ),
        (
            "x.stl",
            b"solid cube\nfacet normal 0 0 1\nendfacet\nendsolid\n",
            "x.stl:2: STL facet 1:",
        ),
        (
            "x.bin",
            b"v 0 0 0\n\xc3\x28\n",
            "x.bin: not an OBJ file: it is not text (byte 8 is not UTF-8)",
        ),
    ];
    for (name, bytes, want) in cases {
        std::fs::write(dir.join(name), bytes).unwrap();
        for cmd in [
            &["render", name][..],
            &["bench", "render", name, "--frames", "1"][..],
        ] {
            let (code, _, err) = run_in(&dir, cmd);
            assert_eq!(code, Some(1), "{cmd:?}: {err}");
            assert!(err.contains(want), "{cmd:?}: {err}");
            assert!(!err.contains("valid UTF-8"), "{cmd:?}: {err}");
        }
    }
}

#[test]
fn bench_render_explains_it_takes_a_model_not_a_scene() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/minimal.toml");
    let scene = scene.to_str().unwrap();
    let (code, _, err) = run_in(Path::new("."), &["bench", "render", scene, "--frames", "1"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("bench render times a model") && err.contains("not a scene file"),
        "{err}"
    );
    assert!(err.contains(&format!("termrast render {scene}")), "{err}");
}

#[test]
fn threads_takes_a_count_from_one() {
    let dir = scratch("threads");
    let (code, out, err) = run_in(&dir, &["bench", "render", "--help"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("the machine's cores"), "{out}");
    for bad in ["0", "two", "1000"] {
        let (code, _, err) = run_in(
            &dir,
            &["bench", "render", "--threads", bad, "--frames", "1"],
        );
        assert_eq!(code, Some(2), "{bad}: {err}");
        assert!(err.contains("threads"), "{bad}: {err}");
    }
    for n in ["1", "2"] {
        let args = [
            "bench",
            "render",
            "--threads",
            n,
            "--frames",
            "1",
            "--size",
            "32x32",
        ];
        let (code, out, err) = run_in(&dir, &args);
        assert_eq!(code, Some(0), "{err}");
        assert!(out.contains(&format!("threads={n}")), "{out}");
    }
}

/// `bench render --pause-ms` waits at most a second before each frame (so a long
/// run cannot be asked for by a slip of the keyboard); with `--measured` the frames
/// are timed as the viewer's are.
#[test]
fn bench_pause_is_bounded() {
    let dir = scratch("pause");
    for bad in ["1001", "-1", "soon"] {
        let pause = format!("--pause-ms={bad}");
        let args = ["bench", "render", &pause, "--frames", "1"];
        let (code, _, err) = run_in(&dir, &args);
        assert_eq!(code, Some(2), "{bad}: {err}");
        assert!(err.contains("--pause-ms"), "{bad}: {err}");
    }
    let args = [
        "bench",
        "render",
        "--pause-ms",
        "1",
        "--measured",
        "--threads",
        "2",
        "--frames",
        "8",
        "--size",
        "32x32",
    ];
    let (code, out, err) = run_in(&dir, &args);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("threads=2"), "{out}");
}

#[test]
fn render_out_in_an_unsupported_format_leaves_no_file() {
    let dir = scratch("out");
    for (name, want) in [
        (
            "x.jpg",
            "x.jpg: --out writes PNG images only, not `.jpg`; name the file `x.png`",
        ),
        (
            "x",
            "x: --out writes PNG images only; name the file `x.png`",
        ),
    ] {
        let (code, _, err) = run_in(&dir, &["render", "--size", "16x16", "--out", name]);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains(want), "{err}");
        assert!(!dir.join(name).exists(), "{name} was left behind");
    }
    let (code, _, err) = run_in(&dir, &["render", "--size", "16x16", "--out", "x.PNG"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.join("x.PNG").metadata().unwrap().len() > 0);
}

/// Runs `termrast line ARGS` under a 1 GB address-space limit: a line too long to
/// show must be refused before it is walked, at once.
fn line_bounded(args: &[&str]) -> (Option<i32>, String, String, Duration) {
    let start = Instant::now();
    let out = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" line \"$@\"")
        .arg(env!("CARGO_BIN_EXE_termrast"))
        .args(args)
        .output()
        .expect("sh runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        start.elapsed(),
    )
}

#[test]
fn line_checks_its_sizes_before_it_walks() {
    for (args, want) in [
        (
            &["0", "0", "1000000000", "1", "--trace"][..],
            "the line has 1000000001 pixels; --trace shows at most 1000000",
        ),
        (
            &["0", "0", "1000000000", "1", "--format", "cells"][..],
            "the line has 1000000001 pixels; --format cells shows at most 1000000",
        ),
        (
            &["0", "0", "0", "1000000000"][..],
            "the grid would be 1×1000000001 cells",
        ),
        (
            &["-9223372036854775808", "0", "0", "0"][..],
            "coordinate -9223372036854775808 is out of range: line coordinates must be within ±2^40",
        ),
    ] {
        let (code, out, err, took) = line_bounded(args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert!(took < Duration::from_secs(10), "{args:?} took {took:?}");
    }
    // The limit is on what is shown: with --size only the pixels inside count.
    let (code, out, err, _) =
        line_bounded(&["0", "0", "1000000000", "1", "--size", "8x2", "--trace"]);
    assert_eq!(code, Some(0), "{err}");
    let steps = out.lines().filter(|l| {
        l.split_whitespace()
            .next()
            .is_some_and(|w| w.parse::<u32>().is_ok())
    });
    assert_eq!(steps.count(), 8, "{out}");
    assert!(out.ends_with("########\n........\n"), "{out}");
    // At the limit a listed line still works.
    let (code, out, err, _) = line_bounded(&["0", "0", "999999", "0", "--format", "cells"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.starts_with("0,0 1,0 ") && out.ends_with(" 999999,0\n"));
    let (code, out, err, _) = line_bounded(&["0", "4", "4", "2"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(out, "origin (0,2)\n....#\n..##.\n##...\n");
}
