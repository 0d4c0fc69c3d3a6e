//! `termrast bench load`: how long a large model takes to load, and the memory it
//! takes, in every format. The same sphere is written in each format, and each file
//! is loaded by a child process of its own, so that its peak resident memory is the
//! load's alone.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use crate::mesh::Mesh;

/// Arguments of `bench load`.
#[derive(Debug, Args)]
pub struct LoadArgs {
    /// Triangles of the sphere written in every format.
    #[arg(long, default_value_t = 1 << 20, value_parser = clap::value_parser!(u64).range(8..=4_194_304))]
    pub triangles: u64,
    /// Where the files are written (a new temporary directory by default); they are
    /// kept there.
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Load one file and print the seconds it took (what each child runs).
    #[arg(long, hide = true)]
    pub one: Option<PathBuf>,
}

/// The formats written, with their file names.
const FILES: &[(&str, &str)] = &[
    ("OBJ", "sphere.obj"),
    ("STL binary", "sphere.stl"),
    ("STL ASCII", "sphere-ascii.stl"),
    ("PLY binary", "sphere.ply"),
    ("PLY ASCII", "sphere-ascii.ply"),
    ("GLB", "sphere.glb"),
];

/// Writes the files, loads each in a child and prints a table.
pub fn run(args: &LoadArgs, out: &mut impl Write) -> Result<(), super::CliError> {
    if let Some(file) = &args.one {
        let start = Instant::now();
        let mut m = Mesh::load(file)?;
        m.normalize();
        m.ensure_normals();
        writeln!(
            out,
            "{} {}",
            start.elapsed().as_secs_f64(),
            m.triangle_count()
        )?;
        return Ok(());
    }
    let dir = args.dir.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("termrast-bench-load-{}", std::process::id()))
    });
    std::fs::create_dir_all(&dir).map_err(|source| super::CliError::File {
        path: dir.clone(),
        source,
    })?;
    let mesh = Mesh::uv_sphere(args.triangles as usize);
    writeln!(
        out,
        "loading sphere:{} ({} triangles, {} vertices), each file in a child process; files in {}",
        args.triangles,
        mesh.triangle_count(),
        mesh.positions.len(),
        dir.display()
    )?;
    writeln!(
        out,
        "{:<12} {:>9} {:>9} {:>11}",
        "format", "MB", "load s", "peak RSS MB"
    )?;
    let exe = std::env::current_exe().map_err(|source| super::CliError::File {
        path: "termrast".into(),
        source,
    })?;
    for (name, file) in FILES {
        let path = dir.join(file);
        write_as(&mesh, name, &path).map_err(|source| super::CliError::File {
            path: path.clone(),
            source,
        })?;
        let size = std::fs::metadata(&path).map_or(0, |m| m.len());
        let (secs, peak_kb) = child_load(&exe, &path)?;
        writeln!(
            out,
            "{name:<12} {:>9.1} {secs:>9.3} {:>11}",
            size as f64 / 1e6,
            peak_kb.map_or("-".into(), |k| format!("{:.0}", k as f64 / 1024.0))
        )?;
    }
    Ok(())
}

/// Runs `termrast bench load --one FILE`: its seconds, and its peak resident memory
/// in KiB where the system reports it.
fn child_load(exe: &Path, file: &Path) -> Result<(f64, Option<u64>), super::CliError> {
    let child = std::process::Command::new(exe)
        .args(["bench", "load", "--one"])
        .arg(file)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(|source| super::CliError::File {
            path: exe.into(),
            source,
        })?;
    let pid = child.id();
    let mut stdout = child.stdout.expect("piped");
    let mut text = String::new();
    io::Read::read_to_string(&mut stdout, &mut text)?;
    let (ok, peak) = wait_with_peak(pid);
    let secs = text
        .split_whitespace()
        .next()
        .and_then(|s| s.parse().ok())
        .filter(|_| ok)
        .ok_or_else(|| {
            super::CliError::Usage(format!("loading {} failed in the child", file.display()))
        })?;
    Ok((secs, peak))
}

#[cfg(target_os = "linux")]
fn wait_with_peak(pid: u32) -> (bool, Option<u64>) {
    let mut status = 0;
    // SAFETY: rusage is plain data, filled by wait4 for the child we spawned.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid as libc::pid_t, &raw mut status, 0, &raw mut usage) };
    let ok = r > 0 && libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    (ok, u64::try_from(usage.ru_maxrss).ok())
}

#[cfg(not(target_os = "linux"))]
fn wait_with_peak(_pid: u32) -> (bool, Option<u64>) {
    (true, None)
}

/// Writes `m` as one of [`FILES`]' formats.
fn write_as(m: &Mesh, format: &str, path: &Path) -> io::Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path)?);
    let tris = m.indices.chunks_exact(3);
    let p = |i: u32| m.positions[i as usize];
    match format {
        "OBJ" => {
            for v in &m.positions {
                writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
            }
            for t in tris {
                writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
            }
        }
        "STL binary" => {
            w.write_all(&[b' '; 80])?;
            w.write_all(&(m.triangle_count() as u32).to_le_bytes())?;
            for t in tris {
                w.write_all(&[0u8; 12])?;
                for &i in t {
                    for c in p(i).to_array() {
                        w.write_all(&c.to_le_bytes())?;
                    }
                }
                w.write_all(&[0, 0])?;
            }
        }
        "STL ASCII" => {
            writeln!(w, "solid sphere")?;
            for t in tris {
                writeln!(w, "facet normal 0 0 0\nouter loop")?;
                for &i in t {
                    let v = p(i);
                    writeln!(w, "vertex {} {} {}", v.x, v.y, v.z)?;
                }
                writeln!(w, "endloop\nendfacet")?;
            }
            writeln!(w, "endsolid sphere")?;
        }
        "PLY binary" | "PLY ASCII" => {
            let binary = format == "PLY binary";
            let encoding = if binary {
                "binary_little_endian"
            } else {
                "ascii"
            };
            write!(
                w,
                "ply\nformat {encoding} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
                m.positions.len(),
                m.triangle_count()
            )?;
            for v in &m.positions {
                if binary {
                    for c in v.to_array() {
                        w.write_all(&c.to_le_bytes())?;
                    }
                } else {
                    writeln!(w, "{} {} {}", v.x, v.y, v.z)?;
                }
            }
            for t in tris {
                if binary {
                    w.write_all(&[3])?;
                    for &i in t {
                        w.write_all(&(i as i32).to_le_bytes())?;
                    }
                } else {
                    writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
                }
            }
        }
        "GLB" => write_glb(m, &mut w)?,
        _ => unreachable!("the formats of FILES"),
    }
    w.flush()
}

/// A binary glTF: one buffer of f32 positions and u32 indices, one mesh, one node.
fn write_glb(m: &Mesh, w: &mut impl Write) -> io::Result<()> {
    let mut bin: Vec<u8> = Vec::with_capacity(m.positions.len() * 12 + m.indices.len() * 4);
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for v in &m.positions {
        for (i, c) in v.to_array().into_iter().enumerate() {
            lo[i] = lo[i].min(c);
            hi[i] = hi[i].max(c);
            bin.extend(c.to_le_bytes());
        }
    }
    let positions = bin.len();
    bin.extend(m.indices.iter().flat_map(|i| i.to_le_bytes()));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteLength":{positions}}},{{"buffer":0,"byteOffset":{positions},"byteLength":{}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}},{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - positions,
        m.positions.len(),
        m.indices.len()
    );
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}
