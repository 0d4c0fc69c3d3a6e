//! `termrast raster`, `render`, `line` and `bench render` end to end, through the real binary.

use std::io::Write;
use std::process::{Command, Stdio};

use termrast::render::Isa;

fn raster(args: &[&str], stdin: &str) -> (bool, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .arg("raster")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn grid_of_the_split_square() {
    let input = "0 0 5 0 5 5\n# comment\n\n0 0 5 5 0 5\n";
    for t in ["scalar", "planes", "block", "wide"] {
        let (ok, out, err) = raster(
            &["--size", "6x6", "--traversal", t, "--format", "counts"],
            input,
        );
        assert!(ok, "{err}");
        assert_eq!(
            out, "11111.\n11111.\n11111.\n11111.\n11111.\n......\n",
            "{t}"
        );
    }
    let (_, grid, _) = raster(&["--size", "6x3"], input);
    assert_eq!(grid, "#####.\n#####.\n#####.\n");
}

#[test]
fn cells_lists_each_triangle_on_its_own_line() {
    let (ok, out, _) = raster(
        &["--size", "4x4", "--format", "cells"],
        "0 0 3 0 0 3\nnan 0 1 1 2 2\n1 1 4 1 1 4\n",
    );
    assert!(ok);
    assert_eq!(out, "0,0 1,0 0,1\n\n1,1 2,1 1,2\n");
}

#[test]
fn counts_show_overlap() {
    // The centre (2.5, 0.5) lies on the hypotenuse, a bottom-right edge: not covered.
    let (_, out, _) = raster(
        &["--size", "3x1", "--format", "counts"],
        "0 0 3 0 0 3\n0 0 3 0 0 3\n",
    );
    assert_eq!(out, "22.\n");
}

#[test]
fn bad_lines_name_the_line_and_fail() {
    let (ok, out, err) = raster(&["--size", "4x4"], "0 0 1 1 2 2\n\n1 2 3 x 5 6\n");
    assert!(!ok);
    assert!(out.is_empty());
    assert!(
        err.contains("line 3") && err.contains("`x` is not a number"),
        "{err}"
    );
    let (ok, _, err) = raster(&["--size", "4x4"], "1 2 3\n");
    assert!(
        !ok && err.contains("line 1") && err.contains("found 3"),
        "{err}"
    );
}

#[test]
fn bad_arguments_are_explained() {
    for (size, needle) in [
        ("80", "not WxH"),
        ("0x5", "between 1 and"),
        ("ax5", "not a whole number"),
    ] {
        let (ok, _, err) = raster(&["--size", size], "");
        assert!(!ok && err.contains(needle), "{size}: {err}");
    }
    let (ok, _, err) = raster(&["--traversal", "fast"], "");
    assert!(!ok && err.contains("scalar"), "{err}");
    for command in ["render", "bench render"] {
        let mut args: Vec<&str> = command.split(' ').collect();
        args.extend(["--frames", "0"]);
        let (ok, _, err) = termrast(&args);
        assert!(
            !ok && err.contains("'0'") && err.contains("--frames"),
            "{command}: {err}"
        );
    }
}

#[test]
fn the_viewer_refuses_a_pipe_and_suggests_render() {
    let out = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("not a terminal") && err.contains("termrast render"),
        "{err}"
    );
}

#[test]
fn render_writes_text_frames() {
    for (glyphs, is_ink) in [
        (
            "braille",
            (|c| ('\u{2801}'..='\u{28FF}').contains(&c) || "░▒▓█".contains(c)) as fn(char) -> bool,
        ),
        ("blocks", |c| {
            ('\u{2580}'..='\u{259F}').contains(&c) || c >= '\u{1FB00}'
        }),
    ] {
        let (ok, out, err) = termrast(&[
            "render", "--cols", "40", "--rows", "12", "--color", "none", "--frames", "2",
            "--glyphs", glyphs,
        ]);
        assert!(ok, "{err}");
        // Each frame is 12 lines (trailing blank cells are not written), then a blank
        // line between frames.
        let lines: Vec<&str> = out.strip_suffix('\n').unwrap_or(&out).split('\n').collect();
        assert_eq!(lines.len(), 2 * 12 + 1, "{out}");
        assert_eq!(lines[12], "", "frames are separated by a blank line");
        for f in [&lines[..12], &lines[13..]] {
            assert!(f.iter().all(|l| l.chars().count() <= 40));
            let ink = f
                .iter()
                .flat_map(|l| l.chars())
                .filter(|&c| is_ink(c))
                .count();
            assert!(
                ink > 50,
                "the teapot is drawn in {glyphs}:\n{}",
                f.join("\n")
            );
        }
    }
    let (ok, out, _) = termrast(&[
        "render",
        "--cols",
        "20",
        "--rows",
        "6",
        "--color",
        "truecolor",
        "--glyphs",
        "half",
    ]);
    assert!(ok && out.contains("\u{1b}[38;2;") && out.contains('▀'));
}

/// A reader that goes away (`termrast render … | head -1`) ends the command quietly,
/// with the status of a command ended by `SIGPIPE`.
#[test]
fn render_ends_quietly_when_its_reader_goes() {
    use std::io::{BufRead, BufReader};

    let mut child = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(["render", "--cols", "40", "--rows", "10", "--frames", "500"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    let mut first = String::new();
    let mut lines = BufReader::new(child.stdout.take().expect("piped"));
    lines.read_line(&mut first).expect("a first line");
    assert!(!first.is_empty());
    drop(lines);
    let out = child.wait_with_output().expect("it ends");
    assert_eq!(out.status.code(), Some(141), "{out:?}");
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
}

fn termrast(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_termrast"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn line_command_traces_the_worked_example() {
    let (ok, out, err) = termrast(&["line", "5", "8", "9", "11", "--trace", "--format", "cells"]);
    assert!(ok, "{err}");
    assert!(out.contains("dx=4 dy=3 incrE=6 incrNE=-2 d0=2"), "{out}");
    let rows: Vec<(String, String)> = out
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w.len() == 5 && w[0].parse::<u32>().is_ok())
                .then(|| (w[2].to_string(), w[3].to_string()))
        })
        .collect();
    let want = [("2", "NE"), ("0", "E"), ("6", "NE"), ("4", "NE")];
    assert_eq!(rows.len(), 4, "{out}");
    for (r, w) in rows.iter().zip(want) {
        assert_eq!((r.0.as_str(), r.1.as_str()), w);
    }
    assert!(out.trim_end().ends_with("5,8 6,9 7,9 8,10 9,11"), "{out}");
    let (_, grid, _) = termrast(&["line", "0", "4", "4", "2"]);
    assert_eq!(grid, "origin (0,2)\n....#\n..##.\n##...\n");
}

#[test]
fn line_command_rejects_bad_input() {
    let (ok, _, err) = termrast(&["line", "1", "2", "x", "4"]);
    assert!(!ok && err.contains("invalid value 'x'"), "{err}");
    let (ok, _, err) = termrast(&["line", "0", "0", "5000", "0"]);
    assert!(!ok && err.contains("--format cells"), "{err}");
    let (ok, _, err) = termrast(&["line", "0", "0", "9999999999999", "0", "--format", "cells"]);
    assert!(!ok && err.contains("2^40"), "{err}");
    let (ok, out, _) = termrast(&[
        "line", "-1000000", "-2", "1000000", "3", "--size", "8x4", "--format", "cells",
    ]);
    assert!(ok);
    // At x = 0 the ideal y is exactly 0.5: a tie, resolved toward the start's row (0);
    // from x = 1 on it is above 0.5.
    assert_eq!(out, "0,0 1,1 2,1 3,1 4,1 5,1 6,1 7,1\n");
}

/// The value of `key=value` in a `bench render` report.
fn report_field(out: &str, key: &str) -> String {
    out.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
        .map(str::to_owned)
        .unwrap_or_else(|| panic!("no {key} in {out}"))
}

/// `bench render` runs on the instruction set it is given, reports it, and covers the
/// same fragments on each; it refuses a name it does not know and one the CPU lacks.
#[test]
fn bench_render_reports_and_checks_its_instruction_set() {
    let mut covered = Vec::new();
    for isa in Isa::supported() {
        let (ok, out, err) = termrast(&[
            "bench",
            "render",
            "teapot",
            "--size",
            "96x64",
            "--frames",
            "2",
            "--isa",
            isa.name(),
        ]);
        assert!(ok, "{err}");
        assert_eq!(report_field(&out, "isa"), isa.name());
        covered.push(report_field(&out, "covered_px"));
    }
    assert!(covered.windows(2).all(|w| w[0] == w[1]), "{covered:?}");
    assert_ne!(covered[0], "0");
    // The AVX-512 copy is built for the `wide` traversal only; others run and report AVX2.
    if Isa::Avx512.is_supported() {
        let (ok, out, err) = termrast(&[
            "bench",
            "render",
            "--size",
            "64x32",
            "--frames",
            "1",
            "--isa",
            "avx512",
            "--traversal",
            "scalar",
        ]);
        assert!(ok, "{err}");
        assert_eq!(report_field(&out, "isa"), "avx2");
    }
    let (ok, _, err) = termrast(&["bench", "render", "--frames", "1", "--isa", "sse9"]);
    assert!(!ok && err.contains("baseline, avx2, avx512"), "{err}");
    if let Some(missing) = Isa::ALL.into_iter().find(|isa| !isa.is_supported()) {
        let (ok, _, err) = termrast(&["bench", "render", "--frames", "1", "--isa", missing.name()]);
        assert!(!ok && err.contains("cannot run"), "{err}");
    }
}

/// `bench render` names the shading it drew with: the sphere in its vertex colours,
/// or with `--no-vertex-colors` white, covering the same fragments.
#[test]
fn bench_render_names_its_shading_and_can_leave_vertex_colours_out() {
    let run = |model: &str, extra: &[&str]| {
        let mut args = vec!["bench", "render", model, "--size", "96x64", "--frames", "2"];
        args.extend(extra);
        let (ok, out, err) = termrast(&args);
        assert!(ok, "{err}");
        (
            report_field(&out, "shading"),
            report_field(&out, "covered_px"),
        )
    };
    let (coloured, covered) = run("sphere:2000", &[]);
    assert_eq!(coloured, "lambert-colors");
    assert_ne!(covered, "0");
    let white = run("sphere:2000", &["--no-vertex-colors"]);
    assert_eq!(white, ("lambert".to_owned(), covered));
    // The teapot has no vertex colours: the flag changes nothing.
    let teapot = run("teapot", &[]);
    assert_eq!(teapot.0, "lambert");
    assert_eq!(run("teapot", &["--no-vertex-colors"]), teapot);
}

/// `bench render --compare` draws with each thread count in turn, round by round, and
/// sums up each count's medians and its speed-up over the first; it refuses
/// `--threads` beside it and `--rounds` without it.
#[test]
fn bench_render_compares_thread_counts_round_by_round() {
    let (ok, out, err) = termrast(&[
        "bench",
        "render",
        "teapot",
        "--size",
        "96x64",
        "--frames",
        "2",
        "--compare",
        "1,2,3",
        "--rounds",
        "2",
    ]);
    assert!(ok, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    let medians = |line: &str| -> Vec<(usize, f64)> {
        let words: Vec<&str> = line.split_whitespace().collect();
        words
            .windows(2)
            .filter_map(|w| {
                let t = w[0].strip_prefix("threads=")?.parse().ok()?;
                let m = w[1].strip_prefix("median_ms=")?;
                Some((t, m.split('-').next()?.parse().ok()?))
            })
            .collect()
    };
    for (r, line) in lines[..2].iter().enumerate() {
        assert!(line.starts_with(&format!("round {}:", r + 1)), "{line}");
        let m = medians(line);
        assert_eq!(
            m.iter().map(|m| m.0).collect::<Vec<_>>(),
            [1, 2, 3],
            "{line}"
        );
        assert!(m.iter().all(|m| m.1 > 0.0), "{line}");
        assert_eq!(
            line.matches("x)").count(),
            2,
            "a ratio per later count: {line}"
        );
    }
    let all = lines[2];
    assert!(all.starts_with("all:"), "{all}");
    assert_eq!(medians(all).len(), 3, "{all}");
    let speedups: Vec<f64> = all
        .split_whitespace()
        .filter_map(|w| w.strip_prefix("speedup=")?.strip_suffix('x')?.parse().ok())
        .collect();
    assert_eq!(speedups.len(), 2, "{all}");
    assert!(speedups.iter().all(|&s| s > 0.0 && s.is_finite()), "{all}");
    let (ok, _, err) = termrast(&["bench", "render", "--compare", "1,2", "--threads", "2"]);
    assert!(!ok && err.contains("--threads"), "{err}");
    let (ok, _, err) = termrast(&["bench", "render", "--rounds", "2"]);
    assert!(!ok && err.contains("--compare"), "{err}");
}
