//! MTL material libraries, parsed here rather than by the OBJ crate so that no line
//! can stop the load: the diffuse colour (`Kd`) and texture (`map_Kd`) are read, every
//! other statement is skipped, and a problem is a warning with the file and line.

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::material::{MeshMaterial, TextureSource, Warnings};
use super::text::{self, number, words};

/// The materials of a library, in file order (a later `newmtl` of the same name
/// replaces the earlier).
pub fn parse(bytes: &[u8], path: &Path, warnings: &mut Warnings) -> Vec<MeshMaterial> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut out: Vec<MeshMaterial> = Vec::new();
    let at = |line: usize| format!("{}:{line}", path.display());
    for (line, l) in text::lines(bytes) {
        let mut w = words(&l);
        let Some(key) = w.next() else { continue };
        match key {
            b"newmtl" => {
                let name = text::rest_after_keyword(&l);
                out.retain(|m| m.name != name);
                out.push(MeshMaterial::plain(&name));
            }
            b"Kd" => {
                let Some(m) = out.last_mut() else {
                    warnings.add("mtl-orphan", || {
                        format!("{}: `Kd` before any `newmtl` is ignored", at(line))
                    });
                    continue;
                };
                let values: Vec<Option<f64>> = w.map(number).collect();
                match values[..] {
                    [Some(g)] => m.diffuse = Vec3::splat(g as f32),
                    [Some(r), Some(g), Some(b)] => {
                        m.diffuse = Vec3::new(r as f32, g as f32, b as f32);
                    }
                    _ => warnings.add("mtl-kd", || {
                        format!(
                            "{}: `Kd` needs 1 or 3 numbers; material `{}` stays white",
                            at(line),
                            m.name
                        )
                    }),
                }
                if !m.diffuse.is_finite() || m.diffuse.min_element() < 0.0 {
                    warnings.add("mtl-kd-range", || {
                        format!(
                            "{}: `Kd` is not a colour; material `{}` stays white",
                            at(line),
                            m.name
                        )
                    });
                    m.diffuse = Vec3::ONE;
                }
            }
            b"map_Kd" => {
                let Some(m) = out.last_mut() else { continue };
                let name = texture_name(&l);
                if name.is_empty() {
                    warnings.add("mtl-map", || {
                        format!("{}: `map_Kd` names no file", at(line))
                    });
                    continue;
                }
                m.texture = find_file(dir, &name, &at(line), warnings).map(TextureSource::File);
            }
            _ => {}
        }
    }
    out
}

/// How many arguments each `map_*` option takes (at most; the three-number options
/// may have fewer).
const OPTIONS: &[(&[u8], usize)] = &[
    (b"-blendu", 1),
    (b"-blendv", 1),
    (b"-bm", 1),
    (b"-boost", 1),
    (b"-cc", 1),
    (b"-clamp", 1),
    (b"-imfchan", 1),
    (b"-mm", 2),
    (b"-o", 3),
    (b"-s", 3),
    (b"-t", 3),
    (b"-texres", 1),
    (b"-type", 1),
];

/// The file name of a `map_Kd` line, past its options (`-s 1 1 1`, `-clamp on`…);
/// the rest of the line, so names with spaces survive.
fn texture_name(line: &[u8]) -> String {
    let mut ws: Vec<&[u8]> = words(line).skip(1).collect();
    let mut i = 0;
    // The last word is always (part of) the name, never an option.
    while let Some(&(_, n)) = ws[..ws.len().saturating_sub(1)]
        .get(i)
        .and_then(|w| OPTIONS.iter().find(|(o, _)| o == w))
    {
        i += 1;
        let mut taken = 0;
        // Numeric options take up to n numbers; the others exactly one word.
        while taken < n && i + 1 < ws.len() {
            let numeric = number(ws[i]).is_some();
            if taken > 0 && !numeric {
                break;
            }
            i += 1;
            taken += 1;
        }
    }
    ws.drain(..i.min(ws.len()));
    ws.iter()
        .map(|w| String::from_utf8_lossy(w))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Finds a file an OBJ or MTL names, relative to `dir`: as written (with Windows
/// separators turned around), else the same name in another letter case, else the
/// bare file name beside the library (exporters often write the author's absolute
/// path); a warning says which was used, or that none exists.
pub fn find_file(dir: &Path, name: &str, at: &str, warnings: &mut Warnings) -> Option<PathBuf> {
    let name = name.replace('\\', "/");
    let exact = dir.join(&name);
    // Anything there by that name (a FIFO too) is the one meant: reading it says
    // what is wrong with it.
    if exact.exists() {
        return Some(exact);
    }
    let wanted = Path::new(&name);
    let file_name = wanted.file_name()?.to_string_lossy().to_lowercase();
    let near = exact.parent().map(Path::to_path_buf);
    for folder in near.iter().map(PathBuf::as_path).chain([dir]) {
        let Ok(entries) = std::fs::read_dir(folder) else {
            continue;
        };
        let found = entries.flatten().map(|e| e.path()).find(|p| {
            p.is_file()
                && p.file_name()
                    .is_some_and(|f| f.to_string_lossy().to_lowercase() == file_name)
        });
        if let Some(found) = found {
            warnings.add("file-fallback", || {
                format!("{at}: `{name}` not found; using {}", found.display())
            });
            return Some(found);
        }
    }
    warnings.add("file-missing", || {
        format!(
            "{at}: `{name}` not found ({}); drawn without it",
            exact.display()
        )
    });
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_and_odd_lines_are_warnings() {
        let mut w = Warnings::default();
        let mats = parse(
            b"newmtl\nKd 1 2\nnewmtl red\nKd 1 0 0\nKs 0.5\nKd\nnewmtl grey\nKd 0.5\nmap_Kd\n",
            Path::new("lib.mtl"),
            &mut w,
        );
        let names: Vec<_> = mats.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["", "red", "grey"]);
        assert_eq!(mats[0].diffuse, Vec3::ONE);
        assert_eq!(
            mats[1].diffuse,
            Vec3::X,
            "a bare Kd keeps the colour before it"
        );
        assert_eq!(mats[2].diffuse, Vec3::splat(0.5));
        let lines = w.into_lines();
        assert!(lines[0].starts_with("lib.mtl:2:"), "{lines:?}");
        assert!(lines[0].contains("once more"), "{lines:?}");
        assert!(lines[1].starts_with("lib.mtl:9:"), "{lines:?}");
    }

    #[test]
    fn texture_options_are_skipped() {
        assert_eq!(texture_name(b"map_Kd -s 1 1 1 -o 0.5 tex.png"), "tex.png");
        assert_eq!(
            texture_name(b"map_Kd -clamp on -bm 0.2 my tex.jpg"),
            "my tex.jpg"
        );
        assert_eq!(texture_name(b"map_Kd -s 2 a.png"), "a.png");
        assert_eq!(texture_name(b"map_Kd -s"), "-s");
    }
}
